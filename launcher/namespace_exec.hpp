// Running a launcher command inside a private network namespace (docs/architecture.md, network
// isolation): `auvrl train` and `auvrl run` prepare their run directory on the host, then run
// themselves again under scripts/netns.sh, which starts every process of the run in a fresh
// namespace and writes its PID to RUN/netns.pid for lcm-spy and the log tools.
#pragma once

#include <string>
#include <vector>

namespace auvrl::launcher {

/// True when this process runs inside the private network namespace a launcher made for it
/// (AUVRL_IN_NETNS=1 in the environment; inherited by every process it starts).
bool in_private_namespace();

/// The head of a command line that runs the rest of it in a new private network namespace:
/// SOURCE/scripts/netns.sh --pidfile RUN/netns.pid.
std::vector<std::string> netns_prefix(const std::string& source_dir, const std::string& run_dir);

/// Replaces this process with `args` (a command line headed by netns_prefix), AUVRL_IN_NETNS=1
/// set so that the command inside knows where it runs. Returns only by throwing
/// std::runtime_error when the command cannot be run.
[[noreturn]] void exec_in_namespace(std::vector<std::string> args);

}  // namespace auvrl::launcher
