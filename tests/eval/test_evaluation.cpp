// The evaluation: scenario definitions, summary.csv and trajectory files with their columns,
// the text table, layout inference and the policy-file errors of `auvrl eval`.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "agent/pid_controller.hpp"
#include "agent_test_util.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "eval/evaluation.hpp"
#include "eval/quick_evaluator.hpp"
#include "eval/ranking.hpp"

namespace auvrl::eval {
namespace {

using test_support::nessie;
using test_support::read_csv;
using test_support::TempDir;
using test_support::vehicle_path;

constexpr double kPi = 3.14159265358979323846;

EvaluationConfig six_thruster_config() {
  EvaluationConfig c;
  c.task.num_thrusters = 6;
  return c;
}

TEST(Scenarios, ParsesNamesAndAll) {
  const std::vector<Scenario> all = parse_scenarios("all");
  ASSERT_EQ(all.size(), 5u);
  EXPECT_EQ(all[0], Scenario::kTest1);
  EXPECT_EQ(all[4], Scenario::kSuite);
  for (Scenario s : all) EXPECT_EQ(parse_scenarios(to_string(s)), std::vector<Scenario>{s});
  EXPECT_THROW(parse_scenarios("test3"), std::invalid_argument);
}

TEST(Scenarios, PaperTestsAsSpecified) {
  const EvaluationConfig c = six_thruster_config();
  const EvaluationEpisode t1 = scenario_episodes(c, Scenario::kTest1).at(0);
  EXPECT_EQ(t1.start.position_ned_m, Eigen::Vector3d(0, 0, 5));
  EXPECT_EQ(t1.start.euler_rpy_rad, Eigen::Vector3d::Zero());
  EXPECT_EQ(t1.goal_ned_m, Eigen::Vector3d(7, 6, 10));
  EXPECT_TRUE(t1.start.thruster_efficiency.empty());
  EXPECT_EQ(t1.start.current_ned_mps, Eigen::Vector3d::Zero());

  // Test 2: facing straight away from the way-point.
  const EvaluationEpisode t2 = scenario_episodes(c, Scenario::kTest2).at(0);
  const double bearing = std::atan2(6.0, 7.0);
  EXPECT_NEAR(std::cos(t2.start.euler_rpy_rad[2] - bearing), -1.0, 1e-12);
  EXPECT_LE(std::abs(t2.start.euler_rpy_rad[2]), kPi);
  EXPECT_EQ(t2.goal_ned_m, t1.goal_ned_m);

  // Fault: T1 at 10 %, the others healthy.
  const EvaluationEpisode f = scenario_episodes(c, Scenario::kFault).at(0);
  ASSERT_EQ(f.start.thruster_efficiency.size(), 6u);
  EXPECT_DOUBLE_EQ(f.start.thruster_efficiency[0], 0.1);
  for (std::size_t i = 1; i < 6; ++i) EXPECT_DOUBLE_EQ(f.start.thruster_efficiency[i], 1.0);

  // Current: 0.3 m/s, horizontal, perpendicular to the start->goal line.
  const EvaluationEpisode cur = scenario_episodes(c, Scenario::kCurrent).at(0);
  EXPECT_NEAR(cur.start.current_ned_mps.norm(), 0.3, 1e-12);
  EXPECT_NEAR(cur.start.current_ned_mps.z(), 0.0, 1e-12);
  EXPECT_NEAR(cur.start.current_ned_mps.head<2>().dot(Eigen::Vector2d(7, 6)), 0.0, 1e-12);
}

TEST(Scenarios, SuiteIsDeterministicPerSeedAndInsideTheRegion) {
  EvaluationConfig c = six_thruster_config();
  const std::vector<EvaluationEpisode> a = scenario_episodes(c, Scenario::kSuite);
  const std::vector<EvaluationEpisode> b = scenario_episodes(c, Scenario::kSuite);
  ASSERT_EQ(a.size(), 100u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].goal_ned_m, b[i].goal_ned_m);
    EXPECT_EQ(a[i].index, static_cast<int>(i));
    EXPECT_EQ(a[i].start.position_ned_m, c.task.start_position_ned_m);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(a[i].goal_ned_m[k], c.task.goal_min_ned_m[k]);
      EXPECT_LE(a[i].goal_ned_m[k], c.task.goal_max_ned_m[k]);
    }
  }
  c.seed = 2;
  EXPECT_NE(scenario_episodes(c, Scenario::kSuite)[0].goal_ned_m, a[0].goal_ned_m);
  c.fault_thruster = 6;
  EXPECT_THROW(scenario_episodes(c, Scenario::kFault), std::invalid_argument);
}

