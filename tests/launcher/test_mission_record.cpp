// auvrl run's record of a mission in process: the mission start found from MISSION_STATUS, the
// trajectory from it with the command in force, and the per-way-point rows (the controller's
// tracker fed with the recorded states, the energy per way-point).
#include <gtest/gtest.h>

#include <cmath>

#include "launcher/mission_record.hpp"

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
