// The robustness suite: its groups and what each draws, the streams (reproducible, one per
// group and episode), the metrics and the comparison on hand-made rows, command smoothness on
// a known sequence, and a short real run of the PID writing its files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "agent/controller.hpp"
#include "agent/pid_controller.hpp"
#include "agent_test_util.hpp"
#include "eval/robustness.hpp"

namespace auvrl::eval {
namespace {

using test_support::nessie;
using test_support::read_csv;
using test_support::TempDir;

constexpr double kPi = 3.14159265358979323846;

EvaluationConfig config() {
  EvaluationConfig c;
  c.task.num_thrusters = 6;
  return c;
}

/// The episodes of one group.
std::vector<EvaluationEpisode> of_group(const std::vector<EvaluationEpisode>& all,
                                        const std::string& group) {
  std::vector<EvaluationEpisode> out;
  for (const EvaluationEpisode& e : all) {
    if (e.group == group) out.push_back(e);
  }
  return out;
}

bool same_draw(const EvaluationEpisode& a, const EvaluationEpisode& b) {
  return a.group == b.group && a.index == b.index && a.goal_ned_m == b.goal_ned_m &&
         a.start.position_ned_m == b.start.position_ned_m &&
         a.start.euler_rpy_rad == b.start.euler_rpy_rad &&
         a.start.velocity_body_mps == b.start.velocity_body_mps &&
         a.start.current_ned_mps == b.start.current_ned_mps && a.start.seed == b.start.seed &&
         a.start.thruster_efficiency == b.start.thruster_efficiency &&
         a.safety_radius_m == b.safety_radius_m;
}

bool inside_region(const task::TaskConfig& task, const Eigen::Vector3d& p) {
  return (p.array() >= task.goal_min_ned_m.array()).all() &&
         (p.array() <= task.goal_max_ned_m.array()).all();
}

TEST(RobustnessGroups, EveryThrusterTwiceAndTheOtherGroupsOnce) {
  const std::vector<RobustnessGroup> groups = robustness_groups(6, {"T1_fwd", "T2"});
  ASSERT_EQ(groups.size(), 3u + 12u + 10u);
  std::set<std::string> names;
  for (const RobustnessGroup& g : groups) names.insert(g.name);
  EXPECT_EQ(names.size(), groups.size());
  for (const char* name :
       {"rest_start", "any_start", "far_waypoint", "t1_10pct", "t1_0pct", "t6_10pct", "t6_0pct",
        "current", "varying_current", "sensor_noise", "drag_x0.6", "drag_x1.5", "added_mass_x1.5",
        "mass_x1.2", "thrust_x0.7", "lag_0.6s", "buoyancy_+2kg"}) {
    EXPECT_EQ(names.count(name), 1u) << name;
  }
  // The vehicle's thruster names label the descriptions (T<i> without one).
  EXPECT_EQ(groups[3].description, "T1_fwd at 10 % efficiency");
  EXPECT_EQ(groups[4].description, "T1_fwd at 0 % efficiency");
  EXPECT_EQ(groups[7].description, "T3 at 10 % efficiency");
  EXPECT_EQ(robustness_groups(4).size(), 3u + 8u + 10u);
}

// The group facing_away is not the bar's: only asked for, after the others.
TEST(RobustnessGroups, FacingAwayOnlyWhenAskedForAndLast) {
  const std::vector<RobustnessGroup> with = robustness_groups(6, {}, true);
  ASSERT_EQ(with.size(), 26u);
  EXPECT_EQ(with.back().name, "facing_away");
  EXPECT_TRUE(with.back().draw.facing_away);
  for (const RobustnessGroup& g : robustness_groups(6)) EXPECT_NE(g.name, "facing_away");
  EvaluationConfig c = config();
  EXPECT_TRUE(of_group(robustness_episodes(c, 6, 3, 7), "facing_away").empty());
  c.robustness_facing_away = true;
  EXPECT_EQ(of_group(robustness_episodes(c, 6, 3, 7), "facing_away").size(), 3u);
}

// Each starts at rest at the task's start, level, the way-point in the region and straight
// behind it horizontally; facing_away_episodes draws the suite's group, more of it.
TEST(RobustnessEpisodes, FacingAwayPutsTheWayPointStraightBehind) {
  EvaluationConfig c = config();
  const std::vector<EvaluationEpisode> behind = facing_away_episodes(c, 6, 40, 7);
  ASSERT_EQ(behind.size(), 40u);
  for (const EvaluationEpisode& e : behind) {
    EXPECT_EQ(e.group, "facing_away");
    EXPECT_EQ(e.start.position_ned_m, c.task.start_position_ned_m);
    EXPECT_TRUE(inside_region(c.task, e.goal_ned_m));
    EXPECT_EQ(e.start.euler_rpy_rad[0], 0.0);
    EXPECT_EQ(e.start.euler_rpy_rad[1], 0.0);
    EXPECT_TRUE(e.start.velocity_body_mps.isZero());
    const double yaw = e.start.euler_rpy_rad[2];
    EXPECT_LE(std::abs(yaw), kPi);
    // The horizontal way-point in the body frame: behind (x < 0), nothing to either side.
    const Eigen::Vector3d to_goal = e.goal_ned_m - e.start.position_ned_m;
    const double ahead_m = std::cos(yaw) * to_goal[0] + std::sin(yaw) * to_goal[1];
    const double starboard_m = -std::sin(yaw) * to_goal[0] + std::cos(yaw) * to_goal[1];
    EXPECT_LT(ahead_m, 0.0);
    EXPECT_NEAR(starboard_m, 0.0, 1e-9);
  }
  c.robustness_facing_away = true;
  const auto suite = of_group(robustness_episodes(c, 6, 5, 7), "facing_away");
  ASSERT_EQ(suite.size(), 5u);
  for (std::size_t i = 0; i < suite.size(); ++i) EXPECT_TRUE(same_draw(suite[i], behind[i])) << i;
  EXPECT_THROW(facing_away_episodes(c, 6, -1, 7), std::invalid_argument);
}

TEST(RobustnessEpisodes, ReproducibleAndEachEpisodeItsOwnStream) {
  const EvaluationConfig c = config();
  const std::vector<EvaluationEpisode> a = robustness_episodes(c, 6, 5, 7);
  const std::vector<EvaluationEpisode> b = robustness_episodes(c, 6, 5, 7);
  ASSERT_EQ(a.size(), 25u * 5u);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(same_draw(a[i], b[i])) << i;
  // Another seed, other draws.
  EXPECT_NE(robustness_episodes(c, 6, 5, 8)[0].goal_ned_m, a[0].goal_ned_m);
  // More episodes per group leave the first ones as they were.
  const std::vector<EvaluationEpisode> more = robustness_episodes(c, 6, 8, 7);
  for (const std::string group : {"rest_start", "current", "buoyancy_+2kg"}) {
    const auto few = of_group(a, group);
    const auto many = of_group(more, group);
    ASSERT_EQ(many.size(), 8u);
    for (std::size_t i = 0; i < few.size(); ++i) EXPECT_TRUE(same_draw(few[i], many[i])) << group;
  }
  // Fewer groups (a four-thruster vehicle has no t5 and t6 groups) leave the others as they were.
  const std::vector<EvaluationEpisode> four = robustness_episodes(c, 4, 5, 7);
  for (const std::string group : {"rest_start", "t2_0pct", "sensor_noise", "lag_0.6s"}) {
    const auto six = of_group(a, group);
    const auto other = of_group(four, group);
    ASSERT_EQ(other.size(), six.size());
    for (std::size_t i = 0; i < six.size(); ++i) {
      EXPECT_EQ(other[i].goal_ned_m, six[i].goal_ned_m) << group;
      EXPECT_EQ(other[i].start.seed, six[i].start.seed) << group;
    }
  }
  // Two groups with the same draw of start and way-point still differ: their own streams.
  EXPECT_NE(of_group(a, "drag_x0.6")[0].goal_ned_m, of_group(a, "drag_x1.5")[0].goal_ned_m);
  EXPECT_THROW(robustness_episodes(c, 6, -1, 7), std::invalid_argument);
}

TEST(RobustnessEpisodes, RestStartsAtRestFacingRandomHeadingsToTheRegion) {
  const EvaluationConfig c = config();
  const auto episodes = robustness_episodes(c, 6, 20, 1);
  const auto rest = of_group(episodes, "rest_start");
  ASSERT_EQ(rest.size(), 20u);
  double min_yaw = kPi, max_yaw = -kPi;
  for (const EvaluationEpisode& e : episodes) {
    EXPECT_EQ(e.scenario, Scenario::kRobustness);
    const double yaw = e.start.euler_rpy_rad[2];
    EXPECT_GE(yaw, -kPi);
    EXPECT_LT(yaw, kPi);
  }
  for (const EvaluationEpisode& e : rest) {
    EXPECT_EQ(e.start.position_ned_m, c.task.start_position_ned_m);
    EXPECT_EQ(e.start.euler_rpy_rad.head<2>(), Eigen::Vector2d::Zero());
    EXPECT_EQ(e.start.velocity_body_mps, Eigen::Vector3d::Zero());
    EXPECT_EQ(e.start.angular_rate_body_rad_s, Eigen::Vector3d::Zero());
    EXPECT_TRUE(inside_region(c.task, e.goal_ned_m));
    EXPECT_GE((e.goal_ned_m - e.start.position_ned_m).norm(), kRobustnessMinGoalDistanceM);
    EXPECT_TRUE(e.start.thruster_efficiency.empty());
    EXPECT_TRUE(e.start.model_variation.is_identity());
    EXPECT_EQ(e.safety_radius_m, 0.0);  // the task's 20 m
    min_yaw = std::min(min_yaw, e.start.euler_rpy_rad[2]);
    max_yaw = std::max(max_yaw, e.start.euler_rpy_rad[2]);
  }
  EXPECT_GT(max_yaw - min_yaw, kPi);  // spread, not one heading
}

TEST(RobustnessEpisodes, AnyStartAndFarWayPointsDrawWhatTheySay) {
  const EvaluationConfig c = config();
  const auto episodes = robustness_episodes(c, 6, 20, 1);
  for (const EvaluationEpisode& e : of_group(episodes, "any_start")) {
    EXPECT_TRUE(inside_region(c.task, e.start.position_ned_m));
    EXPECT_TRUE(inside_region(c.task, e.goal_ned_m));
    EXPECT_LE(e.start.euler_rpy_rad.head<2>().cwiseAbs().maxCoeff(), 0.1);
    EXPECT_LE(e.start.velocity_body_mps.cwiseAbs().maxCoeff(), 0.3);
    EXPECT_LE(e.start.angular_rate_body_rad_s.cwiseAbs().maxCoeff(), 0.1);
    EXPECT_GT(e.start.velocity_body_mps.norm(), 0.0);
    // The safety sphere grows by the start's distance: no episode ends at its first step.
    EXPECT_NEAR(e.safety_radius_m,
                (e.goal_ned_m - e.start.position_ned_m).norm() + c.task.beta_max_m, 1e-9);
  }
  const double region_farthest = std::sqrt(10.0 * 10.0 + 10.0 * 10.0 + 10.0 * 10.0);  // 17.3 m
  for (const EvaluationEpisode& e : of_group(episodes, "far_waypoint")) {
    const double d = (e.goal_ned_m - e.start.position_ned_m).norm();
    EXPECT_EQ(e.start.position_ned_m, c.task.start_position_ned_m);
    EXPECT_GT(d, region_farthest - 1e-9);
    EXPECT_LE(d, kRobustnessFarMaxM);
    EXPECT_GE(e.goal_ned_m.z(), c.task.goal_min_ned_m.z());
    EXPECT_LE(e.goal_ned_m.z(), c.task.goal_max_ned_m.z());
    EXPECT_NEAR(e.safety_radius_m, d + c.task.beta_max_m, 1e-9);
  }
  // A region reaching 30 m from the start leaves no room for far way-points.
  EvaluationConfig wide = config();
  wide.task.goal_max_ned_m = Eigen::Vector3d(30, 30, 15);
  EXPECT_THROW(robustness_episodes(wide, 6, 1, 1), std::invalid_argument);
}

TEST(RobustnessEpisodes, FaultsCurrentsNoiseAndModelsAsNamed) {
  const auto episodes = robustness_episodes(config(), 6, 10, 3);
  for (const EvaluationEpisode& e : of_group(episodes, "t3_0pct")) {
    ASSERT_EQ(e.start.thruster_efficiency.size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(e.start.thruster_efficiency[i], i == 2 ? 0.0 : 1.0);
    }
  }
  for (const EvaluationEpisode& e : of_group(episodes, "t6_10pct")) {
    EXPECT_EQ(e.start.thruster_efficiency[5], 0.1);
    EXPECT_EQ(e.start.thruster_efficiency[0], 1.0);
  }
  for (const EvaluationEpisode& e : of_group(episodes, "thrust_x0.7")) {
    EXPECT_EQ(e.start.thruster_efficiency, std::vector<double>(6, 0.7));
  }
  for (const EvaluationEpisode& e : of_group(episodes, "current")) {
    const double speed = e.start.current_ned_mps.norm();
    EXPECT_GE(speed, 0.1);
    EXPECT_LE(speed, 0.5);
    EXPECT_EQ(e.start.current_ned_mps.z(), 0.0);
    EXPECT_EQ(e.start.current_varying_sigma_mps, 0.0);
  }
  for (const EvaluationEpisode& e : of_group(episodes, "varying_current")) {
    EXPECT_NEAR(e.start.current_ned_mps.norm(), 0.2, 1e-12);
    EXPECT_EQ(e.start.current_varying_sigma_mps, 0.03);
    EXPECT_EQ(e.start.current_varying_time_constant_s, 30.0);
    // The varying part blows along the constant part.
    const double d = e.start.current_varying_direction_rad;
    EXPECT_NEAR(e.start.current_ned_mps.x(), 0.2 * std::cos(d), 1e-12);
    EXPECT_NEAR(e.start.current_ned_mps.y(), 0.2 * std::sin(d), 1e-12);
  }
  for (const EvaluationEpisode& e : of_group(episodes, "sensor_noise")) {
    EXPECT_EQ(e.start.sensor_noise.position_sigma_m, 0.1);
    EXPECT_EQ(e.start.sensor_noise.attitude_sigma_rad, 0.02);
    EXPECT_EQ(e.start.sensor_noise.linear_velocity_sigma_mps, 0.05);
    EXPECT_EQ(e.start.sensor_noise.angular_velocity_sigma_rad_s, 0.02);
  }
  const auto variation = [&](const std::string& group) {
    return of_group(episodes, group).at(0).start.model_variation;
  };
  EXPECT_EQ(variation("drag_x0.6").quadratic_damping_scale, 0.6);
  EXPECT_EQ(variation("drag_x1.5").quadratic_damping_scale, 1.5);
  EXPECT_EQ(variation("added_mass_x1.5").added_mass_scale, 1.5);
  EXPECT_EQ(variation("mass_x1.2").mass_scale, 1.2);
  EXPECT_EQ(variation("lag_0.6s").thruster_lag_time_constant_s, 0.6);
  EXPECT_NEAR(variation("buoyancy_+2kg").extra_buoyancy_n, 19.62, 1e-12);
  EXPECT_TRUE(variation("rest_start").is_identity());
  EXPECT_TRUE(variation("current").is_identity());
}

TEST(RobustnessRun, TheDeadThrusterProducesNothing) {
  EvaluationConfig c = config();
  task::apply_vehicle(nessie().facts(), c.task);
  const EvaluationEpisode e = of_group(robustness_episodes(c, 6, 1, 1), "t2_0pct").at(0);
  agent::PidController pid(nessie());
  std::vector<agent::TrajectoryRow> trajectory;
  const SummaryRow row = run_evaluation_episode(nessie(), c, pid, e, &trajectory);
  EXPECT_EQ(row.scenario, "t2_0pct");
  ASSERT_EQ(trajectory.size(), 701u);
  double commanded = 0.0;
  for (const agent::TrajectoryRow& r : trajectory) {
    EXPECT_EQ(r.thrust_realised_n[1], 0.0);
    commanded = std::max(commanded, std::abs(r.thrust_command_n[1]));
  }
  EXPECT_GT(commanded, 1.0);  // asked for, never given
}

TEST(Smoothness, MeanAbsoluteChangePerStepAndThrusterFromZero) {
  // Steps: from zero |1| + |0| = 1, then 0, then |-2| + |0.5| = 2.5: 3.5 over 3 steps x 2.
  EXPECT_NEAR(command_smoothness({{1.0, 0.0}, {1.0, 0.0}, {-1.0, 0.5}}), 3.5 / 6.0, 1e-12);
  EXPECT_EQ(command_smoothness({}), 0.0);
  EXPECT_EQ(command_smoothness({{0.0, 0.0}, {0.0, 0.0}}), 0.0);
  // Full ahead and full astern in turn: 2 a step but the first (1).
  std::vector<std::vector<double>> bang;
  for (int t = 0; t < 100; ++t) bang.push_back({t % 2 ? -1.0 : 1.0});
  EXPECT_NEAR(command_smoothness(bang), (1.0 + 99 * 2.0) / 100.0, 1e-12);
}

TEST(Smoothness, OfATrajectoryIsThatOfItsNormalisedCommands) {
  std::vector<agent::TrajectoryRow> rows(40);
  std::vector<std::vector<double>> normalised;
  for (std::size_t t = 0; t < rows.size(); ++t) {
    for (int i = 0; i < 6; ++i) {
      rows[t].thrust_command_n.push_back(std::sin(0.7 * static_cast<double>(t) + i) * 13.3);
    }
    if (t < 5) continue;  // from row 5 on
    std::vector<double> u = rows[t].thrust_command_n;
    for (double& f : u) f /= 20.0;
    normalised.push_back(u);
  }
  EXPECT_EQ(trajectory_smoothness(rows, 5, 20.0), command_smoothness(normalised));
  EXPECT_EQ(trajectory_smoothness(rows, 40, 20.0), 0.0);
}

SummaryRow row(const std::string& group, double time_s, double hold_m, double final_m,
               task::EndReason reason, double energy = 50.0, double smoothness = 0.1) {
  SummaryRow r;
  r.scenario = group;
  r.controller = "policy";
  r.reached = time_s >= 0.0;
  r.time_to_reach_s = time_s;
  r.mean_error_after_reach_m = r.reached ? hold_m : -1.0;
  r.final_error_m = final_m;
  r.end_reason = reason;
  r.thrust_energy = energy;
  r.smoothness = smoothness;
  return r;
}

TEST(RobustnessMetrics, HeldFlipsAndMeansOverTheReached) {
  using task::EndReason;
  EXPECT_TRUE(is_held(row("g", 10, 0.1, 0.2, EndReason::kReached)));
  EXPECT_FALSE(is_held(row("g", 10, 0.1, 0.6, EndReason::kTimeLimit)));  // drifted off
  EXPECT_FALSE(is_held(row("g", 10, 0.1, 0.3, EndReason::kFlipped)));    // did not last
  EXPECT_FALSE(is_held(row("g", -1, 0, 0.3, EndReason::kTimeLimit)));    // never reached
  const std::vector<SummaryRow> rows = {
      row("a", 10, 0.1, 0.2, EndReason::kReached, 40, 0.1),
      row("a", 20, 0.3, 0.7, EndReason::kTimeLimit, 60, 0.3),
      row("a", -1, 0, 5.0, EndReason::kFlipped, 80, 0.2),
      row("b", -1, 0, 9.0, EndReason::kBlowUp, 10, 0.0),
      row("a", -1, 0, 25.0, EndReason::kLeftRegion, 20, 0.4),
  };
  const std::vector<GroupMetrics> m = group_metrics(rows);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].group, "a");
  EXPECT_EQ(m[0].controller, "policy");
  EXPECT_EQ(m[0].episodes, 4);
  EXPECT_EQ(m[0].reached, 2);
  EXPECT_EQ(m[0].held, 1);
  EXPECT_EQ(m[0].flips, 1);
  EXPECT_EQ(m[0].blow_ups, 0);
  EXPECT_EQ(m[0].left_region, 1);
  EXPECT_NEAR(m[0].mean_time_s, 15.0, 1e-12);
  EXPECT_NEAR(m[0].mean_hold_m, 0.2, 1e-12);
  EXPECT_NEAR(m[0].mean_energy, 50.0, 1e-12);
  EXPECT_NEAR(m[0].mean_smoothness, 0.25, 1e-12);
  EXPECT_EQ(m[1].group, "b");
  EXPECT_EQ(m[1].blow_ups, 1);
  EXPECT_TRUE(std::isnan(m[1].mean_time_s));
  EXPECT_TRUE(std::isnan(m[1].mean_hold_m));
}

