// The learner's side of the reproducible mode (common/round_schedule.hpp): collecting each
// round of experience from every actor, complete and in a fixed order whatever the order of
// arrival, and the weights the learner published for the current round.
#pragma once

#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <cstdint>
#include <optional>
#include <vector>

#include "common/nn/byte_io.hpp"

namespace auvrl::learner {

/// Collects the batches of one round (the one awaited) from actors 0 .. actors - 1.
class RoundCollector {
 public:
  /// max_batches bounds what a round may claim (round_batches): an episode of max_steps
  /// transitions comes in at most that many batches.
  RoundCollector(int actors, int max_batches);

  /// What offer() did with a batch.
  enum class Offer {
    kStored,      ///< kept for the awaited round
    kDuplicate,   ///< that batch of that actor's round is already held (a resend)
    kOtherRound,  ///< of a round already taken, or not yet awaited: dropped
    /// round_batch or round_batches out of range (more than max_batches), or not as the actor
    /// said before
    kMalformed,
  };
  /// Offers a batch (already checked for sizes and values) of msg.round; `awaited` is the round
  /// the learner takes next.
  Offer offer(const auvrl_lcm::experience_batch_t& msg, std::int64_t awaited);
  /// Whether every actor's every batch of the awaited round is held.
  bool complete() const;
  /// The round's batches, actor by actor and batch by batch, and forgets them.
  std::vector<auvrl_lcm::experience_batch_t> take();
  /// Forgets everything held (the learner went back to a checkpoint).
  void clear();
  /// Actors whose round is not yet complete (for the learner's log when it waits long).
  std::vector<int> incomplete_actors() const;

 private:
  struct ActorRound {
    std::int64_t round = -1;
    std::vector<std::optional<auvrl_lcm::experience_batch_t>> batches;
    int held = 0;
  };
  std::vector<ActorRound> actors_;
  int max_batches_;
};

/// One of the weights the learner published for its current round.
struct RoundWeights {
  std::int32_t index = 0;
  bool final = false;
  std::int64_t version = 0;  ///< update count
  double beta_m = 0.0;
  std::int64_t episodes = 0;
  std::vector<std::uint8_t> network;  ///< the actor network, serialised
};

/// The weights of the current round, by index, so that an actor that missed one (or started
/// late, or after the learner went back to a checkpoint) can ask for it again.
class RoundWeightsHistory {
 public:
  /// Starts round `round` (forgets the previous one's weights).
  void begin(std::int64_t round);
  void add(RoundWeights w);
  std::int64_t round() const { return round_; }
  /// The weights of index k of the current round, if published.
  const RoundWeights* find(std::int32_t index) const;
  /// The newest published (nullptr when none).
  const RoundWeights* newest() const;
  const std::vector<RoundWeights>& all() const { return weights_; }

  void save(nn::Writer& w) const;
  /// Reads what save() wrote; throws (via r.fail) on implausible values.
  void restore(nn::Reader& r);

 private:
  std::int64_t round_ = -1;
  std::vector<RoundWeights> weights_;
};

/// A policy_weights_t for `w` of round `round` (utime now).
auvrl_lcm::policy_weights_t round_weights_message(const RoundWeights& w, std::int64_t round,
                                                  bool training_done);

}  // namespace auvrl::learner
