// auv_learner's handling of hostile messages with a valid LCM encoding, in-process (memq):
// malformed experience, NaN/inf, actions or expert labels beyond [-1, 1], malformed
// expert labels, too many or no transitions, unknown actor ids, and episode reports from unknown
// actors are dropped and counted; nothing of them reaches the replay buffer, the updates or the
// schedule. Sound experience of other sizes (an actor of another vehicle) stops the learner.
// LEARNER_STATS carries the smoothness terms' values. The mean of the actor's recent weights
// survives a checkpoint.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/nn/serialize.hpp"
#include "common/unrecoverable.hpp"
#include "learner/learner_node.hpp"
#include "sim/vehicle_model.hpp"
#include "synthetic_experience.hpp"

namespace {

using namespace auvrl;

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Nessie VII's facts as its file gives them.
VehicleFacts nessie7_facts() {
  return sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml").facts();
}

class LearnerNodeInput : public ::testing::Test {
 protected:
  LearnerNodeInput() : transport_(transport::make_in_process_transport()) {
    config_.vehicle = nessie7_facts();
    task::apply_vehicle(config_.vehicle, config_.task);
    config_.ddpg.state_dim = config_.task.state_dim();
    config_.ddpg.action_dim = config_.task.num_thrusters;
    config_.ddpg.actor_hidden = {8, 8};
    config_.ddpg.critic_hidden = {8, 8};
    config_.ddpg.batch_size = 4;
    config_.ddpg.replay_capacity = 256;
    config_.her = true;
    config_.max_actors = 4;
    config_.max_transitions_per_batch = 50;
    node_ = std::make_unique<learner::LearnerNode>(config_, *transport_, log_);
  }

  auvrl_lcm::experience_batch_t batch(int n = 5, int actor = 1) {
    return test_support::synthetic_experience_batch(actor, ++seq_, n, config_.ddpg.state_dim,
                                                    config_.ddpg.action_dim);
  }
  template <class Msg>
  void send(const std::string& channel, const Msg& msg) {
    transport::publish(*transport_, channel, msg);
    node_->poll(0);
    transport_->drain();
  }
  /// Asserts that nothing was taken in.
  void expect_untouched() {
    EXPECT_EQ(node_->replay().size(), 0u);
    EXPECT_EQ(node_->counters().transitions_received, 0);
    EXPECT_EQ(node_->updates(), 0);
  }

  learner::LearnerNodeConfig config_;
  std::unique_ptr<transport::Transport> transport_;
  std::ostringstream log_;
  std::unique_ptr<learner::LearnerNode> node_;
  std::int64_t seq_ = 0;
};

TEST_F(LearnerNodeInput, MalformedDimensionsAndCountsAreDropped) {
  // (The wire format sizes every row by state_dim and action_dim: rows cannot disagree.)
  send(channels::kExperience, test_support::synthetic_experience_batch(1, 3, 5, 0, 0));
  send(channels::kExperience, batch(0));                                      // no transitions
  send(channels::kExperience, batch(config_.max_transitions_per_batch + 1));  // too many
  EXPECT_EQ(node_->counters().dropped_dims, 3);
  expect_untouched();
}

TEST_F(LearnerNodeInput, SoundExperienceOfOtherSizesStopsTheLearnerNamingBoth) {
  // An actor of another vehicle (8 thrusters) or layout: consistent arrays, other sizes.
  const int sd = config_.ddpg.state_dim, ad = config_.ddpg.action_dim;
  for (const auto& [state_dim, action_dim] : {std::pair{sd + 1, ad}, std::pair{sd, ad + 2}}) {
    node_ = std::make_unique<learner::LearnerNode>(config_, *transport_, log_);
    transport::publish(*transport_, channels::kExperience,
                       test_support::synthetic_experience_batch(1, 1, 5, state_dim, action_dim));
    try {
      node_->poll(0);
      FAIL() << "experience of state " << state_dim << ", action " << action_dim << " was taken";
    } catch (const UnrecoverableFault& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(fmt::format("has state {} and action {} values", state_dim, action_dim)),
                std::string::npos)
          << what;
      EXPECT_NE(what.find(fmt::format("take state {} and action {}", sd, ad)), std::string::npos)
          << what;
      EXPECT_NE(what.find("'nessie7'"), std::string::npos) << what;
    }
    transport_->drain();
    EXPECT_EQ(node_->counters().dropped_dims, 1);
    expect_untouched();
  }
}

