// Starting and ending the project's processes (launcher, tests, benchmarks): a child is
// spawned with its output in a log file and is always ended by its owner: the destructor sends
// SIGTERM, waits, then SIGKILL. Only processes an object started are ever signalled.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace auvrl::process {

/// A child process started with posix_spawn, its output sent to a log file.
class ChildProcess {
 public:
  /// Starts argv[0] (a path) with the arguments; stdout and stderr go to log_path (or are
  /// inherited when empty). Throws std::runtime_error if it cannot be started.
  explicit ChildProcess(std::vector<std::string> argv, std::string log_path = "",
                        bool append_log = false);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// True while the process has not exited (reaps it if it has).
  bool running();
  /// Sends SIGTERM, waits up to grace, then SIGKILL. Returns the wait status (see waitpid).
  int terminate(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));
  /// Sends a signal (SIGKILL, SIGSTOP, ...) without waiting.
  void signal(int signo);
  /// Waits up to timeout for exit; returns the wait status or -1 on timeout.
  int wait_for_exit(std::chrono::milliseconds timeout);
  const std::string& log_path() const { return log_path_; }
  /// The log's contents so far (for assertion messages).
  std::string log() const;

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = 0;
  std::string log_path_;
};

}  // namespace auvrl::process