GroupMetrics metrics(const std::string& group, int held, double time_s, double hold_m,
                     double energy, double smoothness, int flips = 0) {
  GroupMetrics m;
  m.group = group;
  m.episodes = 20;
  m.reached = std::isnan(time_s) ? 0 : 20;
  m.held = held;
  m.flips = flips;
  m.mean_time_s = time_s;
  m.mean_hold_m = hold_m;
  m.mean_energy = energy;
  m.mean_smoothness = smoothness;
  return m;
}

/// The PID's three groups of the comparison tests.
std::vector<GroupMetrics> example_pid_groups() {
  const double none = std::nan("");
  return {metrics("ok", 18, 10, 0.05, 60, 0.01), metrics("bad", 20, 10, 0.05, 60, 0.01),
          metrics("lost", 0, none, none, 60, 0.01)};
}

/// The policy's: "ok": as often, sooner, less energy, hold within 0.05 m, smoothness at 2x:
/// passes. "bad": fails every criterion. "lost": the PID reached nothing, the policy did.
std::vector<GroupMetrics> example_policy_groups() {
  return {metrics("ok", 18, 9.9, 0.1, 60, 0.02), metrics("bad", 19, 10.1, 0.11, 61, 0.021, 1),
          metrics("lost", 3, 30, 0.4, 50, 0.01)};
}

