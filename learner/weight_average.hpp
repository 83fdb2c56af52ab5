// The uniform mean of the actor's weights over its last updates (stochastic weight averaging,
// Izmailov et al. 2018, "Averaging Weights Leads to Wider Optima and Better Generalization"):
// TD3's actor wanders between updates; the mean of where it went lies nearer the middle.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

#include "common/nn/byte_io.hpp"
#include "common/nn/mlp.hpp"

namespace auvrl::learner {

/// A window of copies of the actor's parameters, one taken every `every_updates` updates, the
/// oldest dropped once they span more than `window_updates`; mean() is their uniform mean.
/// window_updates 0 takes none (off).
class WeightAverage {
 public:
  /// Throws std::invalid_argument for every_updates < 1, window_updates < 0, or a window of more
  /// than kMaxCopies copies.
  WeightAverage(std::int64_t every_updates, std::int64_t window_updates);

  static constexpr std::int64_t kMaxCopies = 1000;

  bool enabled() const { return capacity_ > 0; }
  /// Takes a copy of `actor` when `updates` (the count after an update) is a multiple of
  /// every_updates.
  void observe(std::int64_t updates, const nn::Mlp& actor);
  /// Copies held (at most window_updates / every_updates).
  std::size_t copies() const { return copies_.size(); }
  /// The update count of the oldest and newest copy held (0 when none).
  std::int64_t first_updates() const { return copies_.empty() ? 0 : copies_.front().updates; }
  std::int64_t last_updates() const { return copies_.empty() ? 0 : copies_.back().updates; }
  /// A network like `like` (its spec and max_batch) with the copies' mean parameters; nothing
  /// before the first copy. Throws std::invalid_argument when `like` has another size.
  std::optional<nn::Mlp> mean(const nn::Mlp& like) const;

  /// Writes the copies (a checkpoint keeps them: a resumed run's mean loses nothing).
  void save(nn::Writer& w) const;
  /// Reads what save() wrote for networks of `num_params` parameters; fails (Reader::fail) on
  /// other sizes, unordered update counts or more copies than this window holds (the oldest
  /// beyond it are dropped: a smaller window after a resume is allowed).
  void restore(nn::Reader& r, std::int64_t num_params);

 private:
  struct Copy {
    std::int64_t updates = 0;
    nn::Vector params;
  };
  std::int64_t every_updates_;
  std::size_t capacity_;
  std::deque<Copy> copies_;
};

}  // namespace auvrl::learner
