// Hindsight relabelling: a relabelled transition equals the transition the task would have
// produced had the episode's goal been the relabelled one (states, reward with the command change
// price, termination).
#include <gtest/gtest.h>

#include <cmath>

#include "common/task/task.hpp"
#include "learner/hindsight.hpp"

namespace {

using namespace auvrl;

struct Step {
  task::Observation obs;
  task::ActionVector action;
};

/// A made-up episode: the vehicle moves along a curve with changing attitude.
std::vector<Step> make_episode(int n) {
  std::vector<Step> steps;
  for (int t = 0; t <= n; ++t) {
    Step s;
    s.obs.position_ned_m = {0.3 * t, 0.1 * t * std::sin(0.2 * t), 5.0 + 0.05 * t};
    s.obs.euler_rpy_rad = {0.05 * std::sin(0.3 * t), 0.1 * std::cos(0.2 * t), 0.15 * t - 1.0};
    s.obs.velocity_body_mps = {0.3, 0.05 * t, -0.02};
    s.obs.angular_rate_body_rad_s = {0.01, -0.02, 0.15};
    s.action = task::ActionVector::Constant(6, static_cast<float>(0.1 * std::sin(t)));
    steps.push_back(s);
  }
  return steps;
}

class HindsightTest : public ::testing::TestWithParam<task::StateLayout> {};

TEST_P(HindsightTest, RelabelledTransitionsEqualThoseBuiltForTheNewGoal) {
  task::TaskConfig cfg;
  cfg.layout = GetParam();
  cfg.reward = task::RewardKind::kShaped;
  cfg.command_change_weight = 0.5;  // its u_t-1 comes from the stored state
  const int n = 40;
  const auto steps = make_episode(n);
  const Eigen::Vector3d goal(20.0, -5.0, 12.0);
  const double beta = 0.5;
  learner::ReplayBuffer replay(cfg.state_dim(), 6, 1000);
  learner::HindsightRelabeler her(cfg, 4);
  task::StateVector s, s2;
  task::ActionVector prev = task::ActionVector::Zero(6);
  const task::ActionVector expert = task::ActionVector::Constant(6, 0.25f);  // every step labelled
  for (int t = 0; t < n; ++t) {
    task::build_state(cfg, steps[t].obs, goal, prev, s);
    task::build_state(cfg, steps[t + 1].obs, goal, steps[t].action, s2);
    const double d0 = (goal - steps[t].obs.position_ned_m).norm();
    const double d1 = (goal - steps[t + 1].obs.position_ned_m).norm();
    const auto out = task::evaluate_step(cfg, d0, d1, false, steps[t].action, beta, t + 1, prev);
    const learner::TransitionView view{s,
                                       steps[t].action,
                                       static_cast<float>(out.reward),
                                       s2,
                                       out.terminal,
                                       steps[t + 1].obs.position_ned_m.cast<float>(),
                                       goal.cast<float>(),
                                       7,
                                       static_cast<std::uint32_t>(t),
                                       expert.data()};
    const std::size_t slot = replay.next_slot();
    replay.add(view);
    her.on_add(replay, slot, false, 0);
    prev = steps[t].action;
  }

  nn::Rng rng(3);
  learner::Batch batch(cfg.state_dim(), 6, 64);
  int checked = 0;
  for (int round = 0; round < 20; ++round) {
    replay.sample(rng, 64, batch);
    learner::Batch original = batch;
    her.relabel(replay, beta, rng, batch);
    for (int i = 0; i < batch.size; ++i) {
      const std::size_t slot = batch.slot[static_cast<std::size_t>(i)];
      const int t = static_cast<int>(replay.step_index(slot));
      if ((batch.state.col(i) - original.state.col(i)).norm() == 0.0f) {
        EXPECT_EQ(batch.has_expert(0, i), 1.0f);  // not chosen: the label still holds
        continue;
      }
      // The expert's label was for the old goal: it goes with it.
      EXPECT_EQ(batch.has_expert(0, i), 0.0f);
      // Which goal was used? One of the later achieved positions: find it.
      bool matched = false;
      for (int f = t; f < n && !matched; ++f) {
        const Eigen::Vector3d g = steps[f + 1].obs.position_ned_m.cast<float>().cast<double>();
        task::StateVector expect, expect2;
        task::build_state(cfg, steps[t].obs, g,
                          t > 0 ? steps[t - 1].action : task::ActionVector::Zero(6), expect);
        if ((expect - batch.state.col(i)).cwiseAbs().maxCoeff() > 2e-4f) continue;
        task::build_state(cfg, steps[t + 1].obs, g, steps[t].action, expect2);
        EXPECT_LT((expect2 - batch.next_state.col(i)).cwiseAbs().maxCoeff(), 2e-4f);
        const double d0 = (g - steps[t].obs.position_ned_m).norm();
        const double d1 = (g - steps[t + 1].obs.position_ned_m).norm();
        const auto out =
            task::evaluate_step(cfg, d0, d1, false, steps[t].action, beta, t + 1,
                                t > 0 ? steps[t - 1].action : task::ActionVector::Zero(6));
        EXPECT_NEAR(batch.reward(0, i), out.reward, 1e-3);
        EXPECT_EQ(batch.terminal(0, i) > 0.5f, out.terminal);
        matched = true;
      }
      EXPECT_TRUE(matched) << "relabelled goal is not a later achieved position (step " << t << ")";
      ++checked;
    }
  }
  // k = 4: about 80 % of samples are relabelled (all but each episode's last step can be).
  EXPECT_GT(checked, 20 * 64 * 6 / 10);
  EXPECT_EQ(her.relabelled(), checked);
}

INSTANTIATE_TEST_SUITE_P(BothLayouts, HindsightTest,
                         ::testing::Values(task::StateLayout::kPaper,
                                           task::StateLayout::kExtended));

TEST(Hindsight, RelabellingToTheReachedPositionGivesTheGoalReward) {
  task::TaskConfig cfg;
  cfg.layout = task::StateLayout::kExtended;
  learner::ReplayBuffer replay(cfg.state_dim(), 6, 100);
  learner::HindsightRelabeler her(cfg, 1000000);  // relabel (almost) always
  const auto steps = make_episode(1);
  task::StateVector s, s2;
  const Eigen::Vector3d goal(30, 30, 30);
  task::build_state(cfg, steps[0].obs, goal, task::ActionVector::Zero(6), s);
  task::build_state(cfg, steps[1].obs, goal, steps[0].action, s2);
  replay.add({s, steps[0].action, -1.0f, s2, false, steps[1].obs.position_ned_m.cast<float>(),
              goal.cast<float>(), 1, 0});
  her.on_add(replay, 0, false, 0);
  nn::Rng rng(1);
  learner::Batch batch(cfg.state_dim(), 6, 4);
  replay.sample(rng, 4, batch);
  her.relabel(replay, 0.5, rng, batch);
  // The only future goal is where the vehicle arrived: reached, terminal, +goal_reward.
  for (int i = 0; i < 4; ++i) {
    EXPECT_FLOAT_EQ(batch.reward(0, i), static_cast<float>(cfg.goal_reward));
    EXPECT_EQ(batch.terminal(0, i), 1.0f);
  }
}

TEST(Hindsight, OverwrittenEpisodesAreForgotten) {
  task::TaskConfig cfg;
  learner::ReplayBuffer replay(cfg.state_dim(), 6, 4);
  learner::HindsightRelabeler her(cfg, 1000000);
  const auto steps = make_episode(8);
  task::StateVector s;
  task::build_state(cfg, steps[0].obs, {1, 2, 3}, task::ActionVector::Zero(6), s);
  for (int t = 0; t < 8; ++t) {
    const std::size_t slot = replay.next_slot();
    const bool overwrote = replay.size() == replay.capacity();
    const std::uint64_t old = overwrote ? replay.episode_id(slot) : 0;
    // Episode 1 has steps 0..3, episode 2 steps 0..3: episode 2 overwrites episode 1.
    replay.add({s, steps[t].action, -1.0f, s, false, Eigen::Vector3f(t, 0, 5),
                Eigen::Vector3f(1, 2, 3), static_cast<std::uint64_t>(1 + t / 4),
                static_cast<std::uint32_t>(t % 4)});
    her.on_add(replay, slot, overwrote, old);
  }
  nn::Rng rng(2);
  learner::Batch batch(cfg.state_dim(), 6, 32);
  replay.sample(rng, 32, batch);
  her.relabel(replay, 0.5, rng, batch);
  // Every future goal comes from episode 2 (achieved x = 4..7), never from episode 1.
  for (int i = 0; i < batch.size; ++i) {
    EXPECT_EQ(replay.episode_id(batch.slot[static_cast<std::size_t>(i)]), 2u);
  }
  EXPECT_GT(her.relabelled(), 0);
}

}  // namespace