TEST(RobustnessComparison, EachCriterionOfTheBar) {
  const double none = std::nan("");
  const std::vector<GroupMetrics> pid = example_pid_groups();
  const std::vector<GroupComparison> c = compare_robustness(example_policy_groups(), pid);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_TRUE(c[0].passes());
  EXPECT_FALSE(c[1].held);
  EXPECT_FALSE(c[1].no_flip);
  EXPECT_FALSE(c[1].time);
  EXPECT_FALSE(c[1].hold);
  EXPECT_FALSE(c[1].energy);
  EXPECT_FALSE(c[1].smoothness);
  EXPECT_TRUE(c[2].passes());
  // Reaching nothing where the PID reached is a failure of time and hold.
  const auto miss = compare_robustness({metrics("ok", 0, none, none, 10, 0.01)}, pid);
  EXPECT_FALSE(miss[0].time);
  EXPECT_FALSE(miss[0].hold);
  EXPECT_THROW(compare_robustness({metrics("other", 0, 1, 1, 1, 1)}, pid), std::invalid_argument);

  const std::string table = robustness_comparison_markdown(c);
  EXPECT_NE(table.find("| ok | 18/20 vs 18/20 pass | 0 vs 0 pass | 9.9 vs 10.0 pass |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| bad | 19/20 vs 20/20 **FAIL** | 1 vs 0 **FAIL** |"), std::string::npos)
      << table;
  EXPECT_NE(table.find("| 0.100 vs 0.050 pass | 0.020 vs 0.010 pass | pass |"), std::string::npos)
      << table;
  EXPECT_NE(table.find("30.0 vs - pass"), std::string::npos) << table;
  EXPECT_NE(table.find("2 of 3 groups pass every criterion"), std::string::npos) << table;
}

