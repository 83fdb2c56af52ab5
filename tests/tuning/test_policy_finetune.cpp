// Evolution-strategies fine-tuning (tuning/policy_finetune.hpp): its way-points, the per-way-point
// objective against the evaluation's own figures (its PID lag term and its coarser integrator
// too), that it lowers the objective of a trained policy, that the thread count does not change
// the result, that bad settings are refused, its prices of thrust energy and command changes, and
// the objective split into its prices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "agent/pid_controller.hpp"
#include "agent_test_util.hpp"
#include "common/nn/gemm.hpp"
#include "common/nn/random.hpp"
#include "tuning/policy_finetune.hpp"
#include "tuning_test_util.hpp"

namespace auvrl::tuning {
namespace {

using test::committed_policy;
using test::fast_task;
using test_support::nessie;

TEST(FinetuneEpisodes, AreDeterministicInTheRegionAndTurnTheFractionAsked) {
  FinetuneConfig c;
  c.episodes = 20;
  c.random_heading_fraction = 0.25;
  const task::TaskConfig t = fast_task();
  const auto a = finetune_episodes(t, c, 7);
  const auto b = finetune_episodes(t, c, 7);
  const auto other = finetune_episodes(t, c, 8);
  ASSERT_EQ(a.size(), 20u);
  int turned = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].goal_ned_m, b[i].goal_ned_m);
    EXPECT_NE(a[i].goal_ned_m, other[i].goal_ned_m);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(a[i].goal_ned_m[k], t.goal_min_ned_m[k]);
      EXPECT_LE(a[i].goal_ned_m[k], t.goal_max_ned_m[k]);
    }
    EXPECT_EQ(a[i].start.position_ned_m, t.start_position_ned_m);
    if (a[i].start.euler_rpy_rad[2] != t.start_yaw_rad) ++turned;
  }
  EXPECT_EQ(turned, 5);
  // Never the evaluation suite's way-points (task::sample_goal from mt19937_64(1)).
  std::mt19937_64 suite_rng(1);
  const Eigen::Vector3d first_suite_goal = task::sample_goal(t, suite_rng);
  for (const auto& e : a) EXPECT_NE(e.goal_ned_m, first_suite_goal);
}

// facing_away_fraction: that share of the turned starts faces straight away from its
// way-point (in the horizontal plane); every way-point and the other headings stay.
TEST(FinetuneEpisodes, FaceAwayFromTheirWayPointsTheShareOfTurnedStartsAsked) {
  FinetuneConfig c;
  c.episodes = 24;
  c.random_heading_fraction = 0.5;
  const task::TaskConfig t = fast_task();
  const auto drawn = finetune_episodes(t, c, 3);
  c.facing_away_fraction = 0.5;
  const auto away = finetune_episodes(t, c, 3);
  ASSERT_EQ(away.size(), drawn.size());
  int facing_away = 0, turned = 0;
  for (std::size_t i = 0; i < away.size(); ++i) {
    EXPECT_EQ(away[i].goal_ned_m, drawn[i].goal_ned_m);
    const double yaw = away[i].start.euler_rpy_rad[2];
    if (drawn[i].start.euler_rpy_rad[2] != t.start_yaw_rad) ++turned;
    if (yaw == drawn[i].start.euler_rpy_rad[2]) continue;
    ++facing_away;
    const Eigen::Vector3d to_goal = away[i].goal_ned_m - away[i].start.position_ned_m;
    const Eigen::Vector2d heading(std::cos(yaw), std::sin(yaw));
    EXPECT_NEAR(heading.dot(to_goal.head<2>().normalized()), -1.0, 1e-12) << "way-point " << i;
    EXPECT_LE(std::abs(yaw), 3.14159265358979323846);
  }
  EXPECT_EQ(turned, 12);
  EXPECT_EQ(facing_away, 6);
}

// any_start_fraction: that share starts at rest anywhere in the way-points' region, at least
// 1 m from its way-point, with the safety sphere grown by its distance; the way-points stay.
TEST(FinetuneEpisodes, StartAnywhereInTheRegionTheShareAsked) {
  FinetuneConfig c;
  c.episodes = 20;
  const task::TaskConfig t = fast_task();
  const auto fixed = finetune_episodes(t, c, 4);
  c.any_start_fraction = 0.25;
  const auto anywhere = finetune_episodes(t, c, 4);
  ASSERT_EQ(anywhere.size(), fixed.size());
  int moved = 0;
  for (std::size_t i = 0; i < anywhere.size(); ++i) {
    const FinetuneEpisode& e = anywhere[i];
    EXPECT_EQ(e.goal_ned_m, fixed[i].goal_ned_m);
    if (e.start.position_ned_m == t.start_position_ned_m) {
      EXPECT_EQ(e.safety_radius_m, 0.0);
      continue;
    }
    ++moved;
    const double distance_m = (e.goal_ned_m - e.start.position_ned_m).norm();
    EXPECT_GE(distance_m, 1.0);
    EXPECT_DOUBLE_EQ(e.safety_radius_m, distance_m + t.beta_max_m);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(e.start.position_ned_m[k], t.goal_min_ned_m[k]);
      EXPECT_LE(e.start.position_ned_m[k], t.goal_max_ned_m[k]);
    }
  }
  EXPECT_EQ(moved, 5);
}