TEST_F(LearnerNodeInput, NonFiniteValuesAnywhereAreDropped) {
  auto b = batch();
  b.states[1][3] = std::nanf("");
  send(channels::kExperience, b);
  b = batch();
  b.next_states[4][0] = kInf;
  send(channels::kExperience, b);
  b = batch();
  b.rewards[0] = -kInf;
  send(channels::kExperience, b);
  b = batch();
  b.actions[2][5] = std::nanf("");
  send(channels::kExperience, b);
  b = batch();
  b.achieved_position_ned_m[3][2] = kInf;
  send(channels::kExperience, b);
  b = batch();
  b.goal_ned_m[0][1] = std::nanf("");
  send(channels::kExperience, b);
  b = batch();
  b.actions[0][0] = 1.5f;  // beyond tanh: not from a policy
  send(channels::kExperience, b);
  EXPECT_EQ(node_->counters().dropped_non_finite, 7);
  expect_untouched();
}

// Expert labels: none or one per transition of action_dim values in [-1, 1]; anything else is
// dropped whole, and good labels reach the replay buffer with the transitions.
TEST_F(LearnerNodeInput, ExpertLabelsAreCheckedAndStored) {
  const int ad = config_.ddpg.action_dim;
  const auto labelled = [&](int n) {
    auto b = batch(n);
    b.expert_rows = n;
    b.expert_actions.assign(static_cast<std::size_t>(n), std::vector<float>(ad, -0.5f));
    return b;
  };
  auto b = labelled(5);
  b.expert_rows = 4;  // neither 0 nor num_transitions
  b.expert_actions.pop_back();
  send(channels::kExperience, b);
  b = labelled(5);
  b.expert_rows = 6;
  b.expert_actions.push_back(b.expert_actions.back());
  send(channels::kExperience, b);
  EXPECT_EQ(node_->counters().dropped_dims, 2);
  b = labelled(5);
  b.expert_actions[2][1] = std::nanf("");
  send(channels::kExperience, b);
  b = labelled(5);
  b.expert_actions[4][0] = -1.5f;  // beyond [-1, 1]
  send(channels::kExperience, b);
  EXPECT_EQ(node_->counters().dropped_non_finite, 2);
  expect_untouched();

  send(channels::kExperience, labelled(3));
  send(channels::kExperience, batch(2));  // no labels
  ASSERT_EQ(node_->replay().size(), 5u);
  for (std::size_t slot = 0; slot < 5; ++slot) {
    EXPECT_EQ(node_->replay().has_expert(slot), slot < 3) << slot;
    EXPECT_EQ(node_->replay().expert_action(slot)[ad - 1], slot < 3 ? -0.5f : 0.0f) << slot;
  }
}

TEST_F(LearnerNodeInput, UnknownActorsAreDroppedAndDoNotAdvanceTheSchedule) {
  send(channels::kExperience, batch(5, -1));
  send(channels::kExperience, batch(5, config_.max_actors));
  send(channels::kExperience, batch(5, std::numeric_limits<std::int32_t>::max()));
  auvrl_lcm::episode_report_t report{};
  report.actor_id = 99;
  send(channels::kEpisode, report);
  report.actor_id = -7;
  send(channels::kEpisode, report);
  EXPECT_EQ(node_->counters().dropped_unknown_actor, 5);
  EXPECT_EQ(node_->episodes(), 0);
  expect_untouched();
}