TEST(RobustnessComparison, TheCsvHasEachCriterionAndBothControllersFigures) {
  TempDir dir;
  const std::string path = dir.path("comparison.csv");
  write_robustness_comparison_csv(
      path, compare_robustness(example_policy_groups(), example_pid_groups()));
  const std::vector<std::vector<std::string>> rows = read_csv(path);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"group",
                                               "passes",
                                               "held",
                                               "no_flip",
                                               "time",
                                               "energy",
                                               "hold",
                                               "smoothness",
                                               "episodes",
                                               "held_policy",
                                               "held_pid",
                                               "flips_policy",
                                               "flips_pid",
                                               "time_to_reach_policy_s",
                                               "time_to_reach_pid_s",
                                               "thrust_energy_policy",
                                               "thrust_energy_pid",
                                               "hold_error_policy_m",
                                               "hold_error_pid_m",
                                               "smoothness_policy",
                                               "smoothness_pid"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"ok", "1",  "1",  "1",   "1",    "1",    "1",
                                               "1",  "20", "18", "18",  "0",    "0",    "9.9",
                                               "10", "60", "60", "0.1", "0.05", "0.02", "0.01"}));
  EXPECT_EQ(rows[2], (std::vector<std::string>{
                         "bad", "0", "0",    "0",  "0",  "0",  "0",    "0",    "20",    "19",  "20",
                         "1",   "0", "10.1", "10", "61", "60", "0.11", "0.05", "0.021", "0.01"}));
  // The PID reached nothing: its means are empty, and the policy passes.
  EXPECT_EQ(rows[3], (std::vector<std::string>{"lost", "1",  "1",  "1",   "1", "1",    "1",
                                               "1",    "20", "3",  "0",   "0", "0",    "30",
                                               "",     "50", "60", "0.4", "",  "0.01", "0.01"}));
  EXPECT_THROW(write_robustness_comparison_csv(dir.path("missing/comparison.csv"), {}),
               std::runtime_error);
}

