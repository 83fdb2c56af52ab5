// ActorNode's reproducible mode (common/round_schedule.hpp): rounds numbered by the learner,
// weights by round and index, random streams drawn from the seed and the round.
#include <random>

#include "agent/actor_node.hpp"
#include "common/channels.hpp"
#include "common/unrecoverable.hpp"

namespace auvrl::agent {

using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// A stream of its own for each of an actor's random processes in each round.
std::uint64_t stream_seed(std::uint64_t seed, std::int64_t round, std::uint32_t stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(round), static_cast<std::uint32_t>(round >> 32),
                    stream};
  std::uint32_t out[2];
  seq.generate(out, out + 2);
  return (static_cast<std::uint64_t>(out[0]) << 32) | out[1];
}

}  // namespace

void ActorNode::seed_round(std::int64_t round) {
  goal_rng_.seed(stream_seed(config_.seed, round, 1));
  start_rng_.seed(stream_seed(config_.seed, round, 2));
  conditions_rng_.seed(stream_seed(config_.seed, round, 3));
  demonstration_rng_.seed(stream_seed(config_.seed, round, 4));
  noise_.reseed(stream_seed(config_.seed, round, 5));
  episode_id_ = round;  // also seeds the simulator's own noise (EpisodeOptions::start)
}

void ActorNode::on_round_weights(const auvrl_lcm::policy_weights_t& msg) {
  if (msg.round < 0 || msg.round_index < 0) {
    throw UnrecoverableFault(
        "the learner publishes weights of the asynchronous mode; this actor is reproducible "
        "(every process of a run must be started with --reproducible, or none)");
  }
  learner_done_ = learner_done_ || msg.training_done;
  learner_round_ = msg.round;
  round_progress_ = Clock::now();
  const std::int64_t q = msg.round;
  // Round q + 1 acts with q's weights; q + 2 waits for q + 1's after sending q + 1.
  const bool acting = round_ == q + 1;
  // (Once it holds q + 1's weights, a message of q means the learner went back.)
  const bool waiting = round_ == q + 2 && sent_round_ == q + 1 && round_weights_.empty();
  if (!acting && !waiting) {
    // The learner awaits round q + 1: it already holds ours (it moved on) or went back to a
    // checkpoint. Whatever this actor was doing, round q + 1 it is.
    if (round_ != kNoRound) round_abandoned_ = true;
    round_ = q + 1;
    round_weights_.clear();
    applied_index_ = -1;
    if (sent_round_ != q + 1) sent_.clear();
  }
  if (round_ == q + 1) round_weights_[msg.round_index] = msg;
}

void ActorNode::pump_weights() {
  transport_.drain();
  while (!weights_queue_.empty()) {
    on_round_weights(weights_queue_.front());
    weights_queue_.pop_front();
  }
}

void ActorNode::request_round_weights(std::int64_t round, std::int32_t index) {
  if (seconds_since(last_request_) < config_.round_request_s) return;
  send_weights_request(round, index);
}

bool ActorNode::await_round_start() {
  const auto start = Clock::now();
  struct Count {
    Clock::time_point start;
    double& waited_s;
    ~Count() { waited_s += seconds_since(start); }
  } count{start, counters_.round_start_wait_s};
  for (;;) {
    pump_weights();
    if (learner_done_) return false;
    if (round_ != kNoRound && round_weights_.count(0) != 0) return true;
    if (round_ == kNoRound) {
      request_round_weights(-1, 0);  // the newest: it says which round the learner awaits
    } else {
      if (round_ == sent_round_ + 1 && !sent_.empty() &&
          seconds_since(round_progress_) > config_.round_resend_s) {
        // Not taken in time (a datagram lost, or the learner restarted): send it again.
        for (const auto& msg : sent_) transport::publish(transport_, channels::kExperience, msg);
        ++counters_.rounds_resent;
        round_progress_ = Clock::now();
      }
      request_round_weights(round_ - 1, 0);
    }
    transport_.handle(20);
  }
}

