// The mission file parser (auv_controller, auvrl run, auvrl eval --mission): bytes as a mission
// YAML file, read with agent::read_mission_file; an accepted mission is then followed by a
// MissionTracker and checked against its limits along a straight run to its way-points. A bad
// file must be refused with config::ConfigError (file, key, line); any other exception, crash
// or undefined behaviour is a finding.
#include "agent/mission.hpp"
#include "common/config/table.hpp"
#include "fuzz/fuzz_util.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::scratch_dir() + "/mission.yaml";
  fuzz::write_file(path, data, size);
  agent::Mission mission;
  try {
    mission = agent::read_mission_file(path);
  } catch (const config::ConfigError&) {
    return 0;  // refused naming the file, the key and the line: what a bad file must give
  }
  agent::MissionTracker tracker(mission.waypoints);
  task::Observation observation;
  observation.position_ned_m = mission.start.position_ned_m;
  observation.euler_rpy_rad = mission.start.euler_rpy_rad;
  // Each way-point visited in turn, one sample at it per second, checked against the limits.
  for (int step = 0; step < 64 && !tracker.done(); ++step) {
    observation.position_ned_m = tracker.goal_ned_m();
    agent::check_limits(mission, observation);
    tracker.update(static_cast<double>(step), observation.position_ned_m);
  }
  return 0;
}
