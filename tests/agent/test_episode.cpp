// run_episode's end conditions against scripted vehicles and a scripted controller: time limit
// (a cut-off), reaching, leaving beta_max, flipping, a blow-up, a silent simulator; and what
// it reports on the way (transitions, trajectory, reach time, hold error, from the true position
// where the link knows it).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "agent/episode.hpp"

namespace auvrl::agent {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A vehicle whose motion is a script: `move` changes the observation at each step (1-based).
class ScriptedLink final : public VehicleLink {
 public:
  using Move = std::function<void(int step, task::Observation&, VehicleReport&)>;
  ScriptedLink(int num_thrusters, Move move)
      : num_thrusters_(num_thrusters), move_(std::move(move)) {}
  int num_thrusters() const override { return num_thrusters_; }
  std::optional<VehicleReport> reset(const EpisodeStart& start) override {
    step_ = 0;
    report_ = VehicleReport{};
    report_.observation.position_ned_m = start.position_ned_m;
    report_.observation.euler_rpy_rad = start.euler_rpy_rad;
    report_.thrust_realised_n.assign(static_cast<std::size_t>(num_thrusters_), 0.0);
    return report_;
  }
  std::optional<VehicleReport> step(const std::vector<double>& thrust_n) override {
    commands.push_back(thrust_n);
    ++step_;
    report_.time_s = 0.1 * step_;
    report_.thrust_realised_n = thrust_n;
    move_(step_, report_.observation, report_);
    if (silent_from > 0 && step_ >= silent_from) return std::nullopt;
    return report_;
  }
  std::vector<std::vector<double>> commands;
  int silent_from = 0;  ///< from this step on the vehicle does not answer

 private:
  int num_thrusters_;
  Move move_;
  int step_ = 0;
  VehicleReport report_;
};

/// Always the same action; counts its calls and checks the state size it is given.
class ConstantController final : public Controller {
 public:
  explicit ConstantController(float value, int state_dim) : value_(value), state_dim_(state_dim) {}
  void reset() override { ++resets; }
  void act(const task::Observation&, const Eigen::Vector3d&, const task::StateVector& state,
           task::ActionVector& action) override {
    EXPECT_EQ(state.size(), state_dim_);
    action = task::ActionVector::Constant(6, value_);
    ++calls;
  }
  std::string name() const override { return "constant"; }
  int calls = 0, resets = 0;