TEST(Evaluation, WritesSummaryAndTrajectoriesWithTheRightColumns) {
  TempDir dir;
  EvaluationConfig c;
  c.suite_episodes = 3;
  c.suite_trajectories = 2;
  agent::PidController pid(nessie());
  const std::vector<SummaryRow> rows = run_evaluation(
      nessie(), c, pid, {Scenario::kTest1, Scenario::kFault, Scenario::kSuite}, dir.path("out"));
  ASSERT_EQ(rows.size(), 5u);

  const auto summary = read_csv(dir.path("out/summary.csv"));
  ASSERT_EQ(summary.size(), 6u);
  const std::vector<std::string> header = {
      "scenario",      "controller",      "episode",
      "goal_x",        "goal_y",          "goal_z",
      "reached",       "time_to_reach_s", "mean_error_after_reach_m",
      "final_error_m", "thrust_energy",   "end_reason",
      "smoothness"};
  EXPECT_EQ(summary[0], header);
  EXPECT_EQ(summary[1][0], "test1");
  EXPECT_EQ(summary[1][1], "pid");
  EXPECT_EQ(summary[1][2], "0");
  EXPECT_EQ(summary[1][3], "7");
  EXPECT_EQ(summary[1][4], "6");
  EXPECT_EQ(summary[1][5], "10");
  EXPECT_EQ(summary[1][6], "1");
  EXPECT_NEAR(std::stod(summary[1][7]), rows[0].time_to_reach_s, 1e-6);
  // Smoothness, the last column: the PID's commands change, by less than full scale a step.
  EXPECT_NEAR(std::stod(summary[1][12]), rows[0].smoothness, 1e-6);
  EXPECT_GT(rows[0].smoothness, 0.0);
  EXPECT_LT(rows[0].smoothness, 0.5);
  EXPECT_EQ(summary[2][0], "fault");
  EXPECT_EQ(summary[5][0], "suite");
  EXPECT_EQ(summary[5][2], "2");
  for (std::size_t i = 1; i < summary.size(); ++i) EXPECT_EQ(summary[i].size(), header.size());

  // Trajectories: every paper test, the first two of the suite.
  namespace fs = std::filesystem;
  EXPECT_TRUE(fs::exists(dir.path("out/trajectories/test1_0.csv")));
  EXPECT_TRUE(fs::exists(dir.path("out/trajectories/fault_0.csv")));
  EXPECT_TRUE(fs::exists(dir.path("out/trajectories/suite_0.csv")));
  EXPECT_TRUE(fs::exists(dir.path("out/trajectories/suite_1.csv")));
  EXPECT_FALSE(fs::exists(dir.path("out/trajectories/suite_2.csv")));

  const auto traj = read_csv(dir.path("out/trajectories/fault_0.csv"));
  std::vector<std::string> columns = {"t", "x", "y", "z", "phi", "theta", "psi",
                                      "u", "v", "w", "p", "q",   "r"};
  for (int i = 1; i <= 6; ++i) columns.push_back("cmd_" + std::to_string(i));
  for (int i = 1; i <= 6; ++i) columns.push_back("thrust_" + std::to_string(i));
  columns.push_back("distance_m");
  EXPECT_EQ(traj[0], columns);
  ASSERT_EQ(traj.size(), 1u + 701u);  // the reset state, then 700 steps of 0.1 s
  EXPECT_EQ(traj[1][0], "0");
  EXPECT_EQ(traj[1][3], "5");
  EXPECT_NEAR(std::stod(traj.back()[0]), 70.0, 1e-9);
  // The faulted T1 never realises more than 10 % of the maximum thrust, though it is asked to.
  double max_cmd_1 = 0, max_thrust_1 = 0;
  for (std::size_t i = 1; i < traj.size(); ++i) {
    ASSERT_EQ(traj[i].size(), columns.size());
    max_cmd_1 = std::max(max_cmd_1, std::abs(std::stod(traj[i][13])));
    max_thrust_1 = std::max(max_thrust_1, std::abs(std::stod(traj[i][19])));
  }
  EXPECT_GT(max_cmd_1, 0.5 * 39.24);
  EXPECT_LE(max_thrust_1, 0.1 * 39.24 + 1e-6);
  // distance_m agrees with the position.
  const auto& last = traj.back();
  const double d =
      std::hypot(7 - std::stod(last[1]), 6 - std::stod(last[2]), 10 - std::stod(last[3]));
  EXPECT_NEAR(std::stod(last.back()), d, 1e-6);
}

