// Supervision of the training system's processes: starts them, restarts what ends with a
// back-off, kills what hangs (silent past the heartbeat timeout) and gives up on a role that
// keeps failing. Time and processes come through interfaces so that tests drive it in process.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace auvrl::launcher {

/// A source of monotonic time in seconds.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Seconds since an arbitrary fixed origin; never goes back.
  virtual double now_s() const = 0;
};

/// std::chrono::steady_clock as a Clock.
class SteadyClock : public Clock {
 public:
  double now_s() const override;
};

/// One started process as the supervisor sees it.
class Process {
 public:
  virtual ~Process() = default;
  /// The process id (in the run's namespace).
  virtual int pid() const = 0;
  /// True while the process has not exited (reaps it if it has).
  virtual bool running() = 0;
  /// The wait status (see waitpid) once running() returned false.
  virtual int wait_status() = 0;
  /// Sends SIGKILL without waiting.
  virtual void kill() = 0;
  /// SIGTERM, up to grace_s to exit, then SIGKILL; waits for it.
  virtual void terminate(double grace_s) = 0;
};

/// Starts processes.
class ProcessStarter {
 public:
  virtual ~ProcessStarter() = default;
  /// Starts argv with its output appended to log_path; throws std::runtime_error on failure.
  virtual std::unique_ptr<Process> start(const std::vector<std::string>& argv,
                                         const std::string& log_path) = 0;
};

/// Starts real child processes (process::ChildProcess).
class ChildProcessStarter : public ProcessStarter {
 public:
  std::unique_ptr<Process> start(const std::vector<std::string>& argv,
                                 const std::string& log_path) override;
};

/// What a role is; decides what its clean exit means and how its signs of life are keyed.
enum class RoleKind {
  kLogger,   ///< restarted whenever it ends; heard by process id
  kSim,      ///< restarted whenever it ends; heard by process id
  kLearner,  ///< a clean exit ends the run (its schedule ended); heard by process id
  kActor,    ///< a clean exit is final (nothing left to learn); heard by actor id
};

/// One supervised process: what to start and where its output goes.
struct RoleSpec {
  std::string name;  ///< "logger", "sim0", "learner", "actor0", ...
  RoleKind kind = RoleKind::kSim;
  /// The command line for a start after `restarts` restarts.
  std::function<std::vector<std::string>(std::size_t restarts)> argv;
  std::string log_path;  ///< the process's output (appended over restarts)
  int actor_id = -1;     ///< an actor's id (its signs of life are its EPISODE reports)
  /// How the line begins that the role prints once it listens (its subscriptions made); empty:
  /// nothing to wait for.
  std::string listening_text;
  /// Its first start waits until every role with a listening_text has printed that line since its
  /// own start (or listen_wait_s has passed): LCM has no discovery, so what a role publishes before
  /// its readers subscribe is lost to them.
  bool starts_after_listeners = false;
};

/// The rules of supervision (RunSettings' fields of the same names).
struct SupervisorSettings {
  int max_restarts = 5;             ///< restarts allowed within restart_window_s
  double restart_window_s = 120.0;  ///< the window of max_restarts, s
  double heartbeat_timeout_s = 60;  ///< silence that counts as hung, s (0: not watched)
  double first_backoff_s = 0.5;     ///< delay before the first restart, doubled each time
  double max_backoff_s = 30.0;      ///< the longest delay before a restart, s
  double listen_gap_s = 1.0;        ///< a pause of the supervisor's own longer than this is
                                    ///< not counted as the processes' silence, s
  double listen_wait_s = 30.0;      ///< how long the roles that start after the listeners wait
                                    ///< for them before they start anyway, s
};

/// What a supervision pass concluded.
struct SupervisionOutcome {
  bool stop = false;        ///< the run must stop
  int exit_code = 0;        ///< its exit code when it stops
  std::string stop_reason;  ///< why (for "auvrl train: <reason>; stopping")
  /// False when resuming would meet the same fault (another vehicle, other sizes).
  bool resumable = true;
};

/// Starts, watches, restarts and stops the roles. Not thread-safe: the signs of life are
/// reported from the same thread that calls poll().
class Supervisor {
 public:
  /// Lines go to out, each preceded by a line break when tty (the status line is then open).
  Supervisor(SupervisorSettings settings, const Clock& clock, ProcessStarter& starter,
             std::ostream& out, bool tty);

  /// Adds a role (before start_all()).
  void add(RoleSpec spec);
  /// Called after each start with the role's name and the new process id.
  void on_start(std::function<void(const std::string& name, int pid)> hook) {
    on_start_ = std::move(hook);
  }
  /// Starts every role in the order added, except those that start after the listeners:
  /// poll() starts them once the listeners listen.
  void start_all();
  /// A sign of life from process pid (heartbeats, learner figures).
  void heard_from_pid(int pid) { alive_by_pid_[pid] = clock_.now_s(); }
  /// A sign of life from actor actor_id (its episode reports).
  void heard_from_actor(int actor_id) { alive_by_actor_[actor_id] = clock_.now_s(); }
  /// One supervision pass: restarts what is due, kills what hangs, notes what ended.
  SupervisionOutcome poll();
  /// Stops every role of a kind (SIGTERM, grace_s, SIGKILL), in the order added.
  void stop(RoleKind kind, double grace_s);
  /// The process id of a role's current process (-1 if none or unknown).
  int pid(const std::string& name) const;
  /// How often a role was restarted within the restart window so far.
  std::size_t restarts(const std::string& name) const;

 private:
  struct Role {
    RoleSpec spec;
    std::unique_ptr<Process> proc;
    std::deque<double> restarts_s;  ///< times of the restarts within the window
    double restart_due_s = 0;
    bool waiting_restart = false;
    bool finished = false;          ///< ended by itself, successfully, and should stay ended
    std::uintmax_t log_offset = 0;  ///< the size of its log at its latest start, bytes
    bool listening = false;         ///< printed its listening_text since its latest start
  };

  void start(Role& role);
  /// Starts the roles that wait for the listeners once every listener listens or
  /// listen_wait_s has passed since start_all() (saying which did not listen).
  void start_after_listeners();
  bool printed_since_start(const Role& role) const;
  bool anyone_heard();
  void watch_hang(Role& role, bool anyone_heard);
  SupervisionOutcome on_exit(Role& role);
  std::map<int, double>& alive_map(const Role& role);
  int alive_key(const Role& role) const;
  std::ostream& say();

  SupervisorSettings settings_;
  const Clock& clock_;
  ProcessStarter& starter_;
  std::ostream& out_;
  bool tty_;
  std::vector<std::unique_ptr<Role>> roles_;
  std::function<void(const std::string&, int)> on_start_;
  /// The time of the last sign of life by process id (simulators, logger, learner) and by
  /// actor id (episode reports), s.
  std::map<int, double> alive_by_pid_, alive_by_actor_;
  std::optional<double> last_poll_s_;
  double started_all_s_ = 0;
  bool listeners_waited_ = false;  ///< the roles that wait for the listeners were started
};

}  // namespace auvrl::launcher