void ActorNode::use_round_weights(std::int64_t step) {
  const auto want = static_cast<std::int32_t>(step / config_.round_weights_every_steps);
  for (bool first = true;; first = false) {
    if (!first && waiting_since_ == Clock::time_point{}) waiting_since_ = Clock::now();
    pump_weights();
    if (round_abandoned_ || learner_done_) throw RoundAbandoned{};
    auto it = round_weights_.find(want);
    if (it == round_weights_.end() && !round_weights_.empty()) {
      const auto& newest = std::prev(round_weights_.end())->second;
      if (newest.round_final && newest.round_index < want) it = std::prev(round_weights_.end());
    }
    if (it != round_weights_.end()) {
      if (waiting_since_ != Clock::time_point{}) {
        counters_.round_step_wait_s += seconds_since(waiting_since_);
        waiting_since_ = {};
      }
      if (it->first == applied_index_) return;
      std::string error;
      switch (policy_.apply(it->second, error)) {
        case WeightsOutcome::kApplied:
          ++counters_.weights_applied;
          [[fallthrough]];
        case WeightsOutcome::kRefreshed:
          applied_index_ = it->first;
          return;
        case WeightsOutcome::kWrongSizes:
          throw UnrecoverableFault(error + " (vehicle " + describe(config_.vehicle) +
                                   "): the learner serves another vehicle or layout");
        case WeightsOutcome::kRejected:
          ++counters_.weights_rejected;
          log_ << "auv_actor " << config_.actor_id << ": weights of round " << round_ - 1
               << " index " << it->first << " rejected: " << error << "\n";
          round_weights_.erase(it);  // asked for again below
          break;
      }
    }
    request_round_weights(round_ - 1, want);
    transport_.handle(5);
  }
}

EpisodeSummary ActorNode::run_round() {
  for (;;) {
    if (!await_round_start()) return {};
    const std::int64_t round = round_;
    round_abandoned_ = false;
    applied_index_ = -1;
    seed_round(round);
    std::vector<Transition> transitions;
    Eigen::Vector3d goal;
    EpisodeSummary summary;
    try {
      use_round_weights(0);  // before the episode draws: it takes beta from these weights
      summary = play_episode(transitions, goal);
    } catch (const RoundAbandoned&) {
      ++counters_.rounds_abandoned;
      continue;
    }
    if (summary.end_reason == task::EndReason::kSimTimeout) {
      // The simulator did not answer: the round is played again once it does, the same.
      log_ << "auv_actor " << config_.actor_id << ": round " << round
           << " lost its simulator; playing it again\n";
      continue;
    }
    sent_ = discarded(summary) ? std::vector<auvrl_lcm::experience_batch_t>{}
                               : experience_messages(transitions, goal);
    if (sent_.empty()) {
      // No experience (a blow-up): one empty batch still closes the round.
      auvrl_lcm::experience_batch_t empty{};
      empty.utime = transport::now_utime();
      empty.actor_id = config_.actor_id;
      empty.state_dim = config_.task.state_dim();
      empty.action_dim = config_.task.num_thrusters;
      sent_.push_back(std::move(empty));
    }
    for (std::size_t i = 0; i < sent_.size(); ++i) {
      auvrl_lcm::experience_batch_t& msg = sent_[i];
      msg.round = round;
      msg.round_batch = static_cast<std::int32_t>(i);
      msg.round_batches = static_cast<std::int32_t>(sent_.size());
      msg.round_episodes = last_was_demonstration_ ? 0 : 1;
      msg.batch_seq = round * 1000 + static_cast<std::int64_t>(i);
      transport::publish(transport_, channels::kExperience, msg);
      counters_.transitions_sent += msg.num_transitions;
      ++counters_.batches_sent;
    }
    ++counters_.rounds_sent;
    sent_round_ = round;
    round_ = round + 1;
    round_weights_.clear();
    applied_index_ = -1;
    round_progress_ = Clock::now();
    if (!last_was_demonstration_) send_report(summary, goal);
    return summary;
  }
}

}  // namespace auvrl::agent