TEST(Evaluation, NeverReachedLeavesTheReachCellsEmpty) {
  TempDir dir;
  SummaryRow row;
  row.scenario = "test1";
  row.controller = "policy";
  row.goal_ned_m = Eigen::Vector3d(7, 6, 10);
  row.final_error_m = 9.5;
  row.thrust_energy = 12.0;
  row.end_reason = task::EndReason::kTimeLimit;
  write_summary_csv(dir.path("s.csv"), {row});
  const auto csv = read_csv(dir.path("s.csv"));
  ASSERT_EQ(csv.size(), 2u);
  ASSERT_EQ(csv[1].size(), 13u);
  EXPECT_EQ(csv[1][6], "0");
  EXPECT_EQ(csv[1][7], "");
  EXPECT_EQ(csv[1][8], "");
  EXPECT_EQ(csv[1][9], "9.5");
  EXPECT_EQ(csv[1][11], "time_limit");
  // An unwritable path is an error naming it.
  try {
    write_summary_csv(dir.path("missing/dir/s.csv"), {row});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing/dir/s.csv"), std::string::npos);
  }
}

TEST(Evaluation, EpisodesRunTheEvaluationLengthNotTheTrainingOne) {
  TempDir dir;
  EvaluationConfig c;
  c.task.max_steps = 50;  // a short training episode
  agent::PidController pid(nessie());
  run_evaluation(nessie(), c, pid, {Scenario::kTest1}, dir.path("out"));
  const auto trajectory = read_csv(dir.path("out/trajectories/test1_0.csv"));
  EXPECT_EQ(trajectory.size(), 1u + 1u + 700u);  // header, the reset state, 700 steps
  c.episode_steps = 120;
  run_evaluation(nessie(), c, pid, {Scenario::kTest1}, dir.path("short"));
  EXPECT_EQ(read_csv(dir.path("short/trajectories/test1_0.csv")).size(), 1u + 1u + 120u);
}

TEST(Evaluation, SummaryTableHasOneLinePerScenario) {
  agent::PidController pid(nessie());
  EvaluationConfig c;
  c.suite_episodes = 2;
  const std::vector<SummaryRow> rows =
      run_evaluation(nessie(), c, pid, {Scenario::kTest1, Scenario::kSuite}, "");
  const std::string table = format_summary_table(rows);
  EXPECT_NE(table.find("test1    pid                1/1"), std::string::npos) << table;
  EXPECT_NE(table.find("suite    pid                2/2"), std::string::npos) << table;
}

