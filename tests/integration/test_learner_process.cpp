// auv_learner as a real process in a private network namespace, fed by two fake actors: the
// actors get weights on request, see the version rise after each update, bad batches are
// dropped and counted; a checkpoint, kill -9 and --resume continue from the same update count
// with the same buffer content.
#include <gtest/gtest.h>
#include <signal.h>

#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/weights_request_t.hpp>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/nn/serialize.hpp"
#include "learner/checkpoint.hpp"
#include "learner/learner_node.hpp"
#include "synthetic_experience.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;

// The learner's sizes for its default vehicle (Nessie VII, 6 thrusters) and the paper's layout:
// 3 + 3 + 6 + 6 inputs.
constexpr int kStateDim = 18;
constexpr int kActionDim = 6;
constexpr int kBatch = 32;

/// A fake actor: its own LCM instance, sends experience and requests, watches the weights.
struct FakeActor {
  explicit FakeActor(int id) : actor_id(id), transport(transport::make_transport({})) {
    // Every message, not just the newest: the test checks that each version was broadcast.
    transport::subscribe<auvrl_lcm::policy_weights_t>(
        *transport, channels::kPolicyWeights,
        [this](const std::string&, const auvrl_lcm::policy_weights_t& w) {
          versions.push_back(w.version);
          last = w;
        });
  }

  void request_weights() {
    auvrl_lcm::weights_request_t req{};
    req.utime = transport::now_utime();
    req.actor_id = actor_id;
    req.have_version = -1;
    transport::publish(*transport, channels::kWeightsRequest, req);
  }

  /// A batch of n transitions whose values follow from (actor, seq): reproducible.
  auvrl_lcm::experience_batch_t make_batch(int n) {
    return test_support::synthetic_experience_batch(actor_id, ++seq, n, kStateDim, kActionDim);
  }

  void send(const auvrl_lcm::experience_batch_t& b) {
    transport::publish(*transport, channels::kExperience, b);
  }

  /// Handles traffic for up to ms; records every weights version seen.
  void pump(int ms) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (std::chrono::steady_clock::now() < end) transport->handle(10);
  }

  int actor_id;
  std::int64_t seq = 0;
  std::unique_ptr<transport::Transport> transport;
  std::vector<std::int64_t> versions;
  auvrl_lcm::policy_weights_t last{};
};

std::vector<std::string> learner_args(const std::string& dir, bool resume) {
  std::vector<std::string> args = {test_support::bin_path("auv_learner"),
                                   "--algo",
                                   "td3",
                                   "--hidden",
                                   "32-32",
                                   "--batch-size",
                                   std::to_string(kBatch),
                                   "--replay-capacity",
                                   "5000",
                                   "--broadcast-every-updates",
                                   "1",
                                   "--broadcast-min-interval-s",
                                   "0",
                                   "--max-actors",
                                   "4",
                                   "--checkpoint-dir",
                                   dir + "/checkpoints",
                                   "--checkpoint-period-s",
                                   "0.3",
                                   "--seed",
                                   "5"};
  if (resume) args.push_back("--resume");
  return args;
}

learner::LearnerNodeConfig in_process_config(const std::string& dir) {
  learner::LearnerNodeConfig c;
  c.ddpg.algo = learner::Algo::kTd3;
  c.ddpg.state_dim = kStateDim;
  c.ddpg.action_dim = kActionDim;
  c.ddpg.actor_hidden = c.ddpg.critic_hidden = {32, 32};
  c.ddpg.batch_size = kBatch;
  c.ddpg.replay_capacity = 5000;
  c.ddpg.seed = 5;
  c.checkpoint_dir = dir + "/checkpoints";
  c.max_actors = 4;
  return c;
}

/// Hostile batches, which the learner must drop and count, never apply: one without
/// transitions, one with a NaN reward, one with an action no tanh gives and one from an actor
/// it does not know. (Sound experience of other dimensions is not hostile but another
/// vehicle's: it stops the learner, tests/integration/test_vehicle_mismatch.cpp.)
void send_hostile_batches(FakeActor& actor) {
  actor.send(actor.make_batch(0));
  auto nan = actor.make_batch(5);
  nan.rewards[2] = std::nanf("");
  actor.send(nan);
  auto wild = actor.make_batch(5);
  wild.actions[0][0] = 7.0f;
  actor.send(wild);
  auto stranger = actor.make_batch(5);
  stranger.actor_id = 99;
  actor.send(stranger);
}

/// The newest checkpoint in dir/checkpoints, resumed in this process, holds `updates` and
/// exactly the transitions `sent`, in order.
void expect_checkpoint_holds(const std::string& dir,
                             const std::vector<auvrl_lcm::experience_batch_t>& sent,
                             std::int64_t updates) {
  std::ostringstream log;
  auto t = transport::make_in_process_transport();
  learner::LearnerNode restored(in_process_config(dir), *t, log);
  restored.resume();
  ASSERT_EQ(restored.updates(), updates);
  const auto& replay = restored.replay();
  std::size_t slot = 0;
  for (const auto& batch : sent) {
    for (int i = 0; i < batch.num_transitions; ++i, ++slot) {
      ASSERT_LT(slot, replay.size());
      for (int k = 0; k < kStateDim; ++k) {
        ASSERT_EQ(replay.state(slot)[k], batch.states[i][k]) << "slot " << slot;
        ASSERT_EQ(replay.next_state(slot)[k], batch.next_states[i][k]);
      }
      ASSERT_EQ(replay.reward(slot), batch.rewards[i]);
      ASSERT_EQ(replay.terminal(slot), batch.terminal[i] != 0);
    }
  }
  EXPECT_EQ(replay.size(), slot) << "the buffer holds more than was sent";
}

