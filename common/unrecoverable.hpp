// A fault no restart can mend: a process that meets another vehicle than it expects, experience
// or weights of other dimensions, an actor that discards every episode. The process exits with
// kExitUnrecoverable after one line naming both sides; the launcher ends the run with that line
// instead of restarting the process.
#pragma once

#include <stdexcept>
#include <string>

namespace auvrl {

/// Exit status of a process stopped by an UnrecoverableFault (sysexits.h' EX_CONFIG).
inline constexpr int kExitUnrecoverable = 78;

/// Thrown where such a fault is found; main() prints what() as its last line and exits with
/// kExitUnrecoverable.
class UnrecoverableFault : public std::runtime_error {
 public:
  explicit UnrecoverableFault(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace auvrl
