// The reproducible mode's learner side, in process: the round schedule's counting, the
// collection of rounds (complete, in actor order whatever the arrival order, resends and other
// rounds dropped), the weights history's checkpoint record, and a LearnerNode that takes a round
// from two actors arriving in either order to the same networks, publishing each index once.
#include <gtest/gtest.h>

#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/weights_request_t.hpp>
#include <sstream>

#include "common/channels.hpp"
#include "common/nn/byte_io.hpp"
#include "common/round_schedule.hpp"
#include "common/unrecoverable.hpp"
#include "learner/learner_node.hpp"
#include "learner/rounds.hpp"
#include "synthetic_experience.hpp"

namespace {

using namespace auvrl;
using learner::RoundCollector;

constexpr int kStateDim = 5;
constexpr int kActionDim = 2;

/// Batch `index` of `count` of an actor's round, n transitions.
auvrl_lcm::experience_batch_t round_batch(int actor, std::int64_t round, int index, int count,
                                          int n = 6) {
  auto b = test_support::synthetic_experience_batch(actor, round * 100 + index, n, kStateDim,
                                                    kActionDim);
  b.round = round;
  b.round_batch = index;
  b.round_batches = count;
  b.round_episodes = 1;
  return b;
}

TEST(RoundSchedule, CountsStepsAndUpdates) {
  RoundSchedule s{100, 2, 1.0};
  EXPECT_EQ(s.index_for_step(0), 0);
  EXPECT_EQ(s.index_for_step(99), 0);
  EXPECT_EQ(s.index_for_step(100), 1);
  EXPECT_EQ(s.updates_for_index(0), 0);
  EXPECT_EQ(s.updates_for_index(3), 600);  // two actors' 300 steps at one update each
  RoundSchedule half{3, 1, 0.5};
  EXPECT_EQ(half.updates_for_index(1), 2);  // 1.5 rounded up
  EXPECT_EQ(half.updates_for_index(2), 3);
  EXPECT_THROW((RoundSchedule{0, 1, 1.0}.validate()), std::invalid_argument);
  EXPECT_THROW((RoundSchedule{1, 0, 1.0}.validate()), std::invalid_argument);
}

TEST(RoundCollector, CompleteOnlyWithEveryBatchOfEveryActorAndInActorOrder) {
  RoundCollector c(2, 10);
  EXPECT_EQ(c.offer(round_batch(1, 3, 1, 2), 3), RoundCollector::Offer::kStored);
  EXPECT_EQ(c.offer(round_batch(0, 3, 0, 1), 3), RoundCollector::Offer::kStored);
  EXPECT_FALSE(c.complete());
  EXPECT_EQ(c.incomplete_actors(), std::vector<int>{1});
  EXPECT_EQ(c.offer(round_batch(1, 3, 1, 2), 3), RoundCollector::Offer::kDuplicate);
  EXPECT_EQ(c.offer(round_batch(1, 2, 0, 2), 3), RoundCollector::Offer::kOtherRound);
  EXPECT_EQ(c.offer(round_batch(1, 4, 0, 2), 3), RoundCollector::Offer::kOtherRound);
  EXPECT_EQ(c.offer(round_batch(1, 3, 0, 3), 3), RoundCollector::Offer::kMalformed);  // count
  EXPECT_EQ(c.offer(round_batch(1, 3, 2, 2), 3), RoundCollector::Offer::kMalformed);  // index
  EXPECT_EQ(c.offer(round_batch(2, 3, 0, 1), 3), RoundCollector::Offer::kMalformed);  // actor
  EXPECT_EQ(c.offer(round_batch(1, 3, 0, 2), 3), RoundCollector::Offer::kStored);
  ASSERT_TRUE(c.complete());
  const auto batches = c.take();
  ASSERT_EQ(batches.size(), 3u);
  EXPECT_EQ(batches[0].actor_id, 0);
  EXPECT_EQ(batches[1].actor_id, 1);
  EXPECT_EQ(batches[1].round_batch, 0);
  EXPECT_EQ(batches[2].round_batch, 1);
  EXPECT_FALSE(c.complete());
}

TEST(RoundCollector, AnEmptyBatchClosesARoundOnlyAsItsOnlyBatch) {
  RoundCollector c(1, 10);
  EXPECT_EQ(c.offer(round_batch(0, 1, 0, 2, 0), 1), RoundCollector::Offer::kMalformed);
  EXPECT_EQ(c.offer(round_batch(0, 1, 0, 1, 0), 1), RoundCollector::Offer::kStored);
  EXPECT_TRUE(c.complete());
}

TEST(RoundCollector, ARoundClaimingMoreBatchesThanAnEpisodeHasIsRefused) {
  // (A fuzz finding: round_batches of 2^30 made the collector reserve for them.)
  RoundCollector c(1, 700);
  EXPECT_EQ(c.offer(round_batch(0, 1, 0, 1 << 30), 1), RoundCollector::Offer::kMalformed);
  EXPECT_EQ(c.offer(round_batch(0, 1, 0, 701), 1), RoundCollector::Offer::kMalformed);
  EXPECT_EQ(c.offer(round_batch(0, 1, 0, 700), 1), RoundCollector::Offer::kStored);
}

TEST(RoundWeightsHistory, CheckpointRecordRoundTrips) {
  learner::RoundWeightsHistory h;
  h.begin(7);
  h.add({0, false, 120, 0.5, 40, {1, 2, 3}});
  h.add({1, true, 180, 0.5, 40, {4, 5}});
  std::vector<std::uint8_t> bytes;
  nn::VectorSink sink(bytes);
  nn::Writer w(sink);
  h.save(w);
  nn::SpanSource source(bytes);
  nn::Reader r(source, "history");
  learner::RoundWeightsHistory back;
  back.restore(r);
  EXPECT_EQ(back.round(), 7);
  ASSERT_EQ(back.all().size(), 2u);
  EXPECT_EQ(back.find(1)->version, 180);
  EXPECT_TRUE(back.find(1)->final);
  EXPECT_EQ(back.find(0)->network, (std::vector<std::uint8_t>{1, 2, 3}));
  EXPECT_EQ(back.newest()->index, 1);
  EXPECT_EQ(back.find(2), nullptr);
}

/// A reproducible learner node on its own in-process bus, with every weights message kept.
struct ReproducibleLearner {
  explicit ReproducibleLearner(int actors) : transport(transport::make_in_process_transport()) {
    config.ddpg.state_dim = kStateDim;
    config.ddpg.action_dim = kActionDim;
    config.ddpg.actor_hidden = config.ddpg.critic_hidden = {8, 8};
    config.ddpg.batch_size = 4;
    config.ddpg.replay_capacity = 1000;
    config.max_actors = actors;
    config.reproducible = true;
    config.round_weights_every_steps = 2;  // with 2 actors: an index every 4 updates
    node = std::make_unique<learner::LearnerNode>(config, *transport, log);
    transport::subscribe<auvrl_lcm::policy_weights_t>(
        *transport, channels::kPolicyWeights,
        [this](const std::string&, const auvrl_lcm::policy_weights_t& m) { weights.push_back(m); });
  }
  void send(const auvrl_lcm::experience_batch_t& b) {
    transport::publish(*transport, channels::kExperience, b);
  }
  /// Polls until nothing is owed.
  void settle() {
    for (int i = 0; i < 100; ++i) {
      node->poll(0);
      transport->drain();
    }
  }

