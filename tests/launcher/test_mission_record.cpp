// auvrl run's record of a mission in process: the mission start found from MISSION_STATUS, the
// trajectory from it with the command in force, and the per-way-point rows (the controller's
// tracker fed with the recorded states, the energy per way-point); the events as applied.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "child_process.hpp"
#include "launcher/mission_record.hpp"
#include "launcher/mission_replay.hpp"

namespace {

using namespace auvrl;
using launcher::MissionRecorder;

auvrl_lcm::vehicle_state_t state_at(double sim_time_s, double x_m) {
  auvrl_lcm::vehicle_state_t s{};
  s.sim_time_s = sim_time_s;
  s.position_ned_m[0] = x_m;
  s.num_thrusters = 2;
  s.thrust_realised_n = {0.0, 0.0};
  return s;
}

auvrl_lcm::thruster_cmd_t command(double a_n, double b_n) {
  auvrl_lcm::thruster_cmd_t c{};
  c.num_thrusters = 2;
  c.thrust_n = {a_n, b_n};
  return c;
}

auvrl_lcm::mission_status_t status(double elapsed_s) {
  auvrl_lcm::mission_status_t s{};
  s.supervisor_state = auvrl_lcm::mission_status_t::STATE_ACTIVE;
  s.elapsed_s = elapsed_s;
  return s;
}

TEST(MissionRecorder, FindsTheControllersFirstStateAndRecordsFromIt) {
  MissionRecorder recorder(2);
  for (int i = 0; i <= 5; ++i) recorder.add_state(state_at(10.0 + 0.1 * i, 0.0), i);
  EXPECT_FALSE(recorder.start_time_s()) << "no status yet";
  // The controller's first state was 10.2: its status for the state at 10.5 says 0.3 s ...
  recorder.add_status(status(0.3));
  ASSERT_TRUE(recorder.start_time_s());
  EXPECT_NEAR(*recorder.start_time_s(), 10.2, 1e-9);
  recorder.add_command(command(10.0, -20.0));
  recorder.add_state(state_at(10.6, 1.0), 6);
  recorder.add_state(state_at(10.6, 9.0), 6.5);  // a re-sent state: not recorded twice
  recorder.add_state(state_at(10.7, 2.0), 7);
  // ... and one that arrives after a newer state makes the difference larger: ignored.
  recorder.add_status(status(0.4));
  EXPECT_NEAR(*recorder.start_time_s(), 10.2, 1e-9);
  EXPECT_NEAR(*recorder.mission_time_s(), 0.5, 1e-9);
  EXPECT_NEAR(recorder.mission_wall_s(), 5.0, 1e-9);
  const std::vector<agent::TrajectoryRow> rows = recorder.trajectory();
  ASSERT_EQ(rows.size(), 6u);  // 10.2 .. 10.7
  EXPECT_NEAR(rows.front().time_s, 0.0, 1e-9);
  EXPECT_EQ(rows[3].thrust_command_n, std::vector<double>({0.0, 0.0}));
  EXPECT_EQ(rows[4].thrust_command_n, std::vector<double>({10.0, -20.0}));
  EXPECT_EQ(rows[4].observation.position_ned_m.x(), 1.0);
}

TEST(MissionRecorder, WaitingStatusesAndOtherThrusterCountsAreNotUsed) {
  MissionRecorder recorder(2);
  recorder.add_state(state_at(1.0, 0.0), 0);
  auvrl_lcm::mission_status_t waiting = status(0.0);
  waiting.supervisor_state = auvrl_lcm::mission_status_t::STATE_WAITING;
  recorder.add_status(waiting);
  EXPECT_FALSE(recorder.start_time_s());
  auvrl_lcm::vehicle_state_t other = state_at(1.1, 0.0);
  other.num_thrusters = 3;
  recorder.add_state(other, 1);
  EXPECT_EQ(recorder.states_recorded(), 1u);
}

TEST(AnalyseWaypoints, FeedsTheTrackerAndSumsTheEnergyOfEachWaypoint) {
  // Along x at 1 m/s: way-point 1 at x = 2 (within 0.5 m at t = 1.5, held there 1 s), then
  // way-point 2 at x = 5.05 (within 0.5 m at t = 4.6, no hold).
  std::vector<agent::MissionWaypoint> waypoints(2);
  waypoints[0].position_ned_m = {2, 0, 0};
  waypoints[0].hold_s = 1.0;
  waypoints[1].position_ned_m = {5.05, 0, 0};
  waypoints[1].hold_s = 0.0;
  std::vector<agent::TrajectoryRow> rows;
  for (int i = 0; i <= 60; ++i) {
    agent::TrajectoryRow r;
    r.time_s = 0.1 * i;
    const double x = i <= 25 ? 0.1 * i : std::min(2.5 + 0.1 * (i - 25), 5.0);
    r.observation.position_ned_m = {i >= 15 && i <= 25 ? 2.0 : x, 0, 0};
    r.thrust_command_n = {20.0, 0.0};  // mean squared normalised (max 40 N): 0.125
    r.thrust_realised_n = {20.0, 0.0};
    rows.push_back(r);
  }
  const launcher::MissionAnalysis analysis = launcher::analyse_waypoints(waypoints, rows, 40.0);
  const auto& result = analysis.waypoints;
  ASSERT_EQ(result.size(), 2u);
  EXPECT_EQ(result[0].index, 0);
  EXPECT_TRUE(result[0].result.reached);
  EXPECT_NEAR(result[0].result.time_to_reach_s, 1.5, 1e-9);
  EXPECT_NEAR(result[0].result.completed_time_s, 2.5, 1e-9);
  EXPECT_TRUE(result[1].result.reached);
  EXPECT_NEAR(result[1].result.time_to_reach_s, 4.6, 1e-9);
  EXPECT_NEAR(result[1].result.time_from_previous_s, 2.1, 1e-9);
  // Energy: 0.125 per control step while it was the current way-point (none once done).
  EXPECT_NEAR(result[0].thrust_energy, 0.125 * 26, 1e-9);  // rows t = 0 .. 2.5
  EXPECT_NEAR(result[1].thrust_energy, 0.125 * 21, 1e-9);  // rows t = 2.6 .. 4.6
  ASSERT_EQ(analysis.waypoint_index.size(), rows.size());
  EXPECT_EQ(analysis.waypoint_index[25], 0);
  EXPECT_EQ(analysis.waypoint_index[26], 1);
  EXPECT_EQ(analysis.waypoint_index[60], 1);  // done: the last one
  EXPECT_NEAR(rows[0].distance_m, 2.0, 1e-9);
  EXPECT_NEAR(rows[40].distance_m, 5.05 - rows[40].observation.position_ned_m.x(), 1e-9);
  const std::string table = launcher::format_waypoint_table(result);
  EXPECT_NE(table.find("| 1 | 2, 0, 0 | yes | 1.5 |"), std::string::npos) << table;
}

}  // namespace

