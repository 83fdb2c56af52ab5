// A launcher Clock that moves only when the test (or a fuzz target's input) says so.
#pragma once

#include "launcher/supervisor.hpp"

namespace auvrl::launcher {

/// Time that moves only when the test or the fuzz input sets t_s.
class ManualClock : public Clock {
 public:
  double now_s() const override { return t_s; }
  double t_s = 0;  ///< now, s
};

}  // namespace auvrl::launcher
