#include "delay_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/random.hpp"

namespace auvrl::netdelay {

namespace {

/// The number at the start of text and the unit after it; throws on no number.
double number_with_unit(const std::string& text, std::string& unit) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    throw std::invalid_argument("not a number: '" + text + "'");
  }
  if (!std::isfinite(value) || value < 0.0) {
    throw std::invalid_argument("must be finite and >= 0: '" + text + "'");
  }
  unit = text.substr(used);
  return value;
}

}  // namespace

double parse_fraction(const std::string& text) {
  std::string unit;
  double value = number_with_unit(text, unit);
  if (unit == "%")
    value /= 100.0;
  else if (!unit.empty())
    throw std::invalid_argument("expected N% or 0..1: '" + text + "'");
  if (value > 1.0) throw std::invalid_argument("more than 100 %: '" + text + "'");
  return value;
}

double parse_ms(const std::string& text) {
  std::string unit;
  const double value = number_with_unit(text, unit);
  if (unit.empty() || unit == "ms") return value;
  if (unit == "us") return value / 1000.0;
  if (unit == "s") return value * 1000.0;
  throw std::invalid_argument("expected a time such as 5ms, 500us, 0.1s: '" + text + "'");
}

DelaySchedule::DelaySchedule(const DelayOptions& options) : options_(options), rng_(options.seed) {}

bool DelaySchedule::admit(std::uint32_t id, Clock::time_point now) {
  ++stats_.packets;
  if (options_.loss > 0.0 && draw::unit(rng_) < options_.loss) {
    ++stats_.dropped;
    return false;
  }
  double ms = options_.delay_ms;
  if (options_.jitter_ms > 0.0) ms += options_.jitter_ms * (2.0 * draw::unit(rng_) - 1.0);
  ms = std::max(ms, 0.0);
  stats_.delay_sum_ms += ms;
  const auto delay =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(ms));
  heap_.push(Held{now + delay, order_++, id});
  stats_.max_pending = std::max(stats_.max_pending, heap_.size());
  return true;
}

std::optional<Clock::time_point> DelaySchedule::next_due() const {
  if (heap_.empty()) return std::nullopt;
  return heap_.top().due;
}

std::size_t DelaySchedule::release_due(Clock::time_point now, std::vector<std::uint32_t>& out) {
  std::size_t n = 0;
  while (!heap_.empty() && heap_.top().due <= now) {
    out.push_back(heap_.top().id);
    heap_.pop();
    ++n;
  }
  stats_.released += n;
  return n;
}

std::size_t DelaySchedule::release_all(std::vector<std::uint32_t>& out) {
  return release_due(Clock::time_point::max(), out);
}

}  // namespace auvrl::netdelay
