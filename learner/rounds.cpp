#include "learner/rounds.hpp"

#include <algorithm>

#include "common/transport.hpp"

namespace auvrl::learner {

RoundCollector::RoundCollector(int actors, int max_batches)
    : actors_(static_cast<std::size_t>(actors)), max_batches_(std::max(1, max_batches)) {}

RoundCollector::Offer RoundCollector::offer(const auvrl_lcm::experience_batch_t& msg,
                                            std::int64_t awaited) {
  if (msg.actor_id < 0 || msg.actor_id >= static_cast<int>(actors_.size())) {
    return Offer::kMalformed;
  }
  if (msg.round != awaited) return Offer::kOtherRound;
  if (msg.round_batches < 1 || msg.round_batches > max_batches_ || msg.round_batch < 0 ||
      msg.round_batch >= msg.round_batches ||
      (msg.num_transitions == 0 && msg.round_batches != 1) || msg.round_episodes < 0) {
    return Offer::kMalformed;
  }
  ActorRound& a = actors_[static_cast<std::size_t>(msg.actor_id)];
  if (a.round != awaited) a = ActorRound{awaited, {}, 0};
  if (a.batches.empty()) {
    a.batches.resize(static_cast<std::size_t>(msg.round_batches));
  } else if (static_cast<int>(a.batches.size()) != msg.round_batches) {
    return Offer::kMalformed;
  }
  auto& slot = a.batches[static_cast<std::size_t>(msg.round_batch)];
  if (slot) return Offer::kDuplicate;
  slot = msg;
  ++a.held;
  return Offer::kStored;
}

bool RoundCollector::complete() const {
  for (const ActorRound& a : actors_) {
    if (a.batches.empty() || a.held != static_cast<int>(a.batches.size())) return false;
  }
  return true;
}

std::vector<auvrl_lcm::experience_batch_t> RoundCollector::take() {
  std::vector<auvrl_lcm::experience_batch_t> out;
  for (ActorRound& a : actors_) {
    for (auto& b : a.batches) out.push_back(std::move(*b));
    a = ActorRound{};
  }
  return out;
}

void RoundCollector::clear() {
  for (ActorRound& a : actors_) a = ActorRound{};
}

std::vector<int> RoundCollector::incomplete_actors() const {
  std::vector<int> out;
  for (std::size_t i = 0; i < actors_.size(); ++i) {
    const ActorRound& a = actors_[i];
    if (a.batches.empty() || a.held != static_cast<int>(a.batches.size())) {
      out.push_back(static_cast<int>(i));
    }
  }
  return out;
}

void RoundWeightsHistory::begin(std::int64_t round) {
  round_ = round;
  weights_.clear();
}

void RoundWeightsHistory::add(RoundWeights w) { weights_.push_back(std::move(w)); }

const RoundWeights* RoundWeightsHistory::find(std::int32_t index) const {
  for (const RoundWeights& w : weights_) {
    if (w.index == index) return &w;
  }
  return nullptr;
}

const RoundWeights* RoundWeightsHistory::newest() const {
  return weights_.empty() ? nullptr : &weights_.back();
}

void RoundWeightsHistory::save(nn::Writer& w) const {
  w.u64(static_cast<std::uint64_t>(round_));
  w.u32(static_cast<std::uint32_t>(weights_.size()));
  for (const RoundWeights& x : weights_) {
    w.u32(static_cast<std::uint32_t>(x.index));
    w.u8(x.final ? 1 : 0);
    w.u64(static_cast<std::uint64_t>(x.version));
    w.f64(x.beta_m);
    w.u64(static_cast<std::uint64_t>(x.episodes));
    w.u64(x.network.size());
    w.bytes(x.network.data(), x.network.size());
  }
}

void RoundWeightsHistory::restore(nn::Reader& r) {
  const auto round = static_cast<std::int64_t>(r.u64());
  const std::uint32_t count = r.u32();
  if (count > 1000000) r.fail("implausible count of round weights " + std::to_string(count));
  std::vector<RoundWeights> weights(count);
  for (RoundWeights& x : weights) {
    x.index = static_cast<std::int32_t>(r.u32());
    x.final = r.u8() != 0;
    x.version = static_cast<std::int64_t>(r.u64());
    x.beta_m = r.f64();
    x.episodes = static_cast<std::int64_t>(r.u64());
    const std::uint64_t size = r.u64();
    if (size > (std::uint64_t{1} << 31)) r.fail("implausible network size " + std::to_string(size));
    x.network.resize(size);
    r.bytes(x.network.data(), size);
  }
  round_ = round;
  weights_ = std::move(weights);
}

auvrl_lcm::policy_weights_t round_weights_message(const RoundWeights& w, std::int64_t round,
                                                  bool training_done) {
  auvrl_lcm::policy_weights_t msg;
  msg.utime = transport::now_utime();
  msg.version = w.version;
  msg.beta_m = w.beta_m;
  msg.episodes = w.episodes;
  msg.training_done = training_done;
  msg.updates_owed = 0.0;
  msg.round = round;
  msg.round_index = w.index;
  msg.round_final = w.final;
  msg.num_bytes = static_cast<std::int32_t>(w.network.size());
  msg.network.assign(w.network.begin(), w.network.end());
  return msg;
}

}  // namespace auvrl::learner