// The events as the vehicle got them: the current at 0 set with the reset, each current message
// one event and each fault message one event per thruster it changes, with the due time of the
// mission's event it applies.
TEST(MissionEventLog, TurnsFaultAndCurrentMessagesIntoTheMissionsEvents) {
  agent::Mission mission;
  agent::MissionEvent current0, current_later, fault_t1, fault_t2;
  current0.kind = current_later.kind = agent::MissionEvent::Kind::kCurrent;
  current0.current_ned_mps = {0.2, 0.0, 0.0};
  current_later.time_s = 30.0;
  fault_t1.time_s = 20.0;
  fault_t1.thruster = 1;
  fault_t1.efficiency = 0.1;
  fault_t2.time_s = 40.0;
  fault_t2.thruster = 1;
  fault_t2.efficiency = 0.0;
  mission.events = {current0, fault_t1, current_later, fault_t2};
  launcher::MissionEventLog log(mission, {"A", "B"});
  EXPECT_EQ(log.start_current_ned_mps(), Eigen::Vector3d(0.2, 0.0, 0.0));
  ASSERT_EQ(log.events().size(), 1u);
  EXPECT_EQ(log.events()[0].text,
            "t=0 s: water current [0.2, 0, 0] m/s NED, set with the vehicle's reset");

  auvrl_lcm::thruster_fault_t fault{};
  fault.num_thrusters = 2;
  fault.thruster_efficiency = {1.0, 0.1};
  auto added = log.add_fault(fault, 20.04, "SIM_FAULT_0");
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0].time_s, 20.04);
  EXPECT_EQ(added[0].text,
            "t=20.0 s (due at 20 s): thruster 1 (B) at 10 % efficiency, injected on SIM_FAULT_0");
  EXPECT_TRUE(log.add_fault(fault, 20.1, "SIM_FAULT_0").empty()) << "a repeat changes nothing";
  fault.thruster_efficiency = {0.5, 0.0};  // one of the mission's, one not
  added = log.add_fault(fault, 41.0, "SIM_FAULT_0");
  ASSERT_EQ(added.size(), 2u);
  EXPECT_EQ(added[0].text,
            "t=41.0 s (not one of the mission's events): thruster 0 (A) at 50 % efficiency, "
            "injected on SIM_FAULT_0");
  EXPECT_EQ(added[1].text,
            "t=41.0 s (due at 40 s): thruster 1 (B) at 0 % efficiency, injected on SIM_FAULT_0");
  fault.num_thrusters = 3;
  fault.thruster_efficiency = {0.0, 0.0, 0.0};
  EXPECT_TRUE(log.add_fault(fault, 42.0, "SIM_FAULT_0").empty()) << "another vehicle's count";
  auvrl_lcm::water_current_t current{};  // the current at 30 s: zero
  EXPECT_EQ(log.add_current(current, 30.05, "SIM_CURRENT_0").text,
            "t=30.1 s (due at 30 s): water current [0, 0, 0] m/s NED, injected on SIM_CURRENT_0");
  current.current_constant_ned_mps[1] = -0.25;
  EXPECT_EQ(log.add_current(current, 50.0, "SIM_CURRENT_0").text,
            "t=50.0 s (not one of the mission's events): water current [0, -0.25, 0] m/s NED, "
            "injected on SIM_CURRENT_0");
  EXPECT_EQ(log.events().size(), 6u);
}

// What a replay says of each file against the run's.
TEST(CompareFiles, SaysWhereARunsFileAndItsReplayDiffer) {
  const std::string dir = test_support::make_temp_dir("auvrl_compare_files_");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + "/" + name) << text;
    return dir + "/" + name;
  };
  const std::string a = write("a.csv", "t,x\n0,1\n0.1,2\n");
  EXPECT_EQ(launcher::compare_files(a, write("same.csv", "t,x\n0,1\n0.1,2\n")), "identical");
  EXPECT_EQ(launcher::compare_files(a, write("b.csv", "t,x\n0,1\n0.1,3\n")),
            "differs from line 3 (the run has 3 lines, the replay 3)");
  EXPECT_EQ(launcher::compare_files(a, write("short.csv", "t,x\n0,1\n")),
            "differs from line 3 (the run has 3 lines, the replay 2)");
  EXPECT_EQ(launcher::compare_files(a, write("crlf.csv", "t,x\n0,1\n0.1,2")),
            "the same lines, not the same bytes (line ends)");
  EXPECT_EQ(launcher::compare_files(a, dir + "/none.csv"), "missing in the replay");
  EXPECT_EQ(launcher::compare_files(dir + "/none.csv", a), "missing in the run");
}