/// A suite row of episode i: reached at time_s (negative: never) with the given hold error.
SummaryRow suite_row(int i, double time_s, double hold_m = 0.05) {
  SummaryRow r;
  r.scenario = "suite";
  r.episode = i;
  r.goal_ned_m = Eigen::Vector3d(i, -i, 5.0);
  r.reached = time_s >= 0.0;
  r.time_to_reach_s = time_s;
  r.mean_error_after_reach_m = r.reached ? hold_m : -1.0;
  return r;
}

TEST(ValidationScore, WorstRatioToTheReferenceOverTheWayPointsBothReached) {
  const std::vector<SummaryRow> reference = {suite_row(0, 10.0), suite_row(1, 8.0),
                                             suite_row(2, -1.0), suite_row(3, 12.0)};
  // Faster on 0 and 3, slower on 1 (9.2 / 8.0 = 1.15), alone on 2 (no ratio there).
  const std::vector<SummaryRow> rows = {suite_row(0, 9.0, 0.1), suite_row(1, 9.2, 0.2),
                                        suite_row(2, 20.0, 0.3), suite_row(3, 6.0, 0.2)};
  const ValidationScore s = score_against_reference(rows, reference);
  EXPECT_EQ(s.episodes, 4);
  EXPECT_EQ(s.reached, 4);
  EXPECT_NEAR(s.max_time_ratio, 1.15, 1e-12);
  EXPECT_NEAR(s.mean_time_s, (9.0 + 9.2 + 20.0 + 6.0) / 4, 1e-12);
  EXPECT_NEAR(s.mean_hold_m, 0.2, 1e-12);

  // Not reached: counted, but no time, hold or ratio.
  const std::vector<SummaryRow> missed = {suite_row(0, -1.0), suite_row(1, 4.0), suite_row(2, -1.0),
                                          suite_row(3, -1.0)};
  const ValidationScore m = score_against_reference(missed, reference);
  EXPECT_EQ(m.reached, 1);
  EXPECT_NEAR(m.max_time_ratio, 0.5, 1e-12);
  EXPECT_NEAR(m.mean_time_s, 4.0, 1e-12);
}

TEST(ValidationScore, RowsThatAreNotTheReferencesEpisodesAreAnError) {
  const std::vector<SummaryRow> reference = {suite_row(0, 10.0), suite_row(1, 8.0)};
  EXPECT_THROW(score_against_reference({suite_row(0, 9.0)}, reference), std::invalid_argument);
  std::vector<SummaryRow> moved = {suite_row(0, 9.0), suite_row(1, 8.0)};
  moved[1].goal_ned_m.x() += 1.0;
  try {
    score_against_reference(moved, reference);
    FAIL() << "a different way-point was scored";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("episode 1"), std::string::npos) << e.what();
  }
}

