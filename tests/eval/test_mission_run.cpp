// Missions run in process (`auvrl eval --mission`): the committed missions with the PID (test1
// reaches as the scenario does, the tour completes), timed events applied mid-run, aborts on
// the limits, the files written and the vehicle chosen.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "agent/mission.hpp"
#include "agent/pid_controller.hpp"
#include "agent_test_util.hpp"
#include "eval/evaluation.hpp"
#include "eval/mission_run.hpp"

namespace auvrl::eval {
namespace {

using test_support::nessie;
using test_support::read_csv;
using test_support::TempDir;
using test_support::vehicle_path;

std::string mission_path(const std::string& name) {
  return std::string(AUVRL_CONFIG_DIR) + "/missions/" + name + ".yaml";
}

agent::PidController pid() {
  return agent::PidController(nessie(), agent::pid_gains_for(nessie()).gains);
}

/// The PID's summary row of a named scenario.
SummaryRow scenario_row(Scenario scenario) {
  EvaluationConfig config;
  task::apply_vehicle(nessie().facts(), config.task);
  agent::PidController controller = pid();
  return run_evaluation_episode(nessie(), config, controller,
                                scenario_episodes(config, scenario).front(), nullptr);
}

TEST(MissionRun, PidReachesTest1AsTheScenarioDoes) {
  const agent::Mission mission = agent::read_mission_file(mission_path("test1"));
  agent::PidController controller = pid();
  MissionTrajectory trajectory;
  const MissionOutcome outcome =
      run_mission(nessie(), task::TaskConfig{}, controller, mission, 1, &trajectory);
  EXPECT_EQ(outcome.end, MissionEnd::kCompleted);
  ASSERT_EQ(outcome.waypoints.size(), 1u);
  const agent::WaypointResult& r = outcome.waypoints[0].result;
  EXPECT_TRUE(r.reached);
  // The same vehicle, controller and way-point as the scenario: the same first arrival.
  EXPECT_NEAR(r.time_to_reach_s, scenario_row(Scenario::kTest1).time_to_reach_s, 1e-9);
  EXPECT_NEAR(r.completed_time_s, r.time_to_reach_s + 3.0, 1e-9);
  EXPECT_NEAR(outcome.end_time_s, r.completed_time_s, 1e-9);
  EXPECT_LT(r.hold_error_m, 0.5);
  EXPECT_GT(outcome.waypoints[0].thrust_energy, 0.0);
  // The reset row, then one row per step up to the completion.
  EXPECT_EQ(trajectory.rows.size(), trajectory.waypoint_index.size());
  EXPECT_EQ(trajectory.rows.size(),
            static_cast<std::size_t>(std::lround(outcome.end_time_s / 0.1)) + 1);
}

TEST(MissionRun, PidFaultMissionMatchesTheFaultScenario) {
  const agent::Mission mission = agent::read_mission_file(mission_path("fault"));
  agent::PidController controller = pid();
  const MissionOutcome outcome =
      run_mission(nessie(), task::TaskConfig{}, controller, mission, 1, nullptr);
  ASSERT_EQ(outcome.end, MissionEnd::kCompleted);
  EXPECT_NEAR(outcome.waypoints[0].result.time_to_reach_s,
              scenario_row(Scenario::kFault).time_to_reach_s, 1e-9);
}

TEST(MissionRun, PidCompletesTheTour) {
  const agent::Mission mission = agent::read_mission_file(mission_path("tour"));
  ASSERT_GE(mission.waypoints.size(), 5u);
  agent::PidController controller = pid();
  const MissionOutcome outcome =
      run_mission(nessie(), task::TaskConfig{}, controller, mission, 1, nullptr);
  EXPECT_EQ(outcome.end, MissionEnd::kCompleted) << outcome.abort_reason;
  EXPECT_EQ(outcome.completed, static_cast<int>(mission.waypoints.size()));
  EXPECT_LT(outcome.end_time_s, mission.time_limit_s);
  double previous_s = 0.0;
  for (const MissionWaypointRow& row : outcome.waypoints) {
    EXPECT_TRUE(row.result.reached) << row.index;
    EXPECT_GT(row.result.time_to_reach_s, previous_s) << row.index;
    EXPECT_NEAR(row.result.time_from_previous_s, row.result.time_to_reach_s - previous_s, 1e-9);
    previous_s = row.result.completed_time_s;
  }
}

/// A one-way-point mission from test1's, with events.
agent::Mission with_events(std::vector<agent::MissionEvent> events) {
  agent::Mission mission = agent::read_mission_file(mission_path("test1"));
  mission.events = std::move(events);
  mission.time_limit_s = 4.0;
  return mission;
}

MissionTrajectory run_pid(const agent::Mission& mission) {
  agent::PidController controller = pid();
  MissionTrajectory trajectory;
  run_mission(nessie(), task::TaskConfig{}, controller, mission, 1, &trajectory);
  return trajectory;
}

TEST(MissionRun, AppliesEventsAtTheirTimes) {
  agent::MissionEvent fault;
  fault.time_s = 2.0;
  fault.thruster = 0;
  fault.efficiency = 0.0;
  const MissionTrajectory healthy = run_pid(with_events({}));
  const MissionTrajectory faulted = run_pid(with_events({fault}));
  ASSERT_EQ(faulted.rows.size(), 41u);  // the reset and 40 steps
  for (std::size_t k = 0; k <= 20; ++k) {
    EXPECT_EQ(faulted.rows[k].observation.position_ned_m,
              healthy.rows[k].observation.position_ned_m)
        << k;
  }
  EXPECT_NE(healthy.rows[21].thrust_realised_n[0], 0.0);
  for (std::size_t k = 21; k < faulted.rows.size(); ++k) {
    EXPECT_EQ(faulted.rows[k].thrust_realised_n[0], 0.0) << k;
  }

  agent::MissionEvent current;
  current.kind = agent::MissionEvent::Kind::kCurrent;
  current.time_s = 1.0;
  current.current_ned_mps = Eigen::Vector3d(0.0, 0.5, 0.0);
  const MissionTrajectory drifting = run_pid(with_events({current}));
  for (std::size_t k = 0; k <= 10; ++k) {
    EXPECT_EQ(drifting.rows[k].observation.position_ned_m,
              healthy.rows[k].observation.position_ned_m)
        << k;
  }
  EXPECT_GT(drifting.rows[40].observation.position_ned_m.y(),
            healthy.rows[40].observation.position_ned_m.y() + 0.05);

  // A fault at time 0 is the start's, as the fault scenario sets it at the reset.
  fault.time_s = 0.0;
  EXPECT_EQ(run_pid(with_events({fault})).rows[1].thrust_realised_n[0], 0.0);
  fault.thruster = 6;
  EXPECT_THROW(run_pid(with_events({fault})), std::invalid_argument);
}

TEST(MissionRun, AbortsWhenTheVehicleLeavesItsLimits) {
  agent::Mission mission = agent::read_mission_file(mission_path("test1"));
  mission.limits.max_depth_m = 7.0;  // the way-point lies at 10 m
  agent::PidController controller = pid();
  const MissionOutcome outcome =
      run_mission(nessie(), task::TaskConfig{}, controller, mission, 1, nullptr);
  EXPECT_EQ(outcome.end, MissionEnd::kLimitViolation);
  EXPECT_NE(outcome.abort_reason.find("max_depth_m 7 m"), std::string::npos)
      << outcome.abort_reason;
  EXPECT_GT(outcome.end_time_s, 0.0);
  EXPECT_FALSE(outcome.waypoints[0].result.reached);
  EXPECT_NE(format_mission_table(outcome).find("limit_violation"), std::string::npos);
}

TEST(MissionRun, SensorNoiseReachesTheReports) {
  agent::Mission mission = with_events({});
  mission.sensor_noise.position_m = 0.1;
  const MissionTrajectory noisy = run_pid(mission);
  const MissionTrajectory exact = run_pid(with_events({}));
  EXPECT_NE(noisy.rows[0].observation.position_ned_m, exact.rows[0].observation.position_ned_m);
}

TEST(MissionCommand, WritesItsFilesAndSaysWhichVehicle) {
  TempDir dir;
  EvalRequest request;
  request.controller = "pid";
  request.mission_path = mission_path("test1");
  request.vehicle_path = dir.path("default_vehicle.yaml");  // not used: the mission names one
  request.out_dir = dir.path("run");
  std::ostringstream out;
  const MissionOutcome outcome = run_mission_request(request, out);
  EXPECT_EQ(outcome.end, MissionEnd::kCompleted);
  EXPECT_NE(out.str().find("from the mission's vehicle:"), std::string::npos) << out.str();
  const auto rows = read_csv(dir.path("run/mission.csv"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].front(), "index");
  EXPECT_EQ(rows[0].back(), "energy");
  EXPECT_EQ(rows[1][4], "1");
  const auto trajectory = read_csv(dir.path("run/trajectory.csv"));
  EXPECT_EQ(trajectory[0].back(), "waypoint");
  EXPECT_EQ(trajectory[0].size(), test_support::split(trajectory_csv_header(6)).size() + 1);
  EXPECT_TRUE(std::filesystem::exists(dir.path("run/vehicle.csv")));

  // --vehicle given: it wins, and the output says so.
  request.vehicle_path = vehicle_path();
  request.vehicle_given = true;
  std::ostringstream given;
  run_mission_request(request, given);
  EXPECT_NE(given.str().find("from --vehicle (in place of the mission's"), std::string::npos)
      << given.str();
  request.vehicle_path = dir.path("no_vehicle.yaml");
  EXPECT_THROW(run_mission_request(request, given), std::runtime_error);

  request.scenario = "test1";
  EXPECT_THROW(run_mission_request(request, given), std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::eval
