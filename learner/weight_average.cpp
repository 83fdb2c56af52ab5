#include "learner/weight_average.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace auvrl::learner {

namespace {

std::size_t window_copies(std::int64_t every_updates, std::int64_t window_updates) {
  if (every_updates < 1) {
    throw std::invalid_argument(
        fmt::format("average_every_updates {}: expected at least 1", every_updates));
  }
  if (window_updates < 0) {
    throw std::invalid_argument(
        fmt::format("average_window_updates {}: expected 0 (off) or more", window_updates));
  }
  const std::int64_t copies = window_updates / every_updates;
  if (copies > WeightAverage::kMaxCopies) {
    throw std::invalid_argument(
        fmt::format("average_window_updates {} / average_every_updates {} is {} copies; at most {}",
                    window_updates, every_updates, copies, WeightAverage::kMaxCopies));
  }
  return static_cast<std::size_t>(copies);
}

}  // namespace

WeightAverage::WeightAverage(std::int64_t every_updates, std::int64_t window_updates)
    : every_updates_(every_updates), capacity_(window_copies(every_updates, window_updates)) {}

void WeightAverage::observe(std::int64_t updates, const nn::Mlp& actor) {
  if (capacity_ == 0 || updates <= 0 || updates % every_updates_ != 0) return;
  if (!copies_.empty() && copies_.back().updates >= updates) return;  // already taken
  if (copies_.size() == capacity_) copies_.pop_front();
  copies_.push_back({updates, actor.params()});
}

std::optional<nn::Mlp> WeightAverage::mean(const nn::Mlp& like) const {
  if (copies_.empty()) return std::nullopt;
  if (copies_.front().params.size() != like.num_params()) {
    throw std::invalid_argument(fmt::format("weight average of {} parameters for a network of {}",
                                            copies_.front().params.size(), like.num_params()));
  }
  // Summed in double: a thousand floats' sum keeps the precision of each.
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(like.num_params());
  for (const Copy& c : copies_) sum += c.params.cast<double>();
  nn::Mlp mean = like;
  mean.params() = (sum / static_cast<double>(copies_.size())).cast<float>();
  return mean;
}

void WeightAverage::save(nn::Writer& w) const {
  w.u32(static_cast<std::uint32_t>(copies_.size()));
  w.u64(static_cast<std::uint64_t>(copies_.empty() ? 0 : copies_.front().params.size()));
  for (const Copy& c : copies_) {
    w.u64(static_cast<std::uint64_t>(c.updates));
    w.f32_array(c.params.data(), static_cast<std::size_t>(c.params.size()));
  }
}

void WeightAverage::restore(nn::Reader& r, std::int64_t num_params) {
  const std::uint32_t count = r.u32();
  const auto size = static_cast<std::int64_t>(r.u64());
  if (count > kMaxCopies) r.fail(fmt::format("weight average of {} copies", count));
  if (count > 0 && size != num_params) {
    r.fail(fmt::format("weight average of {} parameters, expected {}", size, num_params));
  }
  std::deque<Copy> copies;
  for (std::uint32_t i = 0; i < count; ++i) {
    Copy c{static_cast<std::int64_t>(r.u64()), nn::Vector(size)};
    if (!copies.empty() && c.updates <= copies.back().updates) {
      r.fail(fmt::format("weight average copies out of order ({} after {} updates)", c.updates,
                         copies.back().updates));
    }
    r.f32_array(c.params.data(), static_cast<std::size_t>(size));
    copies.push_back(std::move(c));
  }
  while (copies.size() > capacity_) copies.pop_front();
  copies_ = std::move(copies);
}

}  // namespace auvrl::learner