TEST(QuickEvaluator, ScoresTheSameOnAnyNumberOfThreads) {
  task::TaskConfig task;
  task.layout = task::StateLayout::kExtendedThrust;
  task::apply_vehicle(nessie().facts(), task);
  const nn::Mlp policy =
      nn::network_from_bytes(nn::read_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn"), 1);
  const QuickEvaluator quick(nessie(), task, 4, 2);
  const ValidationScore one = quick.evaluate(policy);
  EXPECT_EQ(one.episodes, 6);
  for (const int threads : {2, 3}) {
    const ValidationScore many = quick.evaluate(policy, threads);
    EXPECT_EQ(many.reached, one.reached) << threads;
    EXPECT_EQ(many.episodes, one.episodes) << threads;
    EXPECT_EQ(many.mean_time_s, one.mean_time_s) << threads;
    EXPECT_EQ(many.mean_hold_m, one.mean_hold_m) << threads;
    EXPECT_EQ(many.max_time_ratio, one.max_time_ratio) << threads;
    EXPECT_EQ(many.mean_energy, one.mean_energy) << threads;
    EXPECT_EQ(many.mean_smoothness, one.mean_smoothness) << threads;
  }
}

TEST(Ranking, RanksReachedThenHoldingThenWorstRatioThenMeanTime) {
  const Ranking training{0.15, true, std::nullopt};
  ValidationScore a, b;
  a.episodes = b.episodes = 40;
  a.reached = 40;
  b.reached = 39;
  a.max_time_ratio = 2.0;
  b.max_time_ratio = 0.8;
  a.mean_hold_m = b.mean_hold_m = 0.05;
  EXPECT_TRUE(ranks_above(a, b, training));  // reaching more way-points comes first
  EXPECT_FALSE(ranks_above(b, a, training));

  b.reached = 40;
  EXPECT_TRUE(ranks_above(b, a, training));  // then the worst ratio to the PID
  EXPECT_FALSE(ranks_above(a, b, training));

  b.mean_hold_m = 0.2;  // faster, but drifting: holding within the limit comes before speed
  EXPECT_TRUE(ranks_above(a, b, training));
  a.mean_hold_m = 0.3;  // both outside: the closer wins
  EXPECT_TRUE(ranks_above(b, a, training));

  a.mean_hold_m = b.mean_hold_m = 0.05;
  a.max_time_ratio = b.max_time_ratio = 0.9;
  a.mean_time_s = 9.0;
  b.mean_time_s = 9.5;
  EXPECT_TRUE(ranks_above(a, b, training));  // the same worst ratio: the shorter mean time
  EXPECT_FALSE(ranks_above(b, a, training));
  EXPECT_FALSE(ranks_above(a, a, training));
}

TEST(Ranking, TheFineTuningsRankingSkipsTheWorstRatio) {
  const Ranking finetuning{0.15, false, std::nullopt};
  ValidationScore a, b;
  a.episodes = b.episodes = a.reached = b.reached = 40;
  a.mean_hold_m = b.mean_hold_m = 0.05;
  a.max_time_ratio = 1.2;  // slower than the PID on one way-point...
  b.max_time_ratio = 0.9;
  a.mean_time_s = 8.0;  // ...but a second sooner on the mean: what the fine-tuning lowers
  b.mean_time_s = 9.0;
  EXPECT_TRUE(ranks_above(a, b, finetuning));
  EXPECT_FALSE(ranks_above(b, a, finetuning));
  EXPECT_TRUE(ranks_above(b, a, Ranking{0.15, true, std::nullopt}));
  a.mean_hold_m = 0.3;  // holding still comes before time
  EXPECT_TRUE(ranks_above(b, a, finetuning));
}

// A fine-tuning that prices thrust keeps its weights by its prices: after reaching, the
// smaller mean time + hold_weight x hold + energy_weight x energy + smoothness_weight x
// smoothness, even against a sooner arrival that spends more thrust and chatters.
TEST(Ranking, APricedFineTuningRanksByItsPricedTime) {
  Ranking priced{0.15, false, Ranking::Prices{10.0, 0.1, 100.0}};
  ValidationScore frugal, fast;
  frugal.episodes = fast.episodes = frugal.reached = fast.reached = 40;
  frugal.mean_time_s = 10.0;
  frugal.mean_hold_m = 0.03;
  frugal.mean_energy = 35.0;
  frugal.mean_smoothness = 0.007;
  fast.mean_time_s = 9.5;  // half a second sooner...
  fast.mean_hold_m = 0.03;
  fast.mean_energy = 60.0;  // ...for 2.5 s of energy
  fast.mean_smoothness = 0.02;
  EXPECT_DOUBLE_EQ(priced_time_s(frugal, *priced.prices), 10.0 + 0.3 + 3.5 + 0.7);
  EXPECT_TRUE(ranks_above(frugal, fast, priced));
  EXPECT_FALSE(ranks_above(fast, frugal, priced));
  EXPECT_TRUE(ranks_above(fast, frugal, Ranking{0.15, false, std::nullopt}));  // unpriced
  fast.reached = 41;  // reaching more still comes first
  EXPECT_TRUE(ranks_above(fast, frugal, priced));
}

// The validation score's energy and smoothness are means over every way-point.
TEST(Ranking, TheScoreCarriesMeanEnergyAndSmoothness) {
  std::vector<SummaryRow> rows(2), reference(2);
  for (int i = 0; i < 2; ++i) {
    rows[static_cast<std::size_t>(i)].episode = reference[static_cast<std::size_t>(i)].episode = i;
  }
  rows[0].reached = true;
  rows[0].time_to_reach_s = 8.0;
  rows[0].thrust_energy = 30.0;
  rows[0].smoothness = 0.01;
  rows[1].thrust_energy = 50.0;  // not reached, still counted
  rows[1].smoothness = 0.03;
  const ValidationScore s = score_against_reference(rows, reference);
  EXPECT_DOUBLE_EQ(s.mean_energy, 40.0);
  EXPECT_DOUBLE_EQ(s.mean_smoothness, 0.02);
  EXPECT_EQ(s.reached, 1);
}

TEST(Evaluation, InfersTheLayoutFromThePolicyInputs) {
  EXPECT_EQ(infer_layout(18, 6), task::StateLayout::kPaper);
  EXPECT_EQ(infer_layout(23, 6), task::StateLayout::kExtended);
  EXPECT_EQ(infer_layout(20, 8), task::StateLayout::kPaper);
  EXPECT_EQ(infer_layout(29, 6), task::StateLayout::kExtendedThrust);
  EXPECT_EQ(infer_layout(33, 8), task::StateLayout::kExtendedThrust);
  EXPECT_THROW(infer_layout(19, 6), std::invalid_argument);
}

nn::Mlp actor(int inputs) {
  nn::Mlp net(nn::MlpSpec::actor(inputs, {16}, 6), 1);
  nn::Rng rng(3);
  net.init_lillicrap(rng);
  return net;
}

/// make_eval_controller's error message for a request, or "" if it succeeded.
std::string controller_error(const EvalRequest& request, EvaluationConfig& config) {
  try {
    make_eval_controller(request, nessie(), config);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(EvalCommand, PolicyFilesLoadWithTheirLayout) {
  TempDir dir;
  nn::save_network_file(dir.path("extended.net"), actor(23));
  nn::save_network_file(dir.path("paper.net"), actor(18));
  EvalRequest request;
  request.controller = "policy";
  request.policy_path = dir.path("extended.net");
  EvaluationConfig config;
  auto controller = make_eval_controller(request, nessie(), config);
  EXPECT_EQ(controller->name(), "policy");
  EXPECT_EQ(config.task.layout, task::StateLayout::kExtended);
  request.policy_path = dir.path("paper.net");
  controller = make_eval_controller(request, nessie(), config);
  EXPECT_EQ(config.task.layout, task::StateLayout::kPaper);
  // And it runs (an untrained policy need not reach anything).
  const std::vector<SummaryRow> rows =
      run_evaluation(nessie(), config, *controller, {Scenario::kTest1}, "");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].controller, "policy");
}

TEST(EvalCommand, ClearErrorsForBadPolicyFiles) {
  TempDir dir;
  EvaluationConfig config;
  EvalRequest request;
  request.controller = "policy";

  request.policy_path = dir.path("nothing_here.net");
  std::string error = controller_error(request, config);
  EXPECT_NE(error.find("nothing_here.net"), std::string::npos) << error;

  {
    std::ofstream garbage(dir.path("garbage.net"));
    garbage << "this is not a network";
  }
  request.policy_path = dir.path("garbage.net");
  error = controller_error(request, config);
  EXPECT_NE(error.find("garbage.net"), std::string::npos) << error;

  // A network with a size that fits no layout.
  nn::save_network_file(dir.path("odd.net"), actor(20));
  request.policy_path = dir.path("odd.net");
  error = controller_error(request, config);
  EXPECT_NE(error.find("odd.net"), std::string::npos) << error;
  EXPECT_NE(error.find("18 (paper), 23 (extended) or 29 (extended_thrust)"), std::string::npos)
      << error;

  // An explicit layout that the network does not fit.
  nn::save_network_file(dir.path("extended.net"), actor(23));
  request.policy_path = dir.path("extended.net");
  request.layout = "paper";
  error = controller_error(request, config);
  EXPECT_NE(error.find("extended.net"), std::string::npos) << error;
  EXPECT_NE(error.find("in=18"), std::string::npos) << error;

  // A truncated file (checksum and size checks).
  std::vector<std::uint8_t> bytes = nn::read_file(dir.path("extended.net"));
  bytes.resize(bytes.size() / 2);
  nn::write_file_atomically(dir.path("truncated.net"), bytes);
  request.layout.clear();
  request.policy_path = dir.path("truncated.net");
  error = controller_error(request, config);
  EXPECT_NE(error.find("truncated.net"), std::string::npos) << error;

  // No policy at all, or both a policy and the PID, or an unknown controller.
  request.policy_path.clear();
  EXPECT_THROW(make_eval_controller(request, nessie(), config), std::invalid_argument);
  request.controller = "pid";
  request.policy_path = dir.path("extended.net");
  EXPECT_THROW(make_eval_controller(request, nessie(), config), std::invalid_argument);
  request.controller = "lqr";
  EXPECT_THROW(make_eval_controller(request, nessie(), config), std::invalid_argument);
}

TEST(EvalCommand, RunsThePidEndToEnd) {
  TempDir dir;
  EvalRequest request;
  request.controller = "pid";
  request.scenario = "test2";
  request.out_dir = dir.path("run");
  request.vehicle_path = vehicle_path();
  std::ostringstream out;
  const std::vector<SummaryRow> rows = run_eval_request(request, out);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0].reached);
  EXPECT_NE(out.str().find("test2"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir.path("run/summary.csv")));
  EXPECT_TRUE(std::filesystem::exists(dir.path("run/trajectories/test2_0.csv")));
  request.out_dir.clear();
  EXPECT_THROW(run_eval_request(request, out), std::invalid_argument);
  request.out_dir = dir.path("run");
  request.vehicle_path = dir.path("no_vehicle.yaml");
  EXPECT_THROW(run_eval_request(request, out), std::runtime_error);
}