TEST(RobustnessMargins, BootstrapIntervalOfTheMean) {
  const PairedDifference same = bootstrap_mean(std::vector<double>(20, 0.5), 7);
  EXPECT_EQ(same.pairs, 20);
  EXPECT_DOUBLE_EQ(same.mean, 0.5);
  EXPECT_DOUBLE_EQ(same.low, 0.5);
  EXPECT_DOUBLE_EQ(same.high, 0.5);

  const PairedDifference none = bootstrap_mean({}, 7);
  EXPECT_EQ(none.pairs, 0);
  EXPECT_TRUE(std::isnan(none.mean) && std::isnan(none.low) && std::isnan(none.high));

  // 1..20: mean 10.5, standard error 5.92 / sqrt(20) = 1.32, so the 95 % interval is about
  // 10.5 +- 2.6 (the bootstrap's is a little narrower: it divides by n, not n - 1).
  std::vector<double> ramp;
  for (int i = 1; i <= 20; ++i) ramp.push_back(i);
  const PairedDifference r = bootstrap_mean(ramp, 7);
  EXPECT_DOUBLE_EQ(r.mean, 10.5);
  EXPECT_GT(r.low, 7.5);
  EXPECT_LT(r.low, 8.6);
  EXPECT_GT(r.high, 12.4);
  EXPECT_LT(r.high, 13.5);
  // Reproducible from the seed; another seed, other resamples.
  const PairedDifference again = bootstrap_mean(ramp, 7);
  EXPECT_EQ(again.low, r.low);
  EXPECT_EQ(again.high, r.high);
  const PairedDifference other = bootstrap_mean(ramp, 8);
  EXPECT_TRUE(other.low != r.low || other.high != r.high);

  EXPECT_THROW(bootstrap_mean(ramp, 7, 99), std::invalid_argument);
  EXPECT_THROW(bootstrap_mean({1.0, std::nan("")}, 7), std::invalid_argument);
}