TEST_F(LearnerNodeInput, HostileStepIndicesAndEpisodeIdsAreStoredSafely) {
  // Values the learner cannot check against anything: extreme but valid numbers must neither
  // crash the hindsight index nor make it allocate per claimed step.
  auto b = batch(8);
  b.step_index = {-1, std::numeric_limits<std::int32_t>::max(), 0, 99999, 5, 5, 3, 700};
  b.episode_id = {std::numeric_limits<std::int64_t>::min(), -1, 0, 1, 2, 2, 2,
                  std::numeric_limits<std::int64_t>::max()};
  send(channels::kExperience, b);
  EXPECT_EQ(node_->replay().size(), 8u);
  for (int i = 0; i < 20; ++i) node_->poll(0);  // updates sample and relabel these
  EXPECT_GT(node_->updates(), 0);
  transport_->drain();
}

TEST_F(LearnerNodeInput, UndecodableBytesAreCounted) {
  const std::uint8_t garbage[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  transport_->publish(channels::kExperience, garbage, sizeof garbage);
  transport_->publish(channels::kEpisode, garbage, sizeof garbage);
  transport_->publish(channels::kWeightsRequest, garbage, sizeof garbage);
  node_->poll(0);
  EXPECT_EQ(node_->counters().dropped_decode, 3);
  EXPECT_EQ(node_->counters().weights_requests, 0);
  expect_untouched();
}

// With the temporal smoothness term on (and the spatial one off), LEARNER_STATS reports the
// mean squared command change the actor steps saw.
TEST_F(LearnerNodeInput, StatsReportTheSmoothnessTerms) {
  config_.ddpg.smooth_temporal_weight = 0.5f;
  config_.her = false;
  node_.reset();
  node_ = std::make_unique<learner::LearnerNode>(config_, *transport_, log_);
  std::vector<auvrl_lcm::learner_stats_t> stats;
  transport::subscribe<auvrl_lcm::learner_stats_t>(
      *transport_, channels::kLearnerStats,
      [&stats](const std::string&, const auvrl_lcm::learner_stats_t& m) { stats.push_back(m); });
  for (int i = 0; i < 4; ++i) send(channels::kExperience, batch(40));
  for (int i = 0; i < 50; ++i) node_->poll(0);
  ASSERT_GT(node_->updates(), 10);
  node_->finish();
  transport_->drain();
  ASSERT_FALSE(stats.empty());
  EXPECT_GT(stats.back().smooth_temporal, 0.0);
  EXPECT_EQ(stats.back().smooth_spatial, 0.0);
}

// The mean of the actor's recent weights is kept in the checkpoint (a resumed learner's mean
// is the one it would have had) and written beside the policy at the end.
TEST_F(LearnerNodeInput, TheWeightAverageSurvivesACheckpointAndIsWrittenAtTheEnd) {
  const std::string dir = test_support::make_temp_dir("auvrl_average_");
  config_.her = false;
  config_.checkpoint_dir = dir + "/checkpoints";
  config_.average_every_updates = 10;
  config_.average_window_updates = 40;
  config_.average_policy_path = dir + "/policy_average.nn";
  node_.reset();
  node_ = std::make_unique<learner::LearnerNode>(config_, *transport_, log_);
  for (int i = 0; i < 4; ++i) send(channels::kExperience, batch(40));
  for (int i = 0; i < 50; ++i) node_->poll(0);
  ASSERT_GE(node_->updates(), 60);
  const learner::WeightAverage& average = node_->weight_average();
  EXPECT_EQ(average.copies(), 4u);
  EXPECT_EQ(average.last_updates(), node_->updates() / 10 * 10);
  const nn::Mlp mean = *average.mean(node_->algorithm().actor());
  EXPECT_NE(mean.params(), node_->algorithm().actor().params());  // a mean, not the last one
  ASSERT_NE(node_->checkpoint(), "");

  learner::LearnerNode resumed(config_, *transport_, log_);
  resumed.resume();
  EXPECT_EQ(resumed.weight_average().copies(), 4u);
  EXPECT_EQ(resumed.weight_average().first_updates(), average.first_updates());
  resumed.finish();
  nn::Mlp written = mean;
  nn::load_network_file(config_.average_policy_path, written);
  EXPECT_EQ(written.params(), mean.params());
  EXPECT_NE(log_.str().find("mean of 4 actors"), std::string::npos) << log_.str();
  std::filesystem::remove_all(dir);
}

}  // namespace