// The policy committed under config/ (README: `auvrl eval` works at once after install) still
// loads with its layout and passes the paper's tests: within 0.5 m sooner than the paper
// (25 s, 17 s, 30 s), holding within 0.3 m, and the whole suite. Guards the file against
// changes to the network format, the state layout or the vehicle model.
TEST(EvalCommand, TheCommittedPolicyPassesThePapersTests) {
  TempDir dir;
  EvalRequest request;
  request.policy_path = std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn";
  request.scenario = "all";
  request.out_dir = dir.path("run");
  request.vehicle_path = vehicle_path();
  std::ostringstream out;
  const std::vector<SummaryRow> rows = run_eval_request(request, out);
  const std::vector<std::pair<std::string, double>> paper_times_s = {
      {"test1", 25.0}, {"test2", 17.0}, {"fault", 30.0}};
  for (const auto& [scenario, paper_time_s] : paper_times_s) {
    bool found = false;
    for (const SummaryRow& row : rows) {
      if (row.scenario != scenario) continue;
      found = true;
      EXPECT_TRUE(row.reached) << scenario;
      EXPECT_LT(row.time_to_reach_s, paper_time_s) << scenario;
      EXPECT_LT(row.mean_error_after_reach_m, 0.3) << scenario;
    }
    EXPECT_TRUE(found) << scenario;
  }
  int suite = 0, suite_reached = 0;
  for (const SummaryRow& row : rows) {
    if (row.scenario != "suite") continue;
    ++suite;
    suite_reached += row.reached ? 1 : 0;
  }
  EXPECT_EQ(suite, 100);
  EXPECT_GE(suite_reached, 95);
}

}  // namespace
}  // namespace auvrl::eval
