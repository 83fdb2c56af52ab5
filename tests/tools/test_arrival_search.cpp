// The open-loop search for the soonest arrival (`auvrl fastest`): it starts from the PID's
// commands and never ends later, it finds a sooner arrival than the PID on test1, its commands
// arrive when auv_sim's open-loop tool replays them, the open-loop controller hands over, and
// bad settings are refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "agent/pid_controller.hpp"
#include "agent_test_util.hpp"
#include "sim/open_loop.hpp"
#include "tools/arrival_search.hpp"

namespace auvrl::tools {
namespace {

using test_support::nessie;
using test_support::read_csv;
using test_support::TempDir;
using test_support::vehicle_path;

eval::EvaluationConfig test_config() {
  eval::EvaluationConfig c;
  c.task.num_thrusters = nessie().num_thrusters();
  c.task.max_thrust_n = nessie().thruster_dynamics.max_thrust_n;
  c.task.control_step_s = nessie().control_step_s;
  return c;
}

eval::EvaluationEpisode test1(const eval::EvaluationConfig& c) {
  return eval::scenario_episodes(c, eval::Scenario::kTest1).front();
}

ArrivalSearchConfig small_search(int iterations) {
  ArrivalSearchConfig s;
  s.iterations = iterations;
  s.population = 60;
  s.elites = 8;
  return s;
}

TEST(ArrivalSearch, StartsFromThePidAndNeverEndsLater) {
  const eval::EvaluationConfig config = test_config();
  const ArrivalSearchResult r =
      search_fastest_arrival(nessie(), config, test1(config), small_search(10));
  agent::PidController pid(nessie(), agent::pid_gains_for(nessie()).gains);  // the library's
  const eval::SummaryRow pid_row =
      eval::run_evaluation_episode(nessie(), config, pid, test1(config), nullptr);
  ASSERT_TRUE(pid_row.reached);
  EXPECT_EQ(r.pid_arrival_step, static_cast<int>(std::lround(pid_row.time_to_reach_s / 0.1)));
  ASSERT_GT(r.start_arrival_step, 0) << "the PID's commands, replayed, arrive too";
  ASSERT_GT(r.best_arrival_step, 0);
  EXPECT_LE(r.best_arrival_step, r.start_arrival_step);
  ASSERT_EQ(r.best_so_far_step.size(), 10u);
  ASSERT_EQ(r.iteration_best_step.size(), 10u);
  for (std::size_t i = 1; i < r.best_so_far_step.size(); ++i) {
    EXPECT_LE(r.best_so_far_step[i], r.best_so_far_step[i - 1]) << "iteration " << i;
  }
  ASSERT_EQ(static_cast<int>(r.commands.size()), r.best_arrival_step);
  for (const Eigen::VectorXd& u : r.commands) {
    ASSERT_EQ(u.size(), 6);
    EXPECT_LE(u.cwiseAbs().maxCoeff(), 1.0);
  }
}

TEST(ArrivalSearch, TheSameSeedGivesTheSameCommands) {
  const eval::EvaluationConfig config = test_config();
  const ArrivalSearchResult a =
      search_fastest_arrival(nessie(), config, test1(config), small_search(5));
  const ArrivalSearchResult b =
      search_fastest_arrival(nessie(), config, test1(config), small_search(5));
  ASSERT_EQ(a.commands.size(), b.commands.size());
  for (std::size_t t = 0; t < a.commands.size(); ++t) EXPECT_EQ(a.commands[t], b.commands[t]);
  EXPECT_EQ(a.iteration_best_step, b.iteration_best_step);
}

// The plant allows a sooner arrival at test1's way-point than the PID's: the search finds one
// within a few thousand rollouts (and the evaluation, with the PID holding after the
// commands, measures the same arrival time).
TEST(ArrivalSearch, FindsASoonerArrivalThanThePidOnTest1) {
  const eval::EvaluationConfig config = test_config();
  ArrivalSearchConfig search = small_search(80);
  search.population = 100;
  search.elites = 10;
  const ArrivalSearchResult r = search_fastest_arrival(nessie(), config, test1(config), search);
  ASSERT_GT(r.best_arrival_step, 0);
  EXPECT_LT(r.best_arrival_step, r.pid_arrival_step);

  OpenLoopController found(r.commands, 6, std::make_unique<agent::PidController>(nessie()));
  EXPECT_EQ(found.name(), "open_loop+pid");
  const eval::SummaryRow row =
      eval::run_evaluation_episode(nessie(), config, found, test1(config), nullptr);
  ASSERT_TRUE(row.reached);
  EXPECT_NEAR(row.time_to_reach_s, r.best_arrival_step * 0.1, 1e-9);
  EXPECT_LT(row.mean_error_after_reach_m, 0.3) << "the PID holds station after the arrival";
}

TEST(ArrivalSearch, AuvSimsOpenLoopToolReplaysTheCommandsToTheSameArrival) {
  const eval::EvaluationConfig config = test_config();
  const ArrivalSearchResult r =
      search_fastest_arrival(nessie(), config, test1(config), small_search(5));
  ASSERT_GT(r.best_arrival_step, 0);
  TempDir dir;
  const std::string path = dir.path("commands.csv");
  write_open_loop_commands_csv(path, r.commands, 0.1, nessie().thruster_dynamics.max_thrust_n);
  const std::vector<std::vector<std::string>> rows = read_csv(path);
  ASSERT_EQ(rows.size(), r.commands.size() + 2) << "header, one row per step, the end row";
  EXPECT_EQ(rows[0], (std::vector<std::string>{"t", "f1", "f2", "f3", "f4", "f5", "f6"}));

  const sim::OpenLoopCommands commands = sim::read_open_loop_csv(path, 6);
  sim::ResetSettings reset;  // auv_sim's default start is test1's
  reset.eta << 0.0, 0.0, 5.0, 0.0, 0.0, 0.0;
  const sim::OpenLoopResult replay =
      sim::run_open_loop_commands(nessie(), reset, commands, -1.0, false);
  ASSERT_EQ(static_cast<int>(replay.samples.size()), r.best_arrival_step + 1);
  const Eigen::Vector3d goal = test1(config).goal_ned_m;
  for (std::size_t k = 0; k + 1 < replay.samples.size(); ++k) {
    EXPECT_GT((goal - replay.samples[k].eta.head<3>()).norm(), 0.5) << "step " << k;
  }
  EXPECT_LE((goal - replay.samples.back().eta.head<3>()).norm(), 0.5);
}

// Arrive and stay: the found commands keep the vehicle within the distance asked for the
// stay_steps after the arrival (checked by replaying them through auv_sim's open-loop tool).
TEST(ArrivalSearch, WithStayWithinTheFoundCommandsStopAtTheWayPoint) {
  const eval::EvaluationConfig config = test_config();
  ArrivalSearchConfig search = small_search(10);
  search.stay_within_m = 0.5;
  search.stay_steps = 30;
  const ArrivalSearchResult r = search_fastest_arrival(nessie(), config, test1(config), search);
  ASSERT_GT(r.start_arrival_step, 0) << "the PID's way stays within 0.5 m";
  ASSERT_GT(r.best_arrival_step, 0);
  EXPECT_LE(r.best_arrival_step, r.start_arrival_step);
  ASSERT_EQ(static_cast<int>(r.commands.size()), r.best_arrival_step + 30);
  EXPECT_GT(r.best_farthest_after_m, 0.0);
  EXPECT_LE(r.best_farthest_after_m, 0.5);

  TempDir dir;
  const std::string path = dir.path("commands.csv");
  write_open_loop_commands_csv(path, r.commands, 0.1, nessie().thruster_dynamics.max_thrust_n);
  sim::ResetSettings reset;
  reset.eta << 0.0, 0.0, 5.0, 0.0, 0.0, 0.0;
  const sim::OpenLoopResult replay =
      sim::run_open_loop_commands(nessie(), reset, sim::read_open_loop_csv(path, 6), -1.0, false);
  ASSERT_EQ(static_cast<int>(replay.samples.size()), r.best_arrival_step + 31);
  const Eigen::Vector3d goal = test1(config).goal_ned_m;
  double farthest = 0.0;
  for (std::size_t k = static_cast<std::size_t>(r.best_arrival_step); k < replay.samples.size();
       ++k) {
    farthest = std::max(farthest, (goal - replay.samples[k].eta.head<3>()).norm());
  }
  EXPECT_NEAR(farthest, r.best_farthest_after_m, 1e-9);
}

/// Records what it was asked, and answers a constant.
class ConstantController final : public agent::Controller {
 public:
  void reset() override { ++resets; }
  void act(const task::Observation&, const Eigen::Vector3d&, const task::StateVector&,
           task::ActionVector& action) override {
    ++calls;
    action = task::ActionVector::Constant(2, 0.25f);
  }
  std::string name() const override { return "constant"; }
  int resets = 0;
  int calls = 0;
};

TEST(OpenLoopController, PlaysItsCommandsClippedThenHandsOverAndStartsAgainOnReset) {
  auto after = std::make_unique<ConstantController>();
  ConstantController* after_view = after.get();
  OpenLoopController c({Eigen::Vector2d(0.5, -0.5), Eigen::Vector2d(2.0, -3.0)}, 2,
                       std::move(after));
  EXPECT_EQ(c.name(), "open_loop+constant");
  const task::Observation obs;
  const task::StateVector state;
  task::ActionVector a;
  for (int episode = 0; episode < 2; ++episode) {
    c.reset();
    c.act(obs, Eigen::Vector3d::Zero(), state, a);
    EXPECT_EQ(a, Eigen::Vector2f(0.5f, -0.5f));
    c.act(obs, Eigen::Vector3d::Zero(), state, a);
    EXPECT_EQ(a, Eigen::Vector2f(1.0f, -1.0f)) << "clipped to [-1, 1]";
    c.act(obs, Eigen::Vector3d::Zero(), state, a);
    EXPECT_EQ(a, Eigen::Vector2f(0.25f, 0.25f)) << "handed over";
  }
  EXPECT_EQ(after_view->resets, 2);
  EXPECT_EQ(after_view->calls, 2);
}

TEST(OpenLoopController, RefusesCommandsOfTheWrongSizeAndNoSuccessor) {
  EXPECT_THROW(
      OpenLoopController({Eigen::Vector3d::Zero()}, 2, std::make_unique<ConstantController>()),
      std::invalid_argument);
  EXPECT_THROW(OpenLoopController({}, 2, nullptr), std::invalid_argument);
}

void expect_refused(const ArrivalSearchConfig& s, const std::string& field) {
  try {
    s.validate();
    ADD_FAILURE() << "accepted a bad " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(ArrivalSearch, RefusesBadSettingsByName) {
  ArrivalSearchConfig s;
  s.steps_per_segment = 0;
  expect_refused(s, "steps_per_segment");
  s = {};
  s.elites = s.population;
  expect_refused(s, "elites");
  s = {};
  s.population = 1;
  expect_refused(s, "population");
  s = {};
  s.iterations = -1;
  expect_refused(s, "iterations");
  s = {};
  s.initial_sigma = 0.0;
  expect_refused(s, "initial_sigma");
  s = {};
  s.smoothing = 1.0;
  expect_refused(s, "smoothing");
  s = {};
  s.stay_steps = 0;
  expect_refused(s, "stay_steps");

  ArrivalSearchRequest request;
  request.out_dir = "unused";
  request.vehicle_path = vehicle_path();
  request.scenario = "suite";
  std::ostringstream out;
  EXPECT_THROW(run_arrival_search_request(request, out), std::invalid_argument);
  request.scenario = "nowhere";
  EXPECT_THROW(run_arrival_search_request(request, out), std::invalid_argument);
}

TEST(ArrivalSearch, SaysSoWhenThePidNeverArrives) {
  const eval::EvaluationConfig config = test_config();
  eval::EvaluationEpisode dead = test1(config);
  dead.start.thruster_efficiency.assign(6, 0.0);  // no thrust at all
  try {
    search_fastest_arrival(nessie(), config, dead, small_search(1));
    ADD_FAILURE() << "searched without a start";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("never reaches the test1 way-point"), std::string::npos)
        << e.what();
  }
}

TEST(ArrivalSearch, TheRequestWritesCommandsSummarySearchAndTrajectories) {
  TempDir dir;
  ArrivalSearchRequest request;
  request.out_dir = dir.path("fastest");
  request.vehicle_path = vehicle_path();
  request.search = small_search(3);
  std::ostringstream out;
  const ArrivalSearchResult r = run_arrival_search_request(request, out);
  ASSERT_GT(r.best_arrival_step, 0);
  EXPECT_NE(out.str().find("PID baseline:"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("soonest found:"), std::string::npos) << out.str();

  const auto summary = read_csv(dir.path("fastest/summary.csv"));
  ASSERT_EQ(summary.size(), 3u);
  EXPECT_EQ(summary[1][1], "pid");
  EXPECT_EQ(summary[2][1], "open_loop+pid");
  EXPECT_EQ(summary[2][0], "test1");
  EXPECT_EQ(read_csv(dir.path("fastest/commands.csv")).size(), r.commands.size() + 2);
  const auto search = read_csv(dir.path("fastest/search.csv"));
  ASSERT_EQ(search.size(), 4u);
  EXPECT_EQ(search[0], (std::vector<std::string>{"iteration", "best_arrival_step",
                                                 "iteration_best_arrival_step"}));
  EXPECT_TRUE(std::filesystem::exists(dir.path("fastest/trajectories/pid_test1.csv")));
  EXPECT_TRUE(std::filesystem::exists(dir.path("fastest/trajectories/open_loop_test1.csv")));
}

}  // namespace
}  // namespace auvrl::tools
