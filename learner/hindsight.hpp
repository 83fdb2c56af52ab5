// Hindsight experience replay (Andrychowicz et al. 2017), "future" strategy: part of every
// minibatch gets, in place of the episode's way-point, a position the vehicle actually
// reached later in the same episode; states, reward and termination are recomputed with the
// task's own functions, so relabelled transitions follow exactly the reward being learned.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "common/nn/random.hpp"
#include "common/task/task.hpp"
#include "learner/replay_buffer.hpp"

namespace auvrl::learner {

/// Keeps track of where each episode's transitions sit in the replay buffer and relabels
/// sampled minibatches.
class HindsightRelabeler {
 public:
  /// k future goals per real one: a fraction k / (k + 1) of each minibatch is relabelled
  /// (k = 4 in the HER paper).
  HindsightRelabeler(task::TaskConfig task, int k);

  /// Call after every ReplayBuffer::add(), with the slot it wrote (next_slot() before the add)
  /// and what was there before (episode id, or none when the buffer was not yet full).
  void on_add(const ReplayBuffer& replay, std::size_t slot, bool overwrote,
              std::uint64_t overwritten_episode);

  /// Relabels a sampled minibatch in place: for each transition chosen (probability
  /// k / (k + 1)) whose episode has a later step still in the buffer, the goal becomes the
  /// position reached at a uniformly drawn later step.
  void relabel(const ReplayBuffer& replay, double beta_m, nn::Rng& rng, Batch& batch) const;

  /// Rebuilds the episode index from the buffer's content (after a checkpoint restore).
  void rebuild(const ReplayBuffer& replay);

  /// Relabelled transitions so far.
  std::int64_t relabelled() const { return relabelled_; }
  const task::TaskConfig& task() const { return task_; }

 private:
  task::TaskConfig task_;
  double relabel_probability_;
  /// Slots of each episode's transitions, by step index (missing steps: not yet arrived).
  std::unordered_map<std::uint64_t, std::vector<std::int64_t>> episodes_;
  mutable std::int64_t relabelled_ = 0;
};

}  // namespace auvrl::learner
