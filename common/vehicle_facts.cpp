#include "common/vehicle_facts.hpp"

#include <fmt/format.h>

#include "common/config/yaml_config.hpp"

namespace auvrl {

std::string default_vehicle_file() {
  return std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
}

std::string read_vehicle_path(config::Section& root) {
  std::string vehicle;
  root.read("vehicle", vehicle);
  return vehicle.empty() ? default_vehicle_file() : config::resolve_path(root, vehicle);
}

std::string describe(const VehicleIdentity& identity) {
  return fmt::format("'{}' ({} thrusters, file crc32 {:08x})", identity.name,
                     identity.num_thrusters, identity.file_crc32);
}

std::string describe(const VehicleFacts& facts) {
  return fmt::format("'{}' ({}: {} thrusters, file crc32 {:08x})", facts.name, facts.source_file,
                     facts.num_thrusters(), facts.file_crc32);
}

std::string vehicle_mismatch_message(const std::string& who, const VehicleFacts& ours,
                                     const std::string& peer, const VehicleIdentity& theirs) {
  return fmt::format(
      "{} expects vehicle {} but {} serves vehicle {}: name the same vehicle file "
      "for every process (auvrl train --vehicle FILE, or the run file's vehicle:)",
      who, describe(ours), peer, describe(theirs));
}

}  // namespace auvrl
