// The replay buffer R of Algorithm 1: a preallocated ring of transitions, sampled uniformly into
// preallocated minibatch matrices.
#pragma once

#include <cstdint>
#include <istream>
#include <ostream>
#include <vector>

#include "common/nn/byte_io.hpp"
#include "common/nn/random.hpp"
#include "common/nn/types.hpp"

namespace auvrl::learner {

/// One transition (x_t, u_t, r_t, x_t+1) with what goal relabelling (HER) needs; the vectors are
/// views, copied by ReplayBuffer::add().
struct TransitionView {
  nn::ConstVectorRef state;       ///< x_t (state_dim)
  nn::ConstVectorRef action;      ///< u_t (action_dim), as applied, in [-1, 1]
  float reward;                   ///< r_t
  nn::ConstVectorRef next_state;  ///< x_t+1 (state_dim)
  /// True only where the episode really ends (goal reached, beta_max left, vehicle flipped): the
  /// value of x_t+1 is then not bootstrapped. An episode cut off by the step limit (700 steps)
  /// is NOT terminal: its last transition bootstraps like any other.
  bool terminal;
  Eigen::Vector3f achieved_position_ned_m;  ///< vehicle position after the transition, NED, m
  Eigen::Vector3f goal_ned_m;               ///< the episode's way-point, NED, m
  std::uint64_t episode_id;                 ///< unique per episode (across actors)
  std::uint32_t step_index;                 ///< t within the episode, from 0
  /// What the expert (the PID baseline) would have commanded in x_t: action_dim values in
  /// [-1, 1], or none (nullptr) when the actor sent no label.
  const float* expert_action = nullptr;
};

/// A minibatch, one column per transition, preallocated for up to max_batch transitions; only
/// the first `size` columns are valid.
struct Batch {
  Batch(int state_dim, int action_dim, int max_batch);

  int size = 0;
  nn::Matrix state;       ///< state_dim x max_batch
  nn::Matrix action;      ///< action_dim x max_batch
  nn::Matrix reward;      ///< 1 x max_batch
  nn::Matrix next_state;  ///< state_dim x max_batch
  nn::Matrix terminal;    ///< 1 x max_batch: 1 where terminal, else 0 (so targets use 1 - terminal)
  nn::Matrix expert_action;         ///< action_dim x max_batch: the expert's label (0 where none)
  nn::Matrix has_expert;            ///< 1 x max_batch: 1 where expert_action is a label, else 0
  std::vector<std::uint64_t> slot;  ///< buffer slot of each sampled transition

  int max_batch() const { return static_cast<int>(state.cols()); }
};

/// Preallocated ring buffer of transitions: when full, each add() overwrites the oldest. Sampling
/// is uniform with replacement over the stored transitions and draws from the caller's seeded
/// generator, so a run is reproducible. Not thread-safe.
class ReplayBuffer {
 public:
  /// Allocates all storage now (4 * (2 * state_dim + 2 * action_dim + 7) + 14 bytes per slot).
  ReplayBuffer(int state_dim, int action_dim, std::size_t capacity);

  /// Stores a transition (throws std::invalid_argument on wrong sizes). Allocates nothing.
  void add(const TransitionView& t);
  /// Fills the first n columns of `out` (n <= out.max_batch()) with transitions drawn uniformly
  /// with replacement. Throws std::logic_error if the buffer is empty. Allocates nothing.
  void sample(nn::Rng& rng, int n, Batch& out) const;
  /// Forgets every transition (keeps the storage).
  void clear();

  int state_dim() const { return state_dim_; }
  int action_dim() const { return action_dim_; }
  std::size_t capacity() const { return capacity_; }
  /// Transitions stored (at most capacity()).
  std::size_t size() const { return size_; }
  /// Transitions ever added, overwritten ones included.
  std::uint64_t total_added() const { return total_added_; }
  /// Slot that the next add() writes (the oldest transition's slot once the buffer is full).
  std::size_t next_slot() const { return next_; }

  /// Read access to a stored transition by slot (0 <= slot < size()), e.g. for relabelling.
  auto state(std::size_t slot) const { return states_.col(static_cast<Eigen::Index>(slot)); }
  auto action(std::size_t slot) const { return actions_.col(static_cast<Eigen::Index>(slot)); }
  float reward(std::size_t slot) const { return rewards_[slot]; }
  auto next_state(std::size_t slot) const {
    return next_states_.col(static_cast<Eigen::Index>(slot));
  }
  bool terminal(std::size_t slot) const { return terminal_[slot] != 0; }
  auto achieved_position_ned_m(std::size_t slot) const {
    return achieved_.col(static_cast<Eigen::Index>(slot));
  }
  auto goal_ned_m(std::size_t slot) const { return goals_.col(static_cast<Eigen::Index>(slot)); }
  std::uint64_t episode_id(std::size_t slot) const { return episode_ids_[slot]; }
  std::uint32_t step_index(std::size_t slot) const { return step_indices_[slot]; }
  bool has_expert(std::size_t slot) const { return has_expert_[slot] != 0; }
  auto expert_action(std::size_t slot) const {
    return expert_actions_.col(static_cast<Eigen::Index>(slot));
  }

  /// Writes the whole content as one self-checking record:
  ///   char[8] "AUVRLRB\0", u32 version (2), u32 state_dim, u32 action_dim, u64 capacity,
  ///   u64 size, u64 next slot, u64 total added, then for slots [0, size): states (f32),
  ///   actions (f32), rewards (f32), next states (f32), terminal flags (u8), achieved positions
  ///   (3 f32), goals (3 f32), episode ids (u64), step indices (u32), expert flags (u8),
  ///   expert actions (f32, action_dim each); then the CRC-32 of all of it. Little-endian.
  ///   Version 1 (no expert fields) is read as transitions without labels.
  void save(std::ostream& os) const;
  void save(nn::Writer& w) const;
  /// Replaces the content with a record written by save(). Dimensions and capacity must equal
  /// this buffer's. Throws std::runtime_error (what was expected, what was found) and leaves the
  /// buffer unchanged on any error: the record is read into new storage first.
  void restore(std::istream& is);
  void restore(nn::Reader& r);

 private:
  int state_dim_;
  int action_dim_;
  std::size_t capacity_;
  std::size_t size_ = 0;
  std::size_t next_ = 0;
  std::uint64_t total_added_ = 0;
  nn::Matrix states_;
  nn::Matrix actions_;
  std::vector<float> rewards_;
  nn::Matrix next_states_;
  std::vector<std::uint8_t> terminal_;
  Eigen::Matrix<float, 3, Eigen::Dynamic> achieved_;
  Eigen::Matrix<float, 3, Eigen::Dynamic> goals_;
  std::vector<std::uint64_t> episode_ids_;
  std::vector<std::uint32_t> step_indices_;
  std::vector<std::uint8_t> has_expert_;
  nn::Matrix expert_actions_;
};

}  // namespace auvrl::learner