// randomised_fraction: that share of the way-points gets the conditions finetune.randomise draws
// (every kind on here, so each randomised episode gets a fault), the way-points and headings
// unchanged; the task's own randomisation (the actors') does not reach them.
TEST(FinetuneEpisodes, RandomiseTheFractionAskedWithoutMovingTheWayPoints) {
  FinetuneConfig c;
  c.episodes = 20;
  task::TaskConfig t = fast_task();
  t.randomise.fault_probability = 1.0;
  t.randomise.model_probability = 1.0;
  c.randomised_fraction = 0.5;
  const auto still = finetune_episodes(t, c, 7);
  c.randomise.fault_probability = 1.0;
  c.randomise.model_probability = 1.0;
  const auto a = finetune_episodes(t, c, 7);
  const auto b = finetune_episodes(t, c, 7);
  int randomised = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].goal_ned_m, still[i].goal_ned_m);
    EXPECT_EQ(a[i].start.euler_rpy_rad, still[i].start.euler_rpy_rad);
    EXPECT_EQ(a[i].start.thruster_efficiency, b[i].start.thruster_efficiency);
    EXPECT_TRUE(still[i].start.thruster_efficiency.empty());
    EXPECT_TRUE(still[i].start.model_variation.is_identity());
    if (!a[i].start.thruster_efficiency.empty()) {
      ++randomised;
      EXPECT_FALSE(a[i].start.model_variation.is_identity());
    }
  }
  EXPECT_EQ(randomised, 10);
  c.randomised_fraction = 1.5;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

// The randomised way-points' faults take the thrusters in turn, each as often as the next, with
// the efficiency drawn; with a wrong model as well, every other thruster keeps the model's thrust
// scale.
TEST(FinetuneEpisodes, FaultsTakeTheThrustersInTurn) {
  FinetuneConfig c;
  c.episodes = 36;
  c.randomised_fraction = 0.5;
  c.randomise.fault_probability = 1.0;
  c.randomise.fault_efficiency = {0.0, 0.1};
  const task::TaskConfig t = fast_task();
  std::vector<int> faults(6, 0);
  for (const FinetuneEpisode& e : finetune_episodes(t, c, 3)) {
    const std::vector<double>& efficiency = e.start.thruster_efficiency;
    if (efficiency.empty()) continue;
    ASSERT_EQ(efficiency.size(), 6u);
    const auto weak = std::min_element(efficiency.begin(), efficiency.end());
    EXPECT_LE(*weak, 0.1);
    EXPECT_EQ(std::count(efficiency.begin(), efficiency.end(), 1.0), 5);
    ++faults[static_cast<std::size_t>(weak - efficiency.begin())];
  }
  EXPECT_EQ(faults, std::vector<int>(6, 3));
  c.randomise.model_probability = 1.0;
  c.randomise.thrust_scale = {0.7, 0.7};
  for (const FinetuneEpisode& e : finetune_episodes(t, c, 3)) {
    const std::vector<double>& efficiency = e.start.thruster_efficiency;
    if (efficiency.empty()) continue;
    EXPECT_EQ(std::count(efficiency.begin(), efficiency.end(), 0.7), 5);
  }
}

