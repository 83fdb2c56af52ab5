// What every process takes from the vehicle file besides the physics, and how a process names
// the vehicle when it meets another one than it expects. The physics library fills it
// (sim::VehicleModel::facts()); the task, the networks and the wire checks read it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace auvrl {

namespace config {
class Section;
}  // namespace config

/// The vehicle a process simulates or controls when nothing names one: the source tree's
/// config/vehicles/nessie7.yaml (the paper's vehicle).
std::string default_vehicle_file();

/// A run file's `vehicle:` resolved against the file's folder, or default_vehicle_file().
std::string read_vehicle_path(config::Section& root);

/// The vehicle's identity and the facts the task needs: thrusters, maximum thrust, control step.
struct VehicleFacts {
  std::string name;                         ///< the vehicle file's `name:`
  std::string source_file;                  ///< path of the vehicle file
  std::uint32_t file_crc32 = 0;             ///< CRC-32 of the vehicle file's bytes
  std::vector<std::string> thruster_names;  ///< in the file's order (action index i = T(i+1))
  double max_thrust_n = 0;                  ///< action +-1 maps to +- this, N
  double control_step_s = 0;                ///< s

  int num_thrusters() const { return static_cast<int>(thruster_names.size()); }
};

/// The identity a peer announces on the wire (sim heartbeat, reset reply).
struct VehicleIdentity {
  std::string name;
  int num_thrusters = 0;
  std::uint32_t file_crc32 = 0;
};

/// The identity of these facts.
inline VehicleIdentity identity_of(const VehicleFacts& facts) {
  return {facts.name, facts.num_thrusters(), facts.file_crc32};
}

/// True when the announced identity is this vehicle (same name, thruster count and file).
inline bool same_vehicle(const VehicleIdentity& a, const VehicleIdentity& b) {
  return a.name == b.name && a.num_thrusters == b.num_thrusters && a.file_crc32 == b.file_crc32;
}

/// "'nessie7' (6 thrusters, file crc32 0x1234abcd)".
std::string describe(const VehicleIdentity& identity);
/// "'nessie7' (config/vehicles/nessie7.yaml: 6 thrusters, file crc32 0x1234abcd)".
std::string describe(const VehicleFacts& facts);

/// One line naming both sides: "<who> expects vehicle <ours> but <peer> serves <theirs>".
std::string vehicle_mismatch_message(const std::string& who, const VehicleFacts& ours,
                                     const std::string& peer, const VehicleIdentity& theirs);

}  // namespace auvrl
