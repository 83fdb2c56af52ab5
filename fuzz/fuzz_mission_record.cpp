// What `auvrl replay` reads from the log it is given (and `auvrl run` hears live): SIM_STATE_0,
// SIM_CMD_0, MISSION_STATUS, SIM_FAULT_0 and SIM_CURRENT_0 messages as raw bytes, decoded as
// the replay's subscriptions decode them and fed to a MissionRecorder and a MissionEventLog for
// config/missions/tour_fault.yaml on Nessie VII; the record is then analysed per way-point as
// the replay's report is. Messages that do not decode are dropped, as the replay drops them;
// any exception, crash or undefined behaviour is a finding.
#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>

#include "agent/mission.hpp"
#include "common/transport.hpp"
#include "fuzz/fuzz_util.hpp"
#include "launcher/mission_record.hpp"
#include "sim/vehicle_model.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const VehicleFacts facts =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml").facts();
  static const agent::Mission mission =
      agent::read_mission_file(std::string(AUVRL_CONFIG_DIR) + "/missions/tour_fault.yaml");
  launcher::MissionRecorder recorder(facts.num_thrusters());
  launcher::MissionEventLog events(mission, facts.thruster_names);
  double wall_s = 0.0;
  for (const fuzz::Record& r : fuzz::read_records(data, size)) {
    // Selector: 0 state, 1 command, 2 status, 3 fault, 4 current.
    switch ((r.selector & 0x7F) % 5) {
      case 0:
        if (auvrl_lcm::vehicle_state_t m; fuzz::decode_record(r, m))
          recorder.add_state(m, wall_s += 0.1);
        break;
      case 1:
        if (auvrl_lcm::thruster_cmd_t m; fuzz::decode_record(r, m)) recorder.add_command(m);
        break;
      case 2:
        if (auvrl_lcm::mission_status_t m; fuzz::decode_record(r, m)) recorder.add_status(m);
        break;
      case 3:
        if (auvrl_lcm::thruster_fault_t m; fuzz::decode_record(r, m)) {
          events.add_fault(m, recorder.mission_time_s(), "SIM_FAULT_0");
        }
        break;
      default:
        if (auvrl_lcm::water_current_t m; fuzz::decode_record(r, m)) {
          events.add_current(m, recorder.mission_time_s(), "SIM_CURRENT_0");
        }
    }
  }
  std::vector<agent::TrajectoryRow> rows = recorder.trajectory();
  const launcher::MissionAnalysis analysis =
      launcher::analyse_waypoints(mission.waypoints, rows, facts.max_thrust_n());
  launcher::format_waypoint_table(analysis.waypoints);
  return 0;
}