  learner::LearnerNodeConfig config;
  std::unique_ptr<transport::Transport> transport;
  std::ostringstream log;
  std::unique_ptr<learner::LearnerNode> node;
  std::vector<auvrl_lcm::policy_weights_t> weights;
};

TEST(ReproducibleLearnerNode, TakesARoundInActorOrderWhateverTheArrivalOrder) {
  ReproducibleLearner a(2), b(2);
  a.settle();
  b.settle();
  ASSERT_FALSE(a.weights.empty());
  EXPECT_EQ(a.weights.back().round, 0);  // the initial networks
  EXPECT_TRUE(a.weights.back().round_final);
  const std::size_t initial = a.weights.size();
  // Round 1: actor 0 sends two batches, actor 1 one; b hears them in another order.
  a.send(round_batch(0, 1, 0, 2, 5));
  a.send(round_batch(0, 1, 1, 2, 5));
  a.send(round_batch(1, 1, 0, 1, 4));
  b.send(round_batch(1, 1, 0, 1, 4));
  b.send(round_batch(0, 1, 1, 2, 5));
  b.send(round_batch(0, 1, 1, 2, 5));  // a resend
  b.send(round_batch(0, 1, 0, 2, 5));
  a.settle();
  b.settle();
  // 14 transitions past a warm-up of batch_size 4: 10 updates, an index every 4 of them.
  EXPECT_EQ(a.node->updates(), 10);
  EXPECT_EQ(b.node->counters().round_duplicates, 1);
  EXPECT_EQ(a.node->episodes(), 2);
  EXPECT_EQ(a.node->weights_message().network, b.node->weights_message().network);
  std::vector<std::pair<int, bool>> indices;
  for (std::size_t i = initial; i < a.weights.size(); ++i) {
    EXPECT_EQ(a.weights[i].round, 1);
    indices.emplace_back(a.weights[i].round_index, a.weights[i].round_final);
  }
  EXPECT_EQ(indices,
            (std::vector<std::pair<int, bool>>{{0, false}, {1, false}, {2, false}, {3, true}}));
  // Asked again, index 1 comes again; an index not yet due does not.
  auvrl_lcm::weights_request_t req{};
  req.actor_id = 0;
  req.want_round = 1;
  req.want_index = 1;
  transport::publish(*a.transport, channels::kWeightsRequest, req);
  a.settle();
  EXPECT_EQ(a.weights.back().round_index, 1);
  EXPECT_EQ(a.weights.back().version, 4);
}

TEST(ReproducibleLearnerNode, AsynchronousExperienceStopsIt) {
  ReproducibleLearner a(1);
  auto b = round_batch(0, 1, 0, 1);
  b.round = 0;  // the asynchronous mode's
  a.send(b);
  a.transport->drain();
  EXPECT_THROW(a.node->poll(0), UnrecoverableFault);
}

}  // namespace
