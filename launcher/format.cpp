#include "launcher/format.hpp"

#include <fmt/format.h>

#include <cmath>

namespace auvrl::launcher {

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long total = std::lround(s);
  const long minutes = (total % 3600) / 60;
  const long seconds = total % 60;
  if (total >= 3600) return fmt::format("{}h{:02}m{:02}s", total / 3600, minutes, seconds);
  return fmt::format("{}m{:02}s", minutes, seconds);
}

}  // namespace auvrl::launcher
