// Delay and loss decisions for auv_netdelay (user-space netem over NFQUEUE): pure logic, no
// sockets, so it can be tested with a fake clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <queue>
#include <random>
#include <string>
#include <vector>

namespace auvrl::netdelay {

using Clock = std::chrono::steady_clock;

/// How each packet is impaired: held for a delay drawn uniformly from
/// [delay_ms - jitter_ms, delay_ms + jitter_ms] (clamped at 0, as netem's default jitter), or
/// dropped with probability loss (0..1). Draws come from a generator seeded with seed.
struct DelayOptions {
  double delay_ms = 0.0;
  double jitter_ms = 0.0;
  double loss = 0.0;
  std::uint64_t seed = 1;
};

/// Parses "10%", "0.1", "5ms", "5" style values: a percentage into 0..1, a time into ms.
/// Throws std::invalid_argument on anything else (negative, trailing garbage).
double parse_fraction(const std::string& text);
double parse_ms(const std::string& text);

/// Counters of what the schedule decided.
struct DelayStats {
  std::uint64_t packets = 0;   ///< packets offered
  std::uint64_t dropped = 0;   ///< verdict drop
  std::uint64_t released = 0;  ///< accepted after their delay
  double delay_sum_ms = 0.0;   ///< sum of the delays drawn for packets not dropped
  std::size_t max_pending = 0;
};

/// Min-heap of packets waiting for their due time. admit() decides drop or delay for a packet
/// arriving now; next_due() is when the earliest held packet must be released; release_due()
/// hands out every packet whose time has come, earliest first. With jitter, packets may leave
/// in another order than they came (as with netem's jitter).
class DelaySchedule {
 public:
  explicit DelaySchedule(const DelayOptions& options);

  /// False: drop the packet now. True: it is held until its due time.
  bool admit(std::uint32_t id, Clock::time_point now);
  std::optional<Clock::time_point> next_due() const;
  /// Appends the ids due at or before now to out, earliest first; returns how many.
  std::size_t release_due(Clock::time_point now, std::vector<std::uint32_t>& out);
  /// Appends every held id (shutdown: accept all, lose nothing), earliest first.
  std::size_t release_all(std::vector<std::uint32_t>& out);
  std::size_t pending() const { return heap_.size(); }
  const DelayStats& stats() const { return stats_; }

 private:
  struct Held {
    Clock::time_point due;
    std::uint64_t order;  // arrival order: ties leave first-in first-out
    std::uint32_t id;
    bool operator>(const Held& o) const { return due != o.due ? due > o.due : order > o.order; }
  };
  DelayOptions options_;
  std::mt19937_64 rng_;
  std::priority_queue<Held, std::vector<Held>, std::greater<Held>> heap_;
  std::uint64_t order_ = 0;
  DelayStats stats_;
};

}  // namespace auvrl::netdelay