 private:
  float value_;
  int state_dim_;
};

struct EpisodeRun {
  EpisodeSummary summary;
  std::vector<Transition> transitions;
  std::vector<TrajectoryRow> trajectory;
};

EpisodeRun run(const task::TaskConfig& task, ScriptedLink& link, Controller& controller,
               EpisodeOptions options) {
  EpisodeRun r;
  options.on_transition = [&r](const Transition& t) { r.transitions.push_back(t); };
  options.trajectory = &r.trajectory;
  r.summary = run_episode(task, link, controller, options);
  return r;
}

EpisodeOptions goal_north(double metres) {
  EpisodeOptions o;
  o.start.position_ned_m = Eigen::Vector3d(0.0, 0.0, 5.0);
  o.goal_ned_m = Eigen::Vector3d(metres, 0.0, 5.0);
  o.beta_m = 0.5;
  return o;
}

task::TaskConfig small_task() {
  task::TaskConfig t;
  t.max_steps = 50;
  return t;
}

TEST(RunEpisode, TimeLimitCutsOffWithoutATerminalTransition) {
  const task::TaskConfig task = small_task();
  ScriptedLink still(6, [](int, task::Observation&, VehicleReport&) {});
  ConstantController controller(0.5f, task.state_dim());
  const EpisodeRun r = run(task, still, controller, goal_north(5.0));
  EXPECT_EQ(r.summary.end_reason, task::EndReason::kTimeLimit);
  EXPECT_EQ(r.summary.length_steps, 50);
  EXPECT_FALSE(r.summary.success);
  EXPECT_LT(r.summary.time_to_reach_s, 0.0);
  ASSERT_EQ(r.transitions.size(), 50u);
  for (const Transition& t : r.transitions) EXPECT_FALSE(t.terminal);
  EXPECT_EQ(r.transitions.back().step_index, 49);
  EXPECT_DOUBLE_EQ(r.summary.final_distance_m, 5.0);
  // Every step: -1 - 0.1 * 0.25.
  EXPECT_NEAR(r.summary.episode_return, 50 * (-1.0 - 0.025), 1e-9);
  EXPECT_NEAR(r.summary.thrust_energy, 50 * 0.25, 1e-9);
  EXPECT_EQ(controller.resets, 1);
  EXPECT_EQ(controller.calls, 50);
  // The commands are the action times the maximum thrust.
  ASSERT_EQ(r.trajectory.size(), 50u);
  for (double f : r.trajectory.front().thrust_command_n) EXPECT_DOUBLE_EQ(f, 0.5 * 39.24);
}

TEST(RunEpisode, ReachingEndsWithTheGoalReward) {
  const task::TaskConfig task = small_task();
  ScriptedLink approach(6, [](int, task::Observation& o, VehicleReport&) {
    o.position_ned_m.x() += 0.5;  // 3 m away: inside 0.5 m after 5 steps
  });
  ConstantController controller(0.0f, task.state_dim());
  const EpisodeRun r = run(task, approach, controller, goal_north(3.0));
  EXPECT_EQ(r.summary.end_reason, task::EndReason::kReached);
  EXPECT_TRUE(r.summary.success);
  EXPECT_EQ(r.summary.length_steps, 5);
  ASSERT_EQ(r.transitions.size(), 5u);
  EXPECT_TRUE(r.transitions.back().terminal);
  EXPECT_DOUBLE_EQ(r.transitions.back().reward, 10.0);
  EXPECT_NEAR(r.summary.episode_return, 4 * -1.0 + 10.0, 1e-12);
  EXPECT_NEAR(r.summary.time_to_reach_s, 0.5, 1e-12);
  EXPECT_NEAR(r.transitions.back().achieved_position_ned_m.x(), 2.5, 1e-12);
}

TEST(RunEpisode, RunFullTimeKeepsGoingAfterReachingAndMeasuresTheHold) {
  const task::TaskConfig task = small_task();
  // Reaches 0.4 m short of the goal at step 5 (time 0.5 s), then stays.
  ScriptedLink approach(6, [](int step, task::Observation& o, VehicleReport&) {
    o.position_ned_m.x() = std::min(0.52 * step, 2.6);
  });
  ConstantController controller(0.0f, task.state_dim());
  EpisodeOptions options = goal_north(3.0);
  options.run_full_time = true;
  const EpisodeRun r = run(task, approach, controller, options);
  EXPECT_EQ(r.summary.length_steps, 50);
  EXPECT_EQ(r.summary.end_reason, task::EndReason::kReached);  // still inside at the end
  EXPECT_NEAR(r.summary.time_to_reach_s, 0.5, 1e-12);
  // Transitions stop where the task ended; the hold is measured to the end.
  EXPECT_EQ(r.transitions.size(), 5u);
  EXPECT_EQ(r.trajectory.size(), 50u);
  EXPECT_NEAR(r.summary.mean_error_after_reach_m, 0.4, 1e-9);
  EXPECT_NEAR(r.summary.final_distance_m, 0.4, 1e-9);
}

// Where the link knows the true position (a simulator in process, with sensor noise), the
// figures use it; the controller and the reward still get the reported observation.
TEST(RunEpisode, FiguresUseTheTruePositionWhereTheLinkKnowsIt) {
  const task::TaskConfig task = small_task();
  // Truly 0.4 m short of the goal from step 5 on; the report says 0.7 m beyond it (noise).
  ScriptedLink noisy(6, [](int step, task::Observation& o, VehicleReport& r) {
    const double x = std::min(0.52 * step, 2.6);
    r.true_position_ned_m = Eigen::Vector3d(x, o.position_ned_m.y(), o.position_ned_m.z());
    o.position_ned_m.x() = step >= 5 ? 3.7 : x;
  });
  ConstantController controller(0.0f, task.state_dim());
  EpisodeOptions options = goal_north(3.0);
  options.run_full_time = true;
  const EpisodeRun r = run(task, noisy, controller, options);
  EXPECT_NEAR(r.summary.time_to_reach_s, 0.5, 1e-12);
  EXPECT_NEAR(r.summary.mean_error_after_reach_m, 0.4, 1e-9);
  EXPECT_NEAR(r.summary.final_distance_m, 0.4, 1e-9);
  EXPECT_NEAR(r.trajectory.back().distance_m, 0.4, 1e-9);
  EXPECT_NEAR(r.trajectory.back().observation.position_ned_m.x(), 3.7, 1e-12);  // as reported
}

TEST(RunEpisode, StepsAfterReachEndsTheFullTimeRunThatManyStepsAfterArriving) {
  const task::TaskConfig task = small_task();
  ScriptedLink approach(6, [](int step, task::Observation& o, VehicleReport&) {
    o.position_ned_m.x() = std::min(0.52 * step, 2.6);  // within 0.5 m at step 5
  });
  ConstantController controller(0.0f, task.state_dim());
  EpisodeOptions options = goal_north(3.0);
  options.run_full_time = true;
  options.steps_after_reach = 7;
  const EpisodeRun r = run(task, approach, controller, options);
  EXPECT_NEAR(r.summary.time_to_reach_s, 0.5, 1e-12);
  EXPECT_EQ(r.summary.length_steps, 5 + 7);
  EXPECT_EQ(r.trajectory.size(), 12u);
  EXPECT_NEAR(r.summary.mean_error_after_reach_m, 0.4, 1e-9);
}

TEST(RunEpisode, LeavingBetaMaxFails) {
  task::TaskConfig task = small_task();
  task.beta_max_m = 20.0;
  ScriptedLink away(6, [](int, task::Observation& o, VehicleReport&) {
    o.position_ned_m.x() -= 1.0;  // 5 m from the goal, 1 m farther per step: out after 16
  });
  ConstantController controller(0.0f, task.state_dim());
  EpisodeOptions options = goal_north(5.0);
  options.run_full_time = true;  // failures end the episode anyway
  const EpisodeRun r = run(task, away, controller, options);
  EXPECT_EQ(r.summary.end_reason, task::EndReason::kLeftRegion);
  EXPECT_EQ(r.summary.length_steps, 16);
  ASSERT_EQ(r.transitions.size(), 16u);
  EXPECT_TRUE(r.transitions.back().terminal);
  EXPECT_DOUBLE_EQ(r.transitions.back().reward, task.failure_reward);
  EXPECT_FALSE(r.summary.success);
}

TEST(RunEpisode, FlippingFails) {
  const task::TaskConfig task = small_task();
  ScriptedLink roll(6, [](int, task::Observation& o, VehicleReport&) {
    o.euler_rpy_rad.x() += 0.25;  // beyond 1.2 rad after 5 steps (exact in binary)
  });
  ConstantController controller(0.0f, task.state_dim());
  const EpisodeRun r = run(task, roll, controller, goal_north(5.0));
  EXPECT_EQ(r.summary.end_reason, task::EndReason::kFlipped);
  EXPECT_EQ(r.summary.length_steps, 5);
  EXPECT_TRUE(r.transitions.back().terminal);
}

TEST(RunEpisode, BlowUpEndsTheEpisodeAndReportsNoTransitionForIt) {
  const task::TaskConfig task = small_task();
  // NaN in each part of the observation in turn, and the simulator's own flag.
  const std::vector<std::function<void(task::Observation&, VehicleReport&)>> faults = {
      [](task::Observation& o, VehicleReport&) { o.position_ned_m.y() = kNaN; },
      [](task::Observation& o, VehicleReport&) { o.euler_rpy_rad.y() = kNaN; },
      [](task::Observation& o, VehicleReport&) { o.velocity_body_mps.z() = kNaN; },
      [](task::Observation& o, VehicleReport&) {
        o.angular_rate_body_rad_s.x() = std::numeric_limits<double>::infinity();
      },
      [](task::Observation&, VehicleReport& r) { r.blown_up = true; },
  };
  for (std::size_t k = 0; k < faults.size(); ++k) {
    ScriptedLink link(6, [&](int step, task::Observation& o, VehicleReport& r) {
      if (step == 3) faults[k](o, r);
    });
    ConstantController controller(0.0f, task.state_dim());
    const EpisodeRun r = run(task, link, controller, goal_north(5.0));
    EXPECT_EQ(r.summary.end_reason, task::EndReason::kBlowUp) << "fault " << k;
    EXPECT_EQ(r.transitions.size(), 2u) << "fault " << k;
    EXPECT_EQ(r.trajectory.size(), 2u) << "fault " << k;
    for (const Transition& t : r.transitions) {
      EXPECT_TRUE(t.state.allFinite());
      EXPECT_TRUE(t.next_state.allFinite());
    }
  }
}

TEST(RunEpisode, SilentSimulatorIsATimeout) {
  const task::TaskConfig task = small_task();
  ScriptedLink link(6, [](int, task::Observation&, VehicleReport&) {});
  link.silent_from = 4;
  ConstantController controller(0.0f, task.state_dim());
  const EpisodeRun r = run(task, link, controller, goal_north(5.0));
  EXPECT_EQ(r.summary.end_reason, task::EndReason::kSimTimeout);
  EXPECT_EQ(r.transitions.size(), 3u);
}

TEST(RunEpisode, ThrusterCountMismatchIsRejected) {
  const task::TaskConfig task = small_task();  // six thrusters
  ScriptedLink link(4, [](int, task::Observation&, VehicleReport&) {});
  ConstantController controller(0.0f, task.state_dim());
  EXPECT_THROW(run_episode(task, link, controller, goal_north(5.0)), std::invalid_argument);
}

TEST(RunEpisode, NoiseIsAppliedAndClipped) {
  const task::TaskConfig task = small_task();
  ScriptedLink still(6, [](int, task::Observation&, VehicleReport&) {});
  ConstantController controller(0.9f, task.state_dim());
  ExplorationNoise noise(ExplorationNoise::Kind::kGaussian, 6, 0.5, 0.15, 8);
  EpisodeOptions options = goal_north(5.0);
  options.noise = &noise;
  const EpisodeRun r = run(task, still, controller, options);
  bool changed = false;
  for (const Transition& t : r.transitions) {
    EXPECT_LE(t.action.cwiseAbs().maxCoeff(), 1.0f);
    changed |= t.action != task::ActionVector::Constant(6, 0.9f);
  }
  EXPECT_TRUE(changed);
  // The next state carries the applied (noisy) action as its previous action (paper layout).
  EXPECT_EQ(r.transitions[3].next_state.tail(6), r.transitions[3].action);
  EXPECT_EQ(r.transitions[4].state.tail(6), r.transitions[3].action);
}

}  // namespace
}  // namespace auvrl::agent