// randomised_episode_steps: the randomised way-points run that long, the others the common
// length (max_steps 0).
TEST(FinetuneEpisodes, TheRandomisedOnesRunTheirOwnLength) {
  FinetuneConfig c;
  c.episodes = 12;
  c.randomised_fraction = 0.25;
  c.randomise.fault_probability = 1.0;
  c.randomised_episode_steps = 400;
  int long_ones = 0;
  for (const FinetuneEpisode& e : finetune_episodes(fast_task(), c, 5)) {
    EXPECT_EQ(e.max_steps, e.start.thruster_efficiency.empty() ? 0 : 400);
    long_ones += e.max_steps == 400;
  }
  EXPECT_EQ(long_ones, 3);
  c.randomised_episode_steps = -1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

// Twenty way-points, half of them turned and eight faulted: the twelve plain ones are those that
// noisy_fraction and dive_fraction take their shares of.
FinetuneConfig twelve_plain_of_twenty() {
  FinetuneConfig c;
  c.episodes = 20;
  c.random_heading_fraction = 0.5;
  c.randomised_fraction = 0.4;
  c.randomise.fault_probability = 1.0;
  return c;
}

// noisy_fraction: that share of the way-points without randomised conditions gets sensor noise
// at finetune.randomise's levels (scaled by a drawn factor) and nothing else; the way-points,
// headings and faults stay as they were.
TEST(FinetuneEpisodes, NoiseTheShareAskedOfThePlainOnes) {
  FinetuneConfig c = twelve_plain_of_twenty();
  c.randomise.sensor_noise_scale = {0.5, 1.5};
  const auto quiet = finetune_episodes(fast_task(), c, 9);
  c.noisy_fraction = 0.25;
  const auto noisy = finetune_episodes(fast_task(), c, 9);
  ASSERT_EQ(noisy.size(), quiet.size());
  int noised = 0;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    EXPECT_EQ(noisy[i].goal_ned_m, quiet[i].goal_ned_m);
    EXPECT_EQ(noisy[i].start.euler_rpy_rad, quiet[i].start.euler_rpy_rad);
    EXPECT_EQ(noisy[i].start.thruster_efficiency, quiet[i].start.thruster_efficiency);
    EXPECT_EQ(quiet[i].start.sensor_noise.position_sigma_m, 0.0);
    const sim::SensorNoise& n = noisy[i].start.sensor_noise;
    if (n.position_sigma_m == 0.0) continue;
    ++noised;
    EXPECT_TRUE(noisy[i].start.thruster_efficiency.empty()) << "noise only on the plain ones";
    EXPECT_TRUE(noisy[i].start.current_ned_mps.isZero());
    EXPECT_TRUE(noisy[i].start.model_variation.is_identity());
    const double factor = n.position_sigma_m / 0.1;
    EXPECT_GE(factor, 0.5);
    EXPECT_LE(factor, 1.5);
    EXPECT_NEAR(n.attitude_sigma_rad, 0.02 * factor, 1e-12);
    EXPECT_NEAR(n.linear_velocity_sigma_mps, 0.05 * factor, 1e-12);
    EXPECT_NEAR(n.angular_velocity_sigma_rad_s, 0.02 * factor, 1e-12);
  }
  EXPECT_EQ(noised, 3) << "a quarter of the 12 plain way-points";
  c.noisy_fraction = -0.1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

// dive_fraction: that share of the plain way-points becomes a steep dive from the task's start
// (the lower half of the depth below it, at most dive_across_m across); the others, the
// headings and the randomised ones do not move.
TEST(FinetuneEpisodes, DiveTheShareAskedOfThePlainOnes) {
  FinetuneConfig c = twelve_plain_of_twenty();
  const task::TaskConfig t = fast_task();
  const auto drawn = finetune_episodes(t, c, 9);
  c.dive_fraction = 0.25;
  c.dive_across_m = 4.0;
  const auto dived = finetune_episodes(t, c, 9);
  ASSERT_EQ(dived.size(), drawn.size());
  const double start_depth_m = t.start_position_ned_m.z();
  const double from_m = start_depth_m + 0.5 * (t.goal_max_ned_m.z() - start_depth_m);
  int dives = 0;
  for (std::size_t i = 0; i < dived.size(); ++i) {
    EXPECT_EQ(dived[i].start.thruster_efficiency, drawn[i].start.thruster_efficiency);
    EXPECT_EQ(dived[i].start.position_ned_m, drawn[i].start.position_ned_m);
    if (dived[i].goal_ned_m == drawn[i].goal_ned_m) continue;
    ++dives;
    EXPECT_TRUE(dived[i].start.thruster_efficiency.empty()) << "dives only among the plain ones";
    const Eigen::Vector3d offset_m = dived[i].goal_ned_m - t.start_position_ned_m;
    EXPECT_LE(offset_m.head<2>().norm(), 4.0 + 1e-12);
    EXPECT_GE(dived[i].goal_ned_m.z(), from_m);
    EXPECT_LE(dived[i].goal_ned_m.z(), t.goal_max_ned_m.z());
  }
  EXPECT_EQ(dives, 3) << "a quarter of the 12 plain way-points";
  c.dive_fraction = 1.1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.dive_fraction = 0.25;
  c.dive_across_m = 0.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

TEST(ArrivalObjective, IsTheArrivalTimeBetweenStepsPlusTheWeightedHoldError) {
  const task::TaskConfig t = fast_task();
  FinetuneEpisode e;
  e.goal_ned_m = Eigen::Vector3d(7.0, 6.0, 10.0);  // test1
  FinetuneConfig c;
  c.episode_steps = 300;
  agent::PidController pid(nessie());
  c.hold_weight = 0.0;
  const double arrival_s = arrival_objective(nessie(), t, pid, e, c);
  // The evaluation's test1 figure for the PID is the first whole step within 0.5 m.
  eval::EvaluationConfig eval;
  eval.task = t;
  eval::EvaluationEpisode test1;
  test1.goal_ned_m = e.goal_ned_m;
  test1.start = e.start;
  const eval::SummaryRow row = eval::run_evaluation_episode(nessie(), eval, pid, test1, nullptr);
  ASSERT_TRUE(row.reached);
  EXPECT_GT(arrival_s, row.time_to_reach_s - 0.1);
  EXPECT_LE(arrival_s, row.time_to_reach_s);
  c.hold_weight = 2.0;
  c.hold_steps = 700;  // longer than the rest of the episode: the mean of what is left
  const double with_hold = arrival_objective(nessie(), t, pid, e, c);
  EXPECT_GT(with_hold, arrival_s);
  EXPECT_LT(with_hold, arrival_s + 2.0 * 0.5);
}

/// Turns the vehicle on the spot: the two surge thrusters push opposite ways, a pure yaw
/// moment (0.37 m between them).
class TurnOnTheSpot final : public agent::Controller {
 public:
  explicit TurnOnTheSpot(float command) : command_(command) {}
  void act(const task::Observation&, const Eigen::Vector3d&, const task::StateVector&,
           task::ActionVector& action) override {
    action.setZero(6);
    action[0] = command_;
    action[1] = -command_;
  }
  std::string name() const override { return "turn_on_the_spot"; }

 private:
  float command_;
};

TEST(ArrivalObjective, PricesTurningOnTheSpotWhileHolding) {
  FinetuneEpisode e;
  e.start.position_ned_m = fast_task().start_position_ned_m;
  e.goal_ned_m = e.start.position_ned_m;  // there from the first step: all of it is the hold
  FinetuneConfig c;
  c.hold_steps = 100;
  auto objective = [&](agent::Controller& controller, double weight) {
    c.hold_turn_weight = weight;
    return arrival_objective(nessie(), fast_task(), controller, e, c);
  };
  TurnOnTheSpot still(0.0f), turning(0.3f);
  EXPECT_NEAR(objective(still, 10.0), objective(still, 0.0), 1e-9) << "it never turns";
  // 0.3 of full thrust each way: about 4.4 N m; Nessie turns at up to ~0.6 rad/s.
  const double price_s = objective(turning, 10.0) - objective(turning, 0.0);
  EXPECT_GT(price_s, 10.0 * 0.05);
  EXPECT_LT(price_s, 10.0 * 0.6);
  EXPECT_NEAR(objective(turning, 20.0) - objective(turning, 0.0), 2.0 * price_s, 1e-9);
  // Turning one way and back again costs next to nothing: only the net change counts. The
  // moment one way for 2 s, the other way for 4 s, then the first way for 2 s again leaves the
  // vehicle about where it started, turning no more, over each 8 s.
  struct ThereAndBack final : agent::Controller {
    int step = 0;
    TurnOnTheSpot one_way{0.3f}, other_way{-0.3f};
    void reset() override { step = 0; }
    void act(const task::Observation& o, const Eigen::Vector3d& goal, const task::StateVector& x,
             task::ActionVector& action) override {
      const int phase = step++ % 80;
      (phase < 20 || phase >= 60 ? one_way : other_way).act(o, goal, x, action);
    }
    std::string name() const override { return "there_and_back"; }
  } there_and_back;
  c.hold_steps = 160;
  const double back_price_s = objective(there_and_back, 10.0) - objective(there_and_back, 0.0);
  EXPECT_LT(back_price_s, 0.25 * price_s);
}

TEST(ArrivalObjective, ChargesTheLagBehindThePidArrivalLessTheLead) {
  const task::TaskConfig t = fast_task();
  FinetuneConfig c;
  c.episode_steps = 300;
  c.hold_weight = 0.0;
  std::vector<FinetuneEpisode> episodes(1);
  episodes[0].goal_ned_m = Eigen::Vector3d(7.0, 6.0, 10.0);  // test1
  // The vehicle's own gains (a nessie7.pid.yaml, else the compiled defaults), as
  // set_pid_arrivals uses.
  agent::PidController pid(nessie(), agent::pid_gains_for(nessie()).gains);
  const double pid_arrival_s = arrival_objective(nessie(), t, pid, episodes[0], c);
  c.pid_lag_weight = 4.0;
  c.pid_lead_s = 0.3;
  set_pid_arrivals(nessie(), t, c, episodes);
  EXPECT_EQ(episodes[0].pid_arrival_s, pid_arrival_s);
  EXPECT_GT(pid_arrival_s, 8.1);  // 8.24 s with the compiled defaults
  EXPECT_LT(pid_arrival_s, 8.3);
  // The PID itself arrives 0.3 s later than asked: 4 s per s of it.
  EXPECT_NEAR(arrival_objective(nessie(), t, pid, episodes[0], c), pid_arrival_s + 4.0 * 0.3, 1e-9);
  // A lead of -0.5 s lets it be up to 0.5 s later for nothing.
  c.pid_lead_s = -0.5;
  EXPECT_EQ(arrival_objective(nessie(), t, pid, episodes[0], c), pid_arrival_s);
  // Without the PID's arrival there is nothing to lag behind.
  FinetuneEpisode no_reference = episodes[0];
  no_reference.pid_arrival_s = std::numeric_limits<double>::quiet_NaN();
  c.pid_lead_s = 0.3;
  EXPECT_EQ(arrival_objective(nessie(), t, pid, no_reference, c), pid_arrival_s);
}

// The thrust prices add energy_weight x the episode's thrust energy and smoothness_weight x its
// command smoothness, both as the evaluation measures them over the same steps.
TEST(ArrivalObjective, PricesTheEpisodesThrustEnergyAndCommandChanges) {
  const task::TaskConfig t = fast_task();
  FinetuneConfig c;
  c.episode_steps = 300;
  FinetuneEpisode e;
  e.goal_ned_m = Eigen::Vector3d(7.0, 6.0, 10.0);
  agent::PidController pid(nessie(), agent::pid_gains_for(nessie()).gains);
  const double base = arrival_objective(nessie(), t, pid, e, c);
  // The same episode run as the objective runs it, for its energy and smoothness.
  task::TaskConfig et = t;
  et.max_steps = c.episode_steps;
  agent::EpisodeOptions options;
  options.goal_ned_m = e.goal_ned_m;
  options.beta_m = 0.5;
  options.start = e.start;
  options.reach_radius_m = 0.5;
  options.run_full_time = true;
  options.steps_after_reach = c.hold_steps;
  std::vector<agent::TrajectoryRow> trajectory;
  options.trajectory = &trajectory;
  auto link = agent::make_in_process_link(nessie());
  const agent::EpisodeSummary s = agent::run_episode(et, *link, pid, options);
  const double smoothness = eval::trajectory_smoothness(trajectory, 0, t.max_thrust_n);
  ASSERT_GT(s.thrust_energy, 1.0);
  ASSERT_GT(smoothness, 0.0);
  c.energy_weight = 0.1;
  EXPECT_NEAR(arrival_objective(nessie(), t, pid, e, c), base + 0.1 * s.thrust_energy, 1e-9);
  c.energy_weight = 0.0;
  c.smoothness_weight = 50.0;
  EXPECT_NEAR(arrival_objective(nessie(), t, pid, e, c), base + 50.0 * smoothness, 1e-9);
  c.smoothness_weight = -1.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

/// Never pushes.
class IdleController final : public agent::Controller {
 public:
  void act(const task::Observation&, const Eigen::Vector3d&, const task::StateVector&,
           task::ActionVector& action) override {
    action = task::ActionVector::Zero(6);
  }
  std::string name() const override { return "idle"; }
};

// Each price by itself: every one as its weight says, their sum the objective, and the means
// over the fine-tuning's own way-points (with the PID's arrivals set) the means of the parts.
TEST(ArrivalObjective, SplitsIntoItsPricesAsTheWeightsSay) {
  const task::TaskConfig t = fast_task();
  FinetuneConfig c;
  c.episodes = 6;
  c.episode_steps = 250;
  c.hold_weight = 10.0;
  c.hold_turn_weight = 20.0;
  c.flip_margin_rad = 0.05;  // low enough that the PID's pitch on the way is priced
  c.flip_margin_weight = 20.0;
  c.energy_weight = 0.1;
  c.smoothness_weight = 100.0;
  c.pid_lag_weight = 4.0;
  c.pid_lead_s = 0.3;
  const std::vector<FinetuneEpisode> episodes = objective_episodes(nessie(), t, c, 7);
  ASSERT_EQ(episodes.size(), 6u);
  agent::PidController pid(nessie(), agent::pid_gains_for(nessie()).gains);
  ObjectiveTerms sum;
  bool flip_priced = false;
  for (const FinetuneEpisode& e : episodes) {
    ASSERT_TRUE(std::isfinite(e.pid_arrival_s));
    const ObjectiveTerms one = arrival_objective_terms(nessie(), t, pid, e, c);
    EXPECT_EQ(one.objective_s, arrival_objective(nessie(), t, pid, e, c));
    EXPECT_NEAR(one.arrival_s + one.hold_s + one.turn_s + one.flip_s + one.energy_s +
                    one.smoothness_s + one.lag_s,
                one.objective_s, 1e-9);
    EXPECT_GT(one.arrival_s, 0.0);
    EXPECT_GT(one.hold_s, 0.0);
    EXPECT_GT(one.energy_s, 0.0);
    EXPECT_GT(one.smoothness_s, 0.0);
    flip_priced = flip_priced || one.flip_s > 0.0;
    // The PID arrives when it arrives: its lateness is the lead it is asked for.
    EXPECT_NEAR(one.lag_s, 4.0 * 0.3, 1e-9);
    // Each price alone is its weight times its figure: halving a weight halves its price.
    FinetuneConfig half = c;
    half.energy_weight = 0.05;
    half.smoothness_weight = 50.0;
    half.hold_weight = 5.0;
    const ObjectiveTerms halved = arrival_objective_terms(nessie(), t, pid, e, half);
    EXPECT_NEAR(halved.energy_s, one.energy_s / 2.0, 1e-12);
    EXPECT_NEAR(halved.smoothness_s, one.smoothness_s / 2.0, 1e-12);
    EXPECT_NEAR(halved.hold_s, one.hold_s / 2.0, 1e-12);
    EXPECT_EQ(halved.arrival_s, one.arrival_s);
    for (auto [total, part] : {std::pair{&sum.arrival_s, one.arrival_s},
                               {&sum.hold_s, one.hold_s},
                               {&sum.turn_s, one.turn_s},
                               {&sum.flip_s, one.flip_s},
                               {&sum.energy_s, one.energy_s},
                               {&sum.smoothness_s, one.smoothness_s},
                               {&sum.lag_s, one.lag_s},
                               {&sum.objective_s, one.objective_s}}) {
      *total += part;
    }
  }
  EXPECT_TRUE(flip_priced);
  const ObjectiveTerms mean = mean_objective_terms(nessie(), t, pid, episodes, c);
  EXPECT_NEAR(mean.arrival_s, sum.arrival_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.hold_s, sum.hold_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.turn_s, sum.turn_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.flip_s, sum.flip_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.energy_s, sum.energy_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.smoothness_s, sum.smoothness_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.lag_s, sum.lag_s / 6.0, 1e-12);
  EXPECT_NEAR(mean.objective_s, sum.objective_s / 6.0, 1e-12);
  // Without a lag price the way-points carry no PID arrival, and nothing is charged for it.
  c.pid_lag_weight = 0.0;
  for (const FinetuneEpisode& e : objective_episodes(nessie(), t, c, 7)) {
    EXPECT_TRUE(std::isnan(e.pid_arrival_s));
    EXPECT_EQ(arrival_objective_terms(nessie(), t, pid, e, c).lag_s, 0.0);
  }
}

// Not arriving: the arrival's price is the episode's time plus the closest approach, no hold.
TEST(ArrivalObjective, NotArrivingPricesNoHold) {
  FinetuneConfig c;
  c.episode_steps = 100;
  FinetuneEpisode e;
  e.goal_ned_m = Eigen::Vector3d(5.0, 0.0, 5.0);
  IdleController idle;
  const ObjectiveTerms terms = arrival_objective_terms(nessie(), fast_task(), idle, e, c);
  EXPECT_NEAR(terms.arrival_s, 10.0 + 5.0, 0.05);
  EXPECT_EQ(terms.hold_s, 0.0);
  EXPECT_EQ(terms.turn_s, 0.0);
  EXPECT_EQ(terms.objective_s, arrival_objective(nessie(), fast_task(), idle, e, c));
}

TEST(ArrivalObjective, NotArrivingCostsTheEpisodeTimePlusTheClosestApproach) {
  FinetuneEpisode e;
  e.goal_ned_m = Eigen::Vector3d(3.0, 4.0, 5.0);  // 5 m ahead of the start, level
  FinetuneConfig c;
  c.episode_steps = 50;
  IdleController idle;
  const double j = arrival_objective(nessie(), fast_task(), idle, e, c);
  EXPECT_NEAR(j, 5.0 + 5.0, 0.05) << "the vehicle barely drifts (1 N buoyant)";
}

TEST(ArrivalObjective, AnEpisodesOwnLengthReplacesTheCommonOne) {
  FinetuneEpisode e;
  e.goal_ned_m = Eigen::Vector3d(3.0, 4.0, 5.0);
  FinetuneConfig c;
  c.episode_steps = 50;
  e.max_steps = 100;
  IdleController idle;
  EXPECT_NEAR(arrival_objective(nessie(), fast_task(), idle, e, c), 10.0 + 5.0, 0.05);
}

// A way-point farther than the task's safety sphere (20 m) from its start: the episode's own
// sphere lets the policy get there; without it the episode ends at once, as a failure.
TEST(ArrivalObjective, AnEpisodesSafetySphereReplacesTheTasks) {
  FinetuneEpisode e;
  e.start.position_ned_m = Eigen::Vector3d(-10.0, -10.0, 5.0);
  e.goal_ned_m = Eigen::Vector3d(8.0, 8.0, 5.0);  // 25.5 m ahead
  e.start.euler_rpy_rad[2] = 0.785398;
  FinetuneConfig c;
  c.episode_steps = 400;
  c.hold_steps = 10;
  const nn::Mlp policy = committed_policy();
  agent::PolicyController controller(policy, fast_task().state_dim(), 6);
  const double failed = arrival_objective(nessie(), fast_task(), controller, e, c);
  EXPECT_NEAR(failed, 40.0 + 25.5, 0.1) << "the episode's time plus the closest approach";
  e.safety_radius_m = 25.5 + 20.0;
  const double arrived = arrival_objective(nessie(), fast_task(), controller, e, c);
  EXPECT_LT(arrived, 30.0);
}

TEST(ArrivalObjective, ACoarserIntegratorGivesTheSameObjectiveForATrainedPolicy) {
  // The fine-tuning's episodes may run RK4 with fewer steps than the vehicle file's 10 (the
  // fast preset runs 2): the policy's objective must not move with it, or the fine-tuning
  // would rank weights on another plant. Measured on the committed policy: the arrivals agree
  // to ~1e-5 s; the hold term, where the policy works its thrusters around the way-point, by
  // up to ~0.02 s on a way-point and ~0.001 s on the mean.
  FinetuneConfig c;
  c.episodes = 8;
  c.random_heading_fraction = 0.5;
  FinetuneConfig arrival_only = c;
  arrival_only.hold_weight = 0.0;
  arrival_only.flip_margin_weight = 0.0;
  const nn::Mlp policy = committed_policy();
  agent::PolicyController controller(policy, fast_task().state_dim(), 6);
  ASSERT_EQ(nessie().substeps, 10);
  double arrival_gap_s = 0.0, fine_sum = 0.0, coarse_sum = 0.0;
  for (const FinetuneEpisode& e : finetune_episodes(fast_task(), c, 5)) {
    for (FinetuneConfig* f : {&c, &arrival_only}) f->integration_substeps = 0;  // the vehicle's
    const double fine = arrival_objective(nessie(), fast_task(), controller, e, c);
    const double fine_arrival =
        arrival_objective(nessie(), fast_task(), controller, e, arrival_only);
    for (FinetuneConfig* f : {&c, &arrival_only}) f->integration_substeps = 10;
    EXPECT_EQ(arrival_objective(nessie(), fast_task(), controller, e, c), fine);
    for (FinetuneConfig* f : {&c, &arrival_only}) f->integration_substeps = 2;
    fine_sum += fine;
    coarse_sum += arrival_objective(nessie(), fast_task(), controller, e, c);
    arrival_gap_s =
        std::max(arrival_gap_s,
                 std::abs(arrival_objective(nessie(), fast_task(), controller, e, arrival_only) -
                          fine_arrival));
  }
  EXPECT_LT(arrival_gap_s, 1e-3);
  EXPECT_NEAR(coarse_sum / c.episodes, fine_sum / c.episodes, 5e-3);
  EXPECT_NE(coarse_sum, fine_sum) << "the substeps did not reach the simulation";
}

FinetuneConfig small_finetune() {
  FinetuneConfig c;
  c.iterations = 4;
  c.pairs = 4;
  c.episodes = 4;
  return c;
}

/// The committed policy with every weight moved by N(0, 0.05^2), fixed seed: trained, but off
/// the fine-tuning's optimum (the committed policy itself is fine-tuned: four small iterations
/// find nothing better around it).
nn::Mlp detuned_policy() {
  nn::Mlp policy = committed_policy();
  nn::Rng rng(7);
  for (Eigen::Index i = 0; i < policy.params().size(); ++i) {
    policy.params()[i] += 0.05f * static_cast<float>(nn::standard_normal(rng));
  }
  return policy;
}

// The search scores its way-points all at once (BatchedObjective): each must get the objective
// of its own episode, to the bit, with dead thrusters, noise, starts anywhere and turned ones,
// and again with other weights on the buffers the first call left.
TEST(BatchedObjective, GivesEachWayPointTheObjectiveOfItsOwnEpisode) {
  if (!nn::gemm::uses_avx512()) {
    GTEST_SKIP() << "the batched pass is bit-exact with the AVX-512 products only";
  }
  FinetuneConfig c;
  c.episodes = 10;
  c.randomised_fraction = 0.4;
  c.noisy_fraction = 0.2;
  c.any_start_fraction = 0.2;
  c.random_heading_fraction = 0.3;
  c.randomised_episode_steps = 300;
  c.integration_substeps = 2;
  c.energy_weight = 0.1;
  c.smoothness_weight = 100;
  c.hold_turn_weight = 20;
  const std::vector<FinetuneEpisode> episodes = finetune_episodes(fast_task(), c, 4);
  BatchedObjective batch(nessie(), fast_task(), detuned_policy(), c, episodes.size());
  agent::PolicyController alone(detuned_policy(), finetune_driving_task(fast_task()));
  for (int round = 0; round < 2; ++round) {
    const std::vector<double> together = batch(episodes);
    ASSERT_EQ(together.size(), episodes.size());
    for (std::size_t i = 0; i < episodes.size(); ++i) {
      EXPECT_EQ(together[i], arrival_objective(nessie(), fast_task(), alone, episodes[i], c))
          << "round " << round << ", way-point " << i;
    }
    batch.network().params() = committed_policy().params();
    alone.set_network(committed_policy());
  }
  std::vector<FinetuneEpisode> more = episodes;
  more.push_back(episodes.front());
  EXPECT_THROW(batch(more), std::invalid_argument);
}

TEST(FinetunePolicy, LowersTheObjectiveOfATrainedPolicy) {
  FinetuneConfig c = small_finetune();
  // The PID's arrivals are part of the objective; a lead of 3 s (the preset's is 0.3 s) makes
  // the term count on every way-point.
  c.pid_lag_weight = 4.0;
  c.pid_lead_s = 3.0;
  c.integration_substeps = 2;
  std::vector<FinetuneIteration> seen;
  const FinetuneResult r =
      finetune_policy(nessie(), fast_task(), detuned_policy(), c, 1,
                      [&](const FinetuneIteration& i, const nn::Mlp& weights) {
                        seen.push_back(i);
                        EXPECT_EQ(weights.num_params(), detuned_policy().num_params());
                      });
  ASSERT_EQ(seen.size(), 4u);
  ASSERT_EQ(r.iterations.size(), 4u);
  EXPECT_EQ(seen.back().iteration, 4);
  EXPECT_GE(seen.back().elapsed_s, seen.front().elapsed_s);
  EXPECT_LT(r.best_objective, r.start_objective - 0.05);
  ASSERT_GT(r.best_iteration, 0);
  EXPECT_EQ(r.best_objective,
            r.iterations[static_cast<std::size_t>(r.best_iteration - 1)].objective);
  // The returned network is the one that scored best_objective, on the way-points with the
  // PID's arrivals (without them the lag term would be missing) and with the task's integral
  // action, as the fine-tuning ran it.
  std::vector<FinetuneEpisode> episodes = finetune_episodes(fast_task(), c, 1);
  agent::PolicyController start(detuned_policy(), fast_task().state_dim(), 6);
  agent::PolicyController best(r.network, fast_task().state_dim(), 6);
  start.use_driving_aids(fast_task());
  best.use_driving_aids(fast_task());
  double start_without_pid = 0.0;
  for (const FinetuneEpisode& e : episodes) {
    start_without_pid += arrival_objective(nessie(), fast_task(), start, e, c);
  }
  set_pid_arrivals(nessie(), fast_task(), c, episodes);
  double sum = 0.0, start_sum = 0.0;
  for (const FinetuneEpisode& e : episodes) {
    sum += arrival_objective(nessie(), fast_task(), best, e, c);
    start_sum += arrival_objective(nessie(), fast_task(), start, e, c);
  }
  EXPECT_NEAR(sum / c.episodes, r.best_objective, 1e-12);
  EXPECT_NEAR(start_sum / c.episodes, r.start_objective, 1e-12);
  EXPECT_GT(start_sum, start_without_pid) << "the start lags the PID on none of the way-points";
}

TEST(FinetunePolicy, TheNumberOfThreadsDoesNotChangeTheResult) {
  FinetuneConfig c = small_finetune();
  c.iterations = 2;
  c.threads = 1;
  const FinetuneResult one = finetune_policy(nessie(), fast_task(), committed_policy(), c, 3);
  c.threads = 3;
  const FinetuneResult three = finetune_policy(nessie(), fast_task(), committed_policy(), c, 3);
  EXPECT_EQ(one.network.params(), three.network.params());
  EXPECT_EQ(one.best_objective, three.best_objective);
}

TEST(FinetunePolicy, RefusesBadSettingsAndANetworkThatDoesNotFit) {
  FinetuneConfig c = small_finetune();
  c.sigma = 0.0;
  EXPECT_THROW(finetune_policy(nessie(), fast_task(), committed_policy(), c, 1),
               std::invalid_argument);
  for (auto bad :
       {+[](FinetuneConfig& f) { f.pairs = 0; },
        +[](FinetuneConfig& f) { f.episodes = 0; },
        +[](FinetuneConfig& f) { f.learning_rate = -1; },
        +[](FinetuneConfig& f) { f.random_heading_fraction = 2; },
        +[](FinetuneConfig& f) { f.facing_away_fraction = -0.1; },
        +[](FinetuneConfig& f) { f.any_start_fraction = 1.5; },
        +[](FinetuneConfig& f) { f.hold_steps = 0; },
        +[](FinetuneConfig& f) { f.hold_turn_weight = -1; },
        +[](FinetuneConfig& f) { f.integration_substeps = -1; },
        +[](FinetuneConfig& f) { f.pid_lag_weight = -1; },
        +[](FinetuneConfig& f) { f.pid_lead_s = std::numeric_limits<double>::infinity(); },
        +[](FinetuneConfig& f) { f.iterations = -1; },
        +[](FinetuneConfig& f) { f.candidates = 0; },
        +[](FinetuneConfig& f) { f.candidates = 65; },
        +[](FinetuneConfig& f) { f.candidates_within_s = -1; },
        +[](FinetuneConfig& f) { f.candidates_within_s = std::nan(""); },
        +[](FinetuneConfig& f) { f.candidate_min_fraction = 0; },
        +[](FinetuneConfig& f) { f.candidate_min_fraction = 1.5; },
        +[](FinetuneConfig& f) { f.candidate_min_fraction = std::nan(""); },
        +[](FinetuneConfig& f) { f.selection_seed = 1; }}) {
    FinetuneConfig f;
    bad(f);
    EXPECT_THROW(f.validate(), std::invalid_argument);
  }
  task::TaskConfig paper = fast_task();
  paper.layout = task::StateLayout::kPaper;
  EXPECT_THROW(finetune_policy(nessie(), paper, committed_policy(), small_finetune(), 1),
               std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::tuning
