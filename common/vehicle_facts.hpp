// What every process takes from the vehicle file besides the physics, and how a process names
// the vehicle when it meets another one than it expects. The physics library fills it
// (sim::VehicleModel::facts()); the task, the networks and the wire checks read it.
#pragma once

#include <array>
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

/// Thruster response as identified on the real vehicle; each effect can be switched off. The
/// physics applies it (sim::step); a driving policy's fault accommodation models a healthy
/// thruster with it (task::ThrusterFaultAccommodation).
struct ThrusterDynamics {
  double max_thrust_n = 39.24;        ///< symmetric saturation |f| <= max, per thruster
  bool delay_enabled = true;          ///< one control-step (sample) delay of the command
  bool lag_enabled = true;            ///< first-order low-pass on the realised thrust
  double lag_time_constant_s = 0.29;  ///< time constant of that low-pass
  bool slew_enabled = true;           ///< rate limit on the realised thrust
  double slew_rate_n_per_s = 21.6;    ///< 5.5 % of full throttle per 0.1 s, in N/s
};

/// The body wrench of one newton of one thruster: [d; r x d] (X Y Z in N, K M N in N m), with
/// d its unit direction and r its position, body frame.
using ThrusterWrench = std::array<double, 6>;

/// The vehicle's identity and the facts the task needs: thrusters, maximum thrust, control step.
struct VehicleFacts {
  std::string name;                             ///< the vehicle file's `name:`
  std::string source_file;                      ///< path of the vehicle file
  std::uint32_t file_crc32 = 0;                 ///< CRC-32 of the vehicle file's bytes
  std::vector<std::string> thruster_names;      ///< in the file's order (action index i = T(i+1))
  double control_step_s = 0;                    ///< s
  ThrusterDynamics thruster_dynamics;           ///< the thrusters' response
  std::vector<ThrusterWrench> thruster_wrench;  ///< per thruster, in the file's order

  int num_thrusters() const { return static_cast<int>(thruster_names.size()); }
  /// Action +-1 maps to +- this, N (the thrusters' saturation).
  double max_thrust_n() const { return thruster_dynamics.max_thrust_n; }
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
