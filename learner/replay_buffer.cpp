#include "learner/replay_buffer.hpp"

#include <stdexcept>
#include <string>

namespace auvrl::learner {
namespace {

constexpr char kMagic[8] = {'A', 'U', 'V', 'R', 'L', 'R', 'B', '\0'};
constexpr std::uint32_t kVersion = 2;
constexpr std::uint32_t kVersionWithoutExpert = 1;

// Prefetches every cache line of column i of m.
void prefetch_column(const nn::Matrix& m, Eigen::Index i) {
  const char* begin = reinterpret_cast<const char*>(m.data() + i * m.rows());
  const char* end = begin + m.rows() * static_cast<Eigen::Index>(sizeof(float));
  for (const char* p = begin; p < end; p += 64) __builtin_prefetch(p);
  __builtin_prefetch(end - 1);
}

}  // namespace

Batch::Batch(int state_dim, int action_dim, int max_batch)
    : state(nn::Matrix::Zero(state_dim, max_batch)),
      action(nn::Matrix::Zero(action_dim, max_batch)),
      reward(nn::Matrix::Zero(1, max_batch)),
      next_state(nn::Matrix::Zero(state_dim, max_batch)),
      terminal(nn::Matrix::Zero(1, max_batch)),
      expert_action(nn::Matrix::Zero(action_dim, max_batch)),
      has_expert(nn::Matrix::Zero(1, max_batch)),
      slot(static_cast<std::size_t>(max_batch), 0) {}

ReplayBuffer::ReplayBuffer(int state_dim, int action_dim, std::size_t capacity)
    : state_dim_(state_dim), action_dim_(action_dim), capacity_(capacity) {
  if (state_dim < 1 || action_dim < 1 || capacity < 1) {
    throw std::invalid_argument("ReplayBuffer: state_dim, action_dim and capacity must be >= 1");
  }
  const auto cap = static_cast<Eigen::Index>(capacity);
  // Left uninitialised: only slots [0, size) are ever read or saved.
  states_.resize(state_dim, cap);
  actions_.resize(action_dim, cap);
  rewards_.resize(capacity);
  next_states_.resize(state_dim, cap);
  terminal_.resize(capacity);
  achieved_.resize(3, cap);
  goals_.resize(3, cap);
  episode_ids_.resize(capacity);
  step_indices_.resize(capacity);
  has_expert_.resize(capacity);
  expert_actions_.resize(action_dim, cap);
}

void ReplayBuffer::add(const TransitionView& t) {
  if (t.state.size() != state_dim_ || t.next_state.size() != state_dim_ ||
      t.action.size() != action_dim_) {
    throw std::invalid_argument(
        "ReplayBuffer::add: state/action/next state of sizes " + std::to_string(t.state.size()) +
        "/" + std::to_string(t.action.size()) + "/" + std::to_string(t.next_state.size()) +
        ", expected " + std::to_string(state_dim_) + "/" + std::to_string(action_dim_) + "/" +
        std::to_string(state_dim_));
  }
  const auto i = static_cast<Eigen::Index>(next_);
  states_.col(i) = t.state;
  actions_.col(i) = t.action;
  rewards_[next_] = t.reward;
  next_states_.col(i) = t.next_state;
  terminal_[next_] = t.terminal ? 1 : 0;
  achieved_.col(i) = t.achieved_position_ned_m;
  goals_.col(i) = t.goal_ned_m;
  episode_ids_[next_] = t.episode_id;
  step_indices_[next_] = t.step_index;
  has_expert_[next_] = t.expert_action ? 1 : 0;
  if (t.expert_action) {
    expert_actions_.col(i) = Eigen::Map<const nn::Vector>(t.expert_action, action_dim_);
  } else {
    expert_actions_.col(i).setZero();
  }
  next_ = next_ + 1 == capacity_ ? 0 : next_ + 1;
  if (size_ < capacity_) ++size_;
  ++total_added_;
}

void ReplayBuffer::sample(nn::Rng& rng, int n, Batch& out) const {
  if (size_ == 0) throw std::logic_error("ReplayBuffer::sample: the buffer is empty");
  if (n < 1 || n > out.max_batch()) {
    throw std::invalid_argument("ReplayBuffer::sample: n = " + std::to_string(n) +
                                ", expected 1.." + std::to_string(out.max_batch()));
  }
  out.size = n;
  // Draw every slot first and ask for its memory: a large buffer lives in DRAM, and fetching
  // the transitions one after the other would wait for each miss in turn.
  for (int k = 0; k < n; ++k) {
    const std::uint64_t slot = nn::uniform_index(rng, size_);
    out.slot[static_cast<std::size_t>(k)] = slot;
    const auto i = static_cast<Eigen::Index>(slot);
    prefetch_column(states_, i);
    prefetch_column(actions_, i);
    prefetch_column(next_states_, i);
    __builtin_prefetch(&rewards_[slot]);
    __builtin_prefetch(&terminal_[slot]);
    __builtin_prefetch(&has_expert_[slot]);
    prefetch_column(expert_actions_, i);
  }
  for (int k = 0; k < n; ++k) {
    const std::uint64_t slot = out.slot[static_cast<std::size_t>(k)];
    const auto i = static_cast<Eigen::Index>(slot);
    out.state.col(k) = states_.col(i);
    out.action.col(k) = actions_.col(i);
    out.reward(0, k) = rewards_[slot];
    out.next_state.col(k) = next_states_.col(i);
    out.terminal(0, k) = terminal_[slot] ? 1.0f : 0.0f;
    out.has_expert(0, k) = has_expert_[slot] ? 1.0f : 0.0f;
    out.expert_action.col(k) = expert_actions_.col(i);
  }
}

void ReplayBuffer::clear() {
  size_ = 0;
  next_ = 0;
  total_added_ = 0;
}

void ReplayBuffer::save(std::ostream& os) const {
  nn::OStreamSink sink(os);
  nn::Writer w(sink);
  save(w);
}

void ReplayBuffer::save(nn::Writer& w) const {
  w.bytes(kMagic, sizeof kMagic);
  w.u32(kVersion);
  w.u32(static_cast<std::uint32_t>(state_dim_));
  w.u32(static_cast<std::uint32_t>(action_dim_));
  w.u64(capacity_);
  w.u64(size_);
  w.u64(next_);
  w.u64(total_added_);
  const std::size_t n = size_;
  w.f32_array(states_.data(), n * static_cast<std::size_t>(state_dim_));
  w.f32_array(actions_.data(), n * static_cast<std::size_t>(action_dim_));
  w.f32_array(rewards_.data(), n);
  w.f32_array(next_states_.data(), n * static_cast<std::size_t>(state_dim_));
  w.bytes(terminal_.data(), n);
  w.f32_array(achieved_.data(), 3 * n);
  w.f32_array(goals_.data(), 3 * n);
  w.u64_array(episode_ids_.data(), n);
  w.u32_array(step_indices_.data(), n);
  w.bytes(has_expert_.data(), n);
  w.f32_array(expert_actions_.data(), n * static_cast<std::size_t>(action_dim_));
  w.checksum();
}

void ReplayBuffer::restore(std::istream& is) {
  nn::IStreamSource source(is);
  nn::Reader r(source, "replay buffer");
  restore(r);
}

void ReplayBuffer::restore(nn::Reader& r) {
  r.expect_magic(kMagic);
  const std::uint32_t version = r.u32();
  if (version != kVersion && version != kVersionWithoutExpert) {
    r.fail("unsupported format version " + std::to_string(version) + ", expected " +
           std::to_string(kVersionWithoutExpert) + " or " + std::to_string(kVersion));
  }
  const std::uint32_t state_dim = r.u32();
  const std::uint32_t action_dim = r.u32();
  const std::uint64_t capacity = r.u64();
  if (state_dim != static_cast<std::uint32_t>(state_dim_) ||
      action_dim != static_cast<std::uint32_t>(action_dim_) || capacity != capacity_) {
    r.fail("state_dim " + std::to_string(state_dim) + ", action_dim " + std::to_string(action_dim) +
           ", capacity " + std::to_string(capacity) + "; expected state_dim " +
           std::to_string(state_dim_) + ", action_dim " + std::to_string(action_dim_) +
           ", capacity " + std::to_string(capacity_));
  }
  const std::uint64_t size = r.u64();
  const std::uint64_t next = r.u64();
  const std::uint64_t total = r.u64();
  if (size > capacity || next >= capacity || (size < capacity && next != size) || total < size) {
    r.fail("inconsistent size " + std::to_string(size) + ", next slot " + std::to_string(next) +
           ", total added " + std::to_string(total) + " for capacity " + std::to_string(capacity));
  }
  ReplayBuffer fresh(state_dim_, action_dim_, capacity_);
  const std::size_t n = size;
  r.f32_array(fresh.states_.data(), n * state_dim);
  r.f32_array(fresh.actions_.data(), n * action_dim);
  r.f32_array(fresh.rewards_.data(), n);
  r.f32_array(fresh.next_states_.data(), n * state_dim);
  r.bytes(fresh.terminal_.data(), n);
  r.f32_array(fresh.achieved_.data(), 3 * n);
  r.f32_array(fresh.goals_.data(), 3 * n);
  r.u64_array(fresh.episode_ids_.data(), n);
  r.u32_array(fresh.step_indices_.data(), n);
  if (version == kVersion) {
    r.bytes(fresh.has_expert_.data(), n);
    r.f32_array(fresh.expert_actions_.data(), n * action_dim);
  } else {
    // The flags are already 0 (a fresh vector); the labels' storage is not initialised.
    fresh.expert_actions_.leftCols(static_cast<Eigen::Index>(n)).setZero();
  }
  r.verify_checksum();
  fresh.size_ = n;
  fresh.next_ = next;
  fresh.total_added_ = total;
  *this = std::move(fresh);
}

}  // namespace auvrl::learner