TEST(LearnerProcess, WeightsRiseCheckpointKillResume) {
  const std::string dir = test_support::make_temp_dir("auvrl_learner_process_");
  auto learner = std::make_unique<ChildProcess>(learner_args(dir, false), dir + "/learner1.log");
  FakeActor a(0), b(1);
  transport::Latest<auvrl_lcm::learner_stats_t> stats(*a.transport, channels::kLearnerStats);

  // A starting actor asks and gets the current policy (version 0) at once.
  for (int i = 0; i < 50 && a.versions.empty(); ++i) {
    a.request_weights();
    a.pump(100);
  }
  ASSERT_FALSE(a.versions.empty()) << learner->log();
  EXPECT_EQ(a.versions.front(), 0);
  nn::Mlp policy = nn::network_from_bytes(
      reinterpret_cast<const std::uint8_t*>(a.last.network.data()), a.last.network.size(), 1);
  EXPECT_EQ(policy.spec().input_dim, kStateDim);
  EXPECT_EQ(policy.spec().output_dim, kActionDim);

  // Experience from both actors; both see the version rise, one by one update.
  std::vector<auvrl_lcm::experience_batch_t> sent;
  for (int round = 0; round < 6; ++round) {
    sent.push_back(a.make_batch(20));
    a.send(sent.back());
    sent.push_back(b.make_batch(20));
    b.send(sent.back());
    a.pump(100);
    b.pump(100);
  }
  a.pump(500);
  b.pump(500);
  for (FakeActor* actor : {&a, &b}) {
    ASSERT_GE(actor->versions.size(), 10u) << learner->log();
    EXPECT_TRUE(std::is_sorted(actor->versions.begin(), actor->versions.end()));
    EXPECT_GT(actor->versions.back(), 0);
  }
  // One update per transition from the moment the buffer holds more than a batch (|R| > m).
  EXPECT_EQ(a.versions.back(), 240 - kBatch);
  // Every version from the first update to the last was broadcast (after each update).
  std::vector<std::int64_t> seen = a.versions;
  seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
  EXPECT_EQ(seen.size(), static_cast<std::size_t>(240 - kBatch + 1))
      << "weights were not broadcast after each update";

  send_hostile_batches(a);
  std::optional<auvrl_lcm::learner_stats_t> s;
  for (int i = 0; i < 60; ++i) {
    a.pump(50);
    if (auto got = stats.take(); got && got->dropped_dims >= 1 && got->dropped_non_finite >= 2 &&
                                 got->dropped_unknown_actor >= 1 && got->checkpoints_written >= 2) {
      s = got;
      break;
    }
  }
  ASSERT_TRUE(s.has_value()) << learner->log();
  EXPECT_EQ(s->updates, 240 - kBatch);
  EXPECT_EQ(s->transitions_received, 240);
  EXPECT_EQ(s->buffer_size, 240);

  // Let a checkpoint with the final state land, then kill -9.
  a.pump(800);
  learner->signal(SIGKILL);
  learner->wait_for_exit(std::chrono::seconds(5));
  const auto files = learner::list_checkpoints(dir + "/checkpoints");
  ASSERT_FALSE(files.empty());
  EXPECT_EQ(files.front().updates, 240 - kBatch);

  expect_checkpoint_holds(dir, sent, 240 - kBatch);

  // --resume: the same update count, the same buffer, and the weights of that checkpoint.
  learner = std::make_unique<ChildProcess>(learner_args(dir, true), dir + "/learner2.log");
  FakeActor c(2);
  for (int i = 0; i < 50 && c.versions.empty(); ++i) {
    c.request_weights();
    c.pump(100);
  }
  ASSERT_FALSE(c.versions.empty()) << learner->log();
  EXPECT_EQ(c.versions.front(), 240 - kBatch);
  EXPECT_EQ(c.last.network, a.last.network) << "resumed weights differ from the last broadcast";
  c.send(c.make_batch(10));
  for (int i = 0; i < 40 && c.versions.back() < 250 - kBatch; ++i) c.pump(50);
  EXPECT_EQ(c.versions.back(), 250 - kBatch) << learner->log();
  const int status = learner->terminate();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << learner->log();
  EXPECT_NE(learner->log().find("resumed from"), std::string::npos);
}

TEST(LearnerProcess, DamagedNewestCheckpointFallsBackToThePreviousOne) {
  const std::string dir = test_support::make_temp_dir("auvrl_learner_ckpt_");
  std::ostringstream log;
  auto t = transport::make_in_process_transport();
  auto config = in_process_config(dir);
  config.keep_checkpoints = 3;
  {
    learner::LearnerNode node(config, *t, log);
    ASSERT_NE(node.checkpoint(), "");
    auvrl_lcm::experience_batch_t batch = FakeActor(0).make_batch(50);
    transport::publish(*t, channels::kExperience, batch);
    for (int i = 0; i < 10; ++i) node.poll(10);
    ASSERT_EQ(node.updates(), 50 - kBatch);
    ASSERT_NE(node.checkpoint(), "");
  }
  auto files = learner::list_checkpoints(dir + "/checkpoints");
  ASSERT_EQ(files.size(), 2u);
  // Truncate the newest.
  std::filesystem::resize_file(files.front().path, 1000);
  learner::LearnerNode node(config, *t, log);
  node.resume();
  EXPECT_EQ(node.updates(), 0);
  EXPECT_NE(log.str().find("is unusable"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find(files.front().path), std::string::npos);
  // Both damaged: a clear error.
  std::filesystem::resize_file(files.back().path, 10);
  learner::LearnerNode node2(config, *t, log);
  EXPECT_THROW(node2.resume(), std::runtime_error);
}

}  // namespace
