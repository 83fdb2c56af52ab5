// Text the launcher shows: durations as 1h02m03s.
#pragma once

#include <string>

namespace auvrl::launcher {

/// A duration as "12s", "3m04s" or "1h02m03s" (rounded to the second); "?" when negative or not
/// finite (an unknown time left).
std::string format_duration(double s);

}  // namespace auvrl::launcher
