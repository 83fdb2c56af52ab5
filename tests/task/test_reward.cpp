// Reward and episode end of Eq. 14 (evaluate_step) and its options: every case.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/task/task.hpp"

namespace auvrl::task {
namespace {

ActionVector uniform_action(float value) { return ActionVector::Constant(6, value); }

TEST(Reward, ReachingPaysTheGoalRewardAndEndsTheTask) {
  const TaskConfig c;
  const StepOutcome o = evaluate_step(c, 0.8, 0.4, false, uniform_action(0.5f), 0.5, 10);
  EXPECT_DOUBLE_EQ(o.reward, 10.0);
  EXPECT_TRUE(o.terminal);
  EXPECT_TRUE(o.done);
  EXPECT_TRUE(o.inside_goal);
  EXPECT_EQ(o.reason, EndReason::kReached);
  EXPECT_DOUBLE_EQ(o.distance_m, 0.4);
}

TEST(Reward, ReachingIsInclusiveAtBeta) {
  const TaskConfig c;
  const StepOutcome o = evaluate_step(c, 1.0, 0.5, false, uniform_action(0.0f), 0.5, 1);
  EXPECT_EQ(o.reason, EndReason::kReached);
}

TEST(Reward, StepCostsOnePlusWeightedThrust) {
  TaskConfig c;
  c.thrust_weight = 0.1;
  ActionVector a(6);
  a << 1.0f, -1.0f, 0.5f, 0.0f, 0.0f, -0.5f;  // mean of squares = 2.5 / 6
  const StepOutcome o = evaluate_step(c, 5.0, 4.0, false, a, 0.5, 1);
  EXPECT_NEAR(o.reward, -1.0 - 0.1 * 2.5 / 6.0, 1e-12);
  EXPECT_NEAR(thrust_cost(c, a), 0.1 * 2.5 / 6.0, 1e-12);
  EXPECT_FALSE(o.terminal);
  EXPECT_FALSE(o.done);
  EXPECT_FALSE(o.inside_goal);
  EXPECT_EQ(o.reason, EndReason::kNone);
  // No thrust, no cost: exactly the paper's -1.
  EXPECT_DOUBLE_EQ(evaluate_step(c, 5.0, 4.0, false, uniform_action(0.0f), 0.5, 1).reward, -1.0);
}

TEST(Reward, LeavingBetaMaxFailsAndEnds) {
  TaskConfig c;
  c.beta_max_m = 20.0;
  const StepOutcome inside = evaluate_step(c, 19.9, 20.0, false, uniform_action(0.0f), 0.5, 3);
  EXPECT_FALSE(inside.done);  // d = beta_max is still allowed
  const StepOutcome o = evaluate_step(c, 19.9, 20.01, false, uniform_action(0.0f), 0.5, 3);
  EXPECT_DOUBLE_EQ(o.reward, -10.0);
  EXPECT_TRUE(o.terminal);
  EXPECT_TRUE(o.done);
  EXPECT_EQ(o.reason, EndReason::kLeftRegion);
  c.failure_reward = -100.0;  // the 1/(1 - gamma) option
  EXPECT_DOUBLE_EQ(evaluate_step(c, 19.9, 25.0, false, uniform_action(0.0f), 0.5, 3).reward,
                   -100.0);
}

TEST(Reward, FlipFailsEvenInsideTheGoal) {
  const TaskConfig c;
  const StepOutcome o = evaluate_step(c, 0.3, 0.2, true, uniform_action(0.0f), 0.5, 3);
  EXPECT_DOUBLE_EQ(o.reward, c.failure_reward);
  EXPECT_TRUE(o.terminal);
  EXPECT_EQ(o.reason, EndReason::kFlipped);
}

TEST(Reward, FlipAngleOnRollOrPitch) {
  TaskConfig c;
  c.flip_angle_rad = 1.2;
  EXPECT_FALSE(is_flipped(c, Eigen::Vector3d(1.19, -1.19, 3.0)));  // yaw never flips
  EXPECT_TRUE(is_flipped(c, Eigen::Vector3d(1.21, 0.0, 0.0)));
  EXPECT_TRUE(is_flipped(c, Eigen::Vector3d(-1.21, 0.0, 0.0)));
  EXPECT_TRUE(is_flipped(c, Eigen::Vector3d(0.0, 1.21, 0.0)));
  EXPECT_TRUE(is_flipped(c, Eigen::Vector3d(0.0, -1.21, 0.0)));
}

TEST(Reward, TimeLimitIsACutOffNotATerminalState) {
  TaskConfig c;
  c.max_steps = 700;
  const StepOutcome before = evaluate_step(c, 5.0, 5.0, false, uniform_action(0.0f), 0.5, 699);
  EXPECT_FALSE(before.done);
  const StepOutcome o = evaluate_step(c, 5.0, 5.0, false, uniform_action(0.0f), 0.5, 700);
  EXPECT_TRUE(o.done);
  EXPECT_FALSE(o.terminal);  // the learner bootstraps through it
  EXPECT_EQ(o.reason, EndReason::kTimeLimit);
  EXPECT_DOUBLE_EQ(o.reward, -1.0);  // the ordinary step reward, no extra penalty
}

TEST(Reward, HoldModeKeepsGoingAndPaysTheHoldReward) {
  TaskConfig c;
  c.hold_mode = true;
  c.hold_reward_per_step = 1.5;
  const ActionVector a = uniform_action(0.5f);  // cost 0.1 * 0.25
  const StepOutcome o = evaluate_step(c, 0.6, 0.3, false, a, 0.5, 10);
  EXPECT_TRUE(o.inside_goal);
  EXPECT_FALSE(o.done);
  EXPECT_FALSE(o.terminal);
  EXPECT_EQ(o.reason, EndReason::kNone);
  EXPECT_NEAR(o.reward, -1.0 - 0.025 + 1.5, 1e-12);
  // Outside the goal in hold mode: the ordinary step reward.
  EXPECT_NEAR(evaluate_step(c, 2.0, 1.9, false, a, 0.5, 10).reward, -1.025, 1e-12);
  // Inside at the time limit: cut off, not terminal.
  const StepOutcome last = evaluate_step(c, 0.3, 0.3, false, a, 0.5, c.max_steps);
  EXPECT_TRUE(last.done);
  EXPECT_FALSE(last.terminal);
  EXPECT_EQ(last.reason, EndReason::kTimeLimit);
  // Shaped reward in hold mode: progress + hold reward.
  c.reward = RewardKind::kShaped;
  EXPECT_NEAR(evaluate_step(c, 0.45, 0.25, false, a, 0.5, 10).reward,
              10.0 * 0.2 - 1.0 - 0.025 + 1.5, 1e-12);
}

TEST(Reward, ShapedProgressSign) {
  TaskConfig c;
  c.reward = RewardKind::kShaped;
  c.progress_weight = 10.0;
  const ActionVector a = uniform_action(0.0f);
  const StepOutcome closer = evaluate_step(c, 5.0, 4.9, false, a, 0.5, 1);
  const StepOutcome away = evaluate_step(c, 5.0, 5.1, false, a, 0.5, 1);
  const StepOutcome still = evaluate_step(c, 5.0, 5.0, false, a, 0.5, 1);
  EXPECT_NEAR(closer.reward, 10.0 * 0.1 - 1.0, 1e-12);
  EXPECT_NEAR(away.reward, -10.0 * 0.1 - 1.0, 1e-12);
  EXPECT_NEAR(still.reward, -1.0, 1e-12);
  EXPECT_GT(closer.reward, still.reward);
  EXPECT_LT(away.reward, still.reward);
  // The goal and failure rewards are the same as the paper's.
  EXPECT_DOUBLE_EQ(evaluate_step(c, 0.7, 0.4, false, a, 0.5, 1).reward, c.goal_reward);
  EXPECT_DOUBLE_EQ(evaluate_step(c, 19.0, 21.0, false, a, 0.5, 1).reward, c.failure_reward);
}

TEST(Reward, ShapedDistanceAndPrecisionTerms) {
  TaskConfig c;
  c.reward = RewardKind::kShaped;
  c.hold_mode = true;
  c.hold_reward_per_step = 1.0;
  c.step_penalty = 0.1;
  c.thrust_weight = 0.0;
  c.distance_weight = 0.2;
  c.precision_reward = 2.0;
  c.precision_scale_m = 0.25;
  const ActionVector a = uniform_action(0.0f);
  // Far away: progress - step - distance term + a vanishing precision bonus.
  EXPECT_NEAR(evaluate_step(c, 5.1, 5.0, false, a, 0.5, 1).reward,
              10.0 * 0.1 - 0.1 - 0.2 * 5.0 + 2.0 * std::exp(-5.0 / 0.25), 1e-12);
  // Holding still inside beta: closer pays more (the flat hold reward alone does not).
  const StepOutcome near = evaluate_step(c, 0.1, 0.1, false, a, 0.5, 50);
  const StepOutcome rim = evaluate_step(c, 0.4, 0.4, false, a, 0.5, 50);
  EXPECT_NEAR(near.reward, -0.1 - 0.02 + 2.0 * std::exp(-0.4) + 1.0, 1e-12);
  EXPECT_NEAR(rim.reward, -0.1 - 0.08 + 2.0 * std::exp(-1.6) + 1.0, 1e-12);
  EXPECT_GT(near.reward, rim.reward);
  EXPECT_FALSE(near.done);
  // At the goal itself the bonus is whole.
  EXPECT_NEAR(evaluate_step(c, 0.0, 0.0, false, a, 0.5, 50).reward, -0.1 + 2.0 + 1.0, 1e-12);
  // Failure is still the failure reward alone.
  EXPECT_DOUBLE_EQ(evaluate_step(c, 19.0, 21.0, false, a, 0.5, 1).reward, c.failure_reward);
}

TEST(Reward, PaperRewardIgnoresTheShapedTerms) {
  TaskConfig c;  // the paper's Eq. 14
  c.distance_weight = 0.5;
  c.precision_reward = 3.0;
  c.progress_weight = 10.0;
  EXPECT_DOUBLE_EQ(evaluate_step(c, 5.0, 4.0, false, uniform_action(0.0f), 0.5, 1).reward, -1.0);
  EXPECT_DOUBLE_EQ(evaluate_step(c, 0.8, 0.1, false, uniform_action(0.0f), 0.5, 1).reward, 10.0);
}

// The command change price: -w * mean((u_t - u_t-1)^2) on every step that is not the goal or a
// failure, in both rewards; nothing without a previous command or with w = 0; u_t-1 as every
// layout's state carries it.
TEST(Reward, CommandChangesArePricedWhenAsked) {
  for (RewardKind kind : {RewardKind::kPaper, RewardKind::kShaped}) {
    TaskConfig c;
    c.reward = kind;
    ActionVector a(6), previous(6);
    a << 1.0f, -1.0f, 0.5f, 0.0f, 0.0f, -0.5f;
    previous << 0.0f, -1.0f, 0.5f, 0.5f, 0.0f, 0.5f;  // squared changes 1 + 0.25 + 1 = 2.25
    const double plain = evaluate_step(c, 5.0, 4.0, false, a, 0.5, 1).reward;
    EXPECT_DOUBLE_EQ(evaluate_step(c, 5.0, 4.0, false, a, 0.5, 1, previous).reward, plain);
    c.command_change_weight = 0.4;
    EXPECT_NEAR(command_change_cost(c, a, previous), 0.4 * 2.25 / 6.0, 1e-12);
    EXPECT_NEAR(evaluate_step(c, 5.0, 4.0, false, a, 0.5, 1, previous).reward,
                plain - 0.4 * 2.25 / 6.0, 1e-12);
    EXPECT_DOUBLE_EQ(evaluate_step(c, 5.0, 4.0, false, a, 0.5, 1, a).reward, plain);
    EXPECT_DOUBLE_EQ(evaluate_step(c, 5.0, 4.0, false, a, 0.5, 1).reward, plain);
    EXPECT_DOUBLE_EQ(evaluate_step(c, 0.8, 0.4, false, a, 0.5, 1, previous).reward, c.goal_reward);
    EXPECT_DOUBLE_EQ(evaluate_step(c, 5.0, 25.0, false, a, 0.5, 1, previous).reward,
                     c.failure_reward);
    EXPECT_THROW(command_change_cost(c, a, ActionVector::Zero(5)), std::invalid_argument);
  }
  for (StateLayout layout :
       {StateLayout::kPaper, StateLayout::kExtended, StateLayout::kExtendedThrust}) {
    TaskConfig c;
    c.layout = layout;
    ActionVector previous(6), read;
    previous << 0.1f, -0.2f, 0.3f, -0.4f, 0.5f, -0.6f;
    StateVector state;
    build_state(c, Observation{}, Eigen::Vector3d(1.0, 2.0, 3.0), previous, state,
                std::vector<double>(6, 5.0));
    previous_action_from_state(c, state, read);
    EXPECT_EQ(read, previous) << to_string(layout);
  }
}

TEST(TaskConfig, ValidateRejectsUnusableValues) {
  EXPECT_NO_THROW(TaskConfig{}.validate());
  TaskConfig c;
  c.beta_max_m = 0.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.max_steps = 0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.scales.position_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.goal_min_ned_m.x() = 11.0;  // min > max
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.failure_reward = std::numeric_limits<double>::infinity();
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.precision_scale_m = 0.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.distance_weight = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.random_start_fraction = 1.5;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.start_velocity_max_body_mps.y() = -0.1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.start_attitude_spread_rad.y() = c.flip_angle_rad;  // would start flipped
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.start_rate_max_body_rad_s.z() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = TaskConfig{};
  c.command_change_weight = -0.1;
  try {
    c.validate();
    ADD_FAILURE() << "a negative command_change_weight was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("task.command_change_weight"), std::string::npos);
  }
}

TEST(TaskConfig, ParsesNames) {
  EXPECT_EQ(parse_layout("paper"), StateLayout::kPaper);
  EXPECT_EQ(parse_layout("extended"), StateLayout::kExtended);
  EXPECT_THROW(parse_layout("Paper"), std::invalid_argument);
  EXPECT_EQ(parse_layout("extended_thrust"), StateLayout::kExtendedThrust);
  EXPECT_STREQ(to_string(StateLayout::kExtendedThrust), "extended_thrust");
  EXPECT_EQ(parse_reward_kind("shaped"), RewardKind::kShaped);
  EXPECT_EQ(parse_reward_kind(to_string(RewardKind::kPaper)), RewardKind::kPaper);
  EXPECT_THROW(parse_reward_kind("dense"), std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::task