SummaryRow row(const std::string& group, int episode, double time_s, double hold_m, double energy,
               double smoothness) {
  SummaryRow r;
  r.scenario = group;
  r.episode = episode;
  r.reached = time_s >= 0;
  r.time_to_reach_s = time_s;
  r.mean_error_after_reach_m = r.reached ? hold_m : -1.0;
  r.final_error_m = r.reached ? hold_m : 5.0;
  r.end_reason = r.reached ? task::EndReason::kReached : task::EndReason::kTimeLimit;
  r.thrust_energy = energy;
  r.smoothness = smoothness;
  return r;
}

TEST(RobustnessMargins, PairsEpisodesAgainstTheBarsThresholds) {
  // Group a: both reach twice. Group b: the policy never reaches, the PID holds.
  const std::vector<SummaryRow> policy = {
      row("a", 0, 9, 0.1, 30, 0.02), row("a", 1, 10, 0.2, 40, 0.02), row("b", 0, -1, 0, 70, 0.01)};
  const std::vector<SummaryRow> pid = {row("b", 0, 12, 0.05, 60, 0.01),
                                       row("a", 1, 10, 0.05, 50, 0.02),
                                       row("a", 0, 10, 0.05, 50, 0.01)};
  const std::vector<GroupMargins> m = paired_margins(policy, pid, 3);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].group, "a");
  EXPECT_EQ(m[0].time_s.pairs, 2);
  EXPECT_DOUBLE_EQ(m[0].time_s.mean, -0.5);         // (9 - 10 + 10 - 10) / 2
  EXPECT_DOUBLE_EQ(m[0].energy.mean, -15.0);        // (30 - 50 + 40 - 50) / 2
  EXPECT_NEAR(m[0].hold_m.mean, 0.05, 1e-12);       // (0.1 - 0.1 + 0.2 - 0.1) / 2
  EXPECT_NEAR(m[0].smoothness.mean, -0.01, 1e-12);  // (0.02 - 0.02 + 0.02 - 0.04) / 2
  EXPECT_LE(m[0].time_s.low, -0.5);
  EXPECT_GE(m[0].time_s.high, -0.5);
  EXPECT_EQ(m[0].held_policy_only, 0);
  EXPECT_EQ(m[0].held_reference_only, 0);
  EXPECT_EQ(m[1].group, "b");
  EXPECT_EQ(m[1].time_s.pairs, 0);
  EXPECT_EQ(m[1].hold_m.pairs, 0);
  EXPECT_EQ(m[1].energy.pairs, 1);
  EXPECT_DOUBLE_EQ(m[1].energy.mean, 10.0);
  EXPECT_EQ(m[1].held_policy_only, 0);
  EXPECT_EQ(m[1].held_reference_only, 1);

  const std::string table = robustness_margins_markdown(m);
  EXPECT_NE(table.find("| a | 0 / 0 | -0.50 ["), std::string::npos) << table;
  EXPECT_NE(table.find("| b | 0 / 1 | - | **+10.0 [+10.0, +10.0]** | - |"), std::string::npos)
      << table;

  try {
    paired_margins({row("c", 4, 9, 0.1, 30, 0.02)}, pid, 3);
    FAIL() << "a policy row without its PID row was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("group c episode 4"), std::string::npos) << e.what();
  }
}

/// The committed policy (config/policies/fast.nn) driving `config`'s task (its layout set from
/// the policy) on each episode; each must reach its way-point.
std::vector<SummaryRow> committed_policy_rows(EvaluationConfig config,
                                              const std::vector<EvaluationEpisode>& episodes) {
  auto policy = agent::load_policy(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn",
                                   nessie().name, 6, std::nullopt, config.task);
  std::vector<SummaryRow> rows;
  for (const EvaluationEpisode& e : episodes) {
    rows.push_back(run_evaluation_episode(nessie(), config, *policy, e, nullptr));
    EXPECT_TRUE(rows.back().reached) << e.index;
  }
  return rows;
}

/// The mean of one figure over rows.
template <typename Figure>
double mean_of(const std::vector<SummaryRow>& rows, Figure figure) {
  double sum = 0.0;
  for (const SummaryRow& row : rows) sum += figure(row);
  return sum / static_cast<double>(rows.size());
}

// The policy's integral action (task.integral) drives out what a steady push leaves: the
// committed policy against 2 kg of extra buoyancy holds closer with it than without it.
TEST(RobustnessRun, IntegralActionHoldsCloserAgainstExtraBuoyancy) {
  EvaluationConfig c = config();
  task::apply_vehicle(nessie().facts(), c.task);
  const std::vector<EvaluationEpisode> episodes =
      of_group(robustness_episodes(c, 6, 4, 1), "buoyancy_+2kg");
  ASSERT_EQ(episodes.size(), 4u);
  const auto mean_hold_m = [&](double gain_per_s) {
    EvaluationConfig with = c;
    with.task.integral.gain_per_s = gain_per_s;
    return mean_of(committed_policy_rows(with, episodes),
                   [](const SummaryRow& r) { return r.mean_error_after_reach_m; });
  };
  const double without_m = mean_hold_m(0.0), with_m = mean_hold_m(0.1);
  std::cout << "mean hold error with 2 kg of extra buoyancy: " << without_m
            << " m without integral "
            << "action, " << with_m << " m with it\n";
  EXPECT_LT(with_m, 0.6 * without_m);
}

// The position filter (task.position_filter) is what keeps the committed policy's commands
// from chasing the sensor noise: with it the commands change less per step and spend less.
TEST(RobustnessRun, ThePositionFilterCalmsTheCommandsUnderSensorNoise) {
  EvaluationConfig c = config();
  task::apply_vehicle(nessie().facts(), c.task);
  const std::vector<EvaluationEpisode> episodes =
      of_group(robustness_episodes(c, 6, 4, 1), "sensor_noise");
  ASSERT_EQ(episodes.size(), 4u);
  const auto rows = [&](double time_constant_s) {
    EvaluationConfig with = c;
    with.task.position_filter.time_constant_s = time_constant_s;
    return committed_policy_rows(with, episodes);
  };
  const auto smoothness = [](const SummaryRow& r) { return r.smoothness; };
  const auto energy = [](const SummaryRow& r) { return r.thrust_energy; };
  const std::vector<SummaryRow> without = rows(0.0), with = rows(0.5);
  std::cout << "under sensor noise: smoothness " << mean_of(without, smoothness)
            << " without the position filter, " << mean_of(with, smoothness) << " with it; energy "
            << mean_of(without, energy) << ", " << mean_of(with, energy) << "\n";
  EXPECT_LT(mean_of(with, smoothness), 0.8 * mean_of(without, smoothness));
  EXPECT_LT(mean_of(with, energy), 0.9 * mean_of(without, energy));
}

// The fault accommodation (task.fault_accommodation) stops commanding a dead thruster and gives
// its share to the others: the committed policy with its front lateral or front vertical
// thruster dead holds closer and spends less with it than without it.
TEST(RobustnessRun, FaultAccommodationHoldsCloserWithADeadThruster) {
  EvaluationConfig c = config();
  task::apply_vehicle(nessie().facts(), c.task);
  for (const char* group : {"t4_0pct", "t6_0pct"}) {
    const std::vector<EvaluationEpisode> episodes =
        of_group(robustness_episodes(c, 6, 4, 1), group);
    ASSERT_EQ(episodes.size(), 4u);
    const auto rows = [&](bool accommodate) {
      EvaluationConfig with = c;
      with.task.fault_accommodation.enabled = accommodate;
      return committed_policy_rows(with, episodes);
    };
    const auto hold = [](const SummaryRow& r) { return r.mean_error_after_reach_m; };
    const auto energy = [](const SummaryRow& r) { return r.thrust_energy; };
    const std::vector<SummaryRow> without = rows(false), with = rows(true);
    std::cout << group << ": hold error " << mean_of(without, hold) << " m without the fault "
              << "accommodation, " << mean_of(with, hold) << " m with it; energy "
              << mean_of(without, energy) << ", " << mean_of(with, energy) << "\n";
    EXPECT_LT(mean_of(with, hold), 0.9 * mean_of(without, hold)) << group;
    EXPECT_LT(mean_of(with, energy), 0.8 * mean_of(without, energy)) << group;
  }
}

// A weak thruster keeps the policy's command while the healthy ones make up what it fails to
// deliver (task.fault_accommodation.weak_below): the committed policy reaches the paper's fault
// (T1 at 10 %) sooner, and holds closer with its front vertical thruster at 10 %, than with
// dead thrusters only accommodated (weak_below at dead_below).
TEST(RobustnessRun, FaultAccommodationMakesUpAWeakThrustersShortfall) {
  EvaluationConfig c = config();
  task::apply_vehicle(nessie().facts(), c.task);
  ASSERT_GT(c.task.fault_accommodation.weak_below, c.task.fault_accommodation.dead_below);
  EvaluationConfig dead_only = c;
  dead_only.task.fault_accommodation.weak_below = dead_only.task.fault_accommodation.dead_below;
  const std::vector<EvaluationEpisode> fault = {scenario_episodes(c, Scenario::kFault).at(0)};
  const double weak_s = committed_policy_rows(c, fault).at(0).time_to_reach_s;
  const double dead_only_s = committed_policy_rows(dead_only, fault).at(0).time_to_reach_s;
  const std::vector<EvaluationEpisode> t6 = of_group(robustness_episodes(c, 6, 6, 1), "t6_10pct");
  ASSERT_EQ(t6.size(), 6u);
  const auto hold = [](const SummaryRow& r) { return r.mean_error_after_reach_m; };
  const double weak_m = mean_of(committed_policy_rows(c, t6), hold);
  const double dead_only_m = mean_of(committed_policy_rows(dead_only, t6), hold);
  std::cout << "the fault: " << weak_s << " s with weak thrusters accommodated, " << dead_only_s
            << " s with dead ones only; T6 at 10 %: hold error " << weak_m << " m, " << dead_only_m
            << " m\n";
  EXPECT_LT(weak_s, dead_only_s);
  EXPECT_LT(weak_m, dead_only_m);
}

TEST(RobustnessRun, ThePidOnTwoEpisodesPerGroupWritesFiniteFigures) {
  TempDir dir;
  agent::PidController pid(nessie());
  const RobustnessResult a = run_robustness(nessie(), config(), pid, 2, 1, dir.path("out"));
  ASSERT_EQ(a.rows.size(), 50u);
  ASSERT_EQ(a.groups.size(), 25u);
  EXPECT_GE(a.elapsed_s, 0.0);
  for (const GroupMetrics& g : a.groups) {
    EXPECT_EQ(g.episodes, 2) << g.group;
    EXPECT_EQ(g.flips + g.blow_ups, 0) << g.group;
    EXPECT_TRUE(std::isfinite(g.mean_energy)) << g.group;
    EXPECT_GT(g.mean_energy, 0.0) << g.group;
    EXPECT_TRUE(std::isfinite(g.mean_smoothness)) << g.group;
    EXPECT_GT(g.mean_smoothness, 0.0) << g.group;
  }
  EXPECT_EQ(a.groups[0].group, "rest_start");
  EXPECT_EQ(a.groups[0].held, 2);  // the PID holds the region's way-points
  EXPECT_TRUE(std::isfinite(a.groups[0].mean_time_s));
  EXPECT_TRUE(std::isfinite(a.groups[0].mean_hold_m));

  // Deterministic: the same figures again, and on three threads with a PID each.
  const RobustnessResult b = run_robustness(nessie(), config(), pid, 2, 1, "");
  const RobustnessResult c = run_robustness(
      nessie(), config(), [] { return std::make_unique<agent::PidController>(nessie()); }, 3, 2, 1,
      "");
  ASSERT_EQ(c.rows.size(), a.rows.size());
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    for (const RobustnessResult* r : {&b, &c}) {
      EXPECT_EQ(a.rows[i].final_error_m, r->rows[i].final_error_m) << i;
      EXPECT_EQ(a.rows[i].time_to_reach_s, r->rows[i].time_to_reach_s) << i;
      EXPECT_EQ(a.rows[i].thrust_energy, r->rows[i].thrust_energy) << i;
      EXPECT_EQ(a.rows[i].smoothness, r->rows[i].smoothness) << i;
    }
  }

  const auto groups = read_csv(dir.path("out/robustness.csv"));
  ASSERT_EQ(groups.size(), 26u);
  EXPECT_EQ(groups[0], (std::vector<std::string>{
                           "group", "controller", "episodes", "reached", "held", "flips",
                           "blow_ups", "left_region", "mean_time_to_reach_s", "mean_hold_error_m",
                           "mean_thrust_energy", "mean_smoothness", "description"}));
  EXPECT_EQ(groups[1][0], "rest_start");
  EXPECT_EQ(groups[1][1], "pid");
  const auto episodes = read_csv(dir.path("out/robustness_episodes.csv"));
  ASSERT_EQ(episodes.size(), 51u);
  const std::vector<std::string>& header = episodes[0];
  for (std::size_t i = 1; i < episodes.size(); ++i) EXPECT_EQ(episodes[i].size(), header.size());
  EXPECT_EQ(header.front(), "group");
  EXPECT_EQ(header.back(), "smoothness");
  EXPECT_TRUE(std::filesystem::exists(dir.path("out/vehicle.csv")));

  std::ostringstream table;
  table << format_robustness_table(a.groups);
  EXPECT_NE(table.str().find("rest_start       pid"), std::string::npos) << table.str();
}

TEST(RobustnessCommand, ComparesAPolicyWithThePid) {
  TempDir dir;
  EvalRequest request;
  request.policy_path = std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn";
  request.scenario = "robustness";
  request.robustness_episodes = 1;
  request.robustness_with_pid = true;
  request.out_dir = dir.path("run");
  request.vehicle_path = test_support::vehicle_path();
  std::ostringstream out;
  const RobustnessResult result = run_robustness_request(request, out);
  EXPECT_EQ(result.rows.size(), 25u);
  EXPECT_EQ(result.rows[0].controller, "policy");
  for (const char* file :
       {"run/robustness.csv", "run/robustness_episodes.csv", "run/pid/robustness.csv",
        "run/robustness_comparison.md", "run/robustness_comparison.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.path(file))) << file;
  }
  // The CSV says what the table says: as many groups passing.
  const std::vector<std::vector<std::string>> csv_rows =
      read_csv(dir.path("run/robustness_comparison.csv"));
  ASSERT_EQ(csv_rows.size(), 26u);
  int passing = 0;
  for (std::size_t i = 1; i < csv_rows.size(); ++i) passing += csv_rows[i][1] == "1" ? 1 : 0;
  EXPECT_NE(out.str().find(std::to_string(passing) + " of 25 groups pass every criterion"),
            std::string::npos)
      << out.str();
  // Then how sure each criterion is, episode by episode.
  EXPECT_NE(out.str().find("| rest_start | "), out.str().rfind("| rest_start | ")) << out.str();
  EXPECT_NE(out.str().find("How sure each criterion is"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("robustness suite (pid): 25 episodes"), std::string::npos);
  // --with-pid needs a policy; at least one episode per group.
  request.controller = "pid";
  request.policy_path.clear();
  EXPECT_THROW(run_robustness_request(request, out), std::invalid_argument);
  request.robustness_with_pid = false;
  request.robustness_episodes = 0;
  EXPECT_THROW(run_robustness_request(request, out), std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::eval
