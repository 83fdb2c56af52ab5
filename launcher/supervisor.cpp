#include "launcher/supervisor.hpp"

#include <fmt/format.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>

#include "common/process.hpp"
#include "common/unrecoverable.hpp"
#include "launcher/format.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

double SteadyClock::now_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

namespace {

/// process::ChildProcess as a Process.
class ChildProcessHandle : public Process {
 public:
  ChildProcessHandle(const std::vector<std::string>& argv, const std::string& log_path)
      : child_(argv, log_path, true) {}
  int pid() const override { return child_.pid(); }
  bool running() override { return child_.running(); }
  int wait_status() override { return child_.wait_for_exit(std::chrono::milliseconds(0)); }
  void kill() override { child_.signal(SIGKILL); }
  void terminate(double grace_s) override {
    child_.terminate(std::chrono::milliseconds(std::lround(grace_s * 1000)));
  }

 private:
  process::ChildProcess child_;
};

std::string describe_status(int status) {
  return WIFSIGNALED(status) ? fmt::format("signal {}", WTERMSIG(status))
                             : fmt::format("exit {}", WEXITSTATUS(status));
}

}  // namespace

std::unique_ptr<Process> ChildProcessStarter::start(const std::vector<std::string>& argv,
                                                    const std::string& log_path) {
  return std::make_unique<ChildProcessHandle>(argv, log_path);
}

Supervisor::Supervisor(SupervisorSettings settings, const Clock& clock, ProcessStarter& starter,
                       std::ostream& out, bool tty)
    : settings_(settings), clock_(clock), starter_(starter), out_(out), tty_(tty) {}

void Supervisor::add(RoleSpec spec) {
  auto role = std::make_unique<Role>();
  role->spec = std::move(spec);
  roles_.push_back(std::move(role));
}

namespace {

/// The last non-empty line of a process's output (what an UnrecoverableFault printed).
std::string last_line(const std::string& log_path) {
  std::ifstream in(log_path);
  std::string line, last = "(no output; see " + log_path + ")";
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

}  // namespace

void Supervisor::start_all() {
  started_all_s_ = clock_.now_s();
  for (auto& role : roles_) {
    if (!role->spec.starts_after_listeners) start(*role);
  }
  start_after_listeners();
}

bool Supervisor::printed_since_start(const Role& role) const {
  std::ifstream in(role.spec.log_path);
  in.seekg(static_cast<std::streamoff>(role.log_offset));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(role.spec.listening_text, 0) == 0) return true;
  }
  return false;
}

void Supervisor::start_after_listeners() {
  if (listeners_waited_) return;
  std::vector<const Role*> silent;
  for (auto& role : roles_) {
    if (role->spec.listening_text.empty() || !role->proc) continue;
    // One that ended since it said so listens no longer: its restart must say so again.
    if (!role->waiting_restart && !role->listening) role->listening = printed_since_start(*role);
    if (role->waiting_restart || !role->listening) silent.push_back(role.get());
  }
  if (!silent.empty() && clock_.now_s() - started_all_s_ < settings_.listen_wait_s) return;
  listeners_waited_ = true;
  std::vector<Role*> waiting;
  for (auto& role : roles_) {
    if (role->spec.starts_after_listeners && !role->proc) waiting.push_back(role.get());
  }
  if (waiting.empty()) return;
  for (const Role* role : silent) {
    say() << fmt::format(
        "{} not listening after {:g} s (no line beginning \"{}\" in {}); "
        "starting {}{} anyway\n",
        role->spec.name, settings_.listen_wait_s, role->spec.listening_text, role->spec.log_path,
        waiting.front()->spec.name,
        waiting.size() > 1 ? fmt::format(" and {} more", waiting.size() - 1) : "");
  }
  for (Role* role : waiting) start(*role);
}

std::ostream& Supervisor::say() {
  out_ << (tty_ ? "\n" : "") << "auvrl train: ";
  return out_;
}

std::map<int, double>& Supervisor::alive_map(const Role& role) {
  return role.spec.kind == RoleKind::kActor ? alive_by_actor_ : alive_by_pid_;
}

int Supervisor::alive_key(const Role& role) const {
  return role.spec.kind == RoleKind::kActor ? role.spec.actor_id : role.proc->pid();
}

void Supervisor::start(Role& role) {
  // The replaced process's signs of life no longer count (nor does its entry stay).
  if (role.proc) alive_by_pid_.erase(role.proc->pid());
  std::error_code no_log;
  const std::uintmax_t log_size = fs::file_size(role.spec.log_path, no_log);
  role.log_offset = no_log ? 0 : log_size;
  role.listening = false;
  role.proc = starter_.start(role.spec.argv(role.restarts_s.size()), role.spec.log_path);
  // The new process is watched from its own first sign of life on.
  alive_by_pid_.erase(role.proc->pid());
  if (role.spec.kind == RoleKind::kActor) alive_by_actor_.erase(role.spec.actor_id);
  if (on_start_) on_start_(role.spec.name, role.proc->pid());
}

bool Supervisor::anyone_heard() {
  // The supervisor's own pauses (a quick evaluation, starved of CPU, a blocked write) are not
  // the processes' silence: a gap between two passes beyond listen_gap_s moves every sign of
  // life forward by it.
  const double now = clock_.now_s();
  if (last_poll_s_ && now - *last_poll_s_ > settings_.listen_gap_s) {
    const double gap = now - *last_poll_s_;
    for (auto* alive : {&alive_by_pid_, &alive_by_actor_}) {
      for (auto& entry : *alive) entry.second = std::min(now, entry.second + gap);
    }
  }
  last_poll_s_ = now;
  // When nobody at all was heard for half the timeout, the machine (or the bus) is the likelier
  // culprit than every process at once.
  for (const auto* alive : {&alive_by_pid_, &alive_by_actor_}) {
    for (const auto& entry : *alive) {
      if (now - entry.second < settings_.heartbeat_timeout_s / 2) return true;
    }
  }
  return false;
}

void Supervisor::watch_hang(Role& role, bool anyone_heard) {
  auto& alive = alive_map(role);
  const auto seen = alive.find(alive_key(role));
  if (settings_.heartbeat_timeout_s <= 0 || !anyone_heard || seen == alive.end()) return;
  const double silent_s = clock_.now_s() - seen->second;
  if (silent_s <= settings_.heartbeat_timeout_s) return;
  // SIGKILL; the restart follows once it is reaped.
  say() << role.spec.name << " silent for " << std::lround(silent_s)
        << " s (no heartbeat; hung?); killing it\n";
  alive.erase(seen);
  role.proc->kill();
}

SupervisionOutcome Supervisor::on_exit(Role& role) {
  const int status = role.proc->wait_status();
  const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kExitUnrecoverable) {
    // Another vehicle, other sizes, nothing but discarded episodes: a restart would meet the
    // same fault. The process's last line says what it met.
    role.finished = true;
    return {true, 1, fmt::format("{} stopped: {}", role.spec.name, last_line(role.spec.log_path)),
            false};
  }
  if (clean && role.spec.kind == RoleKind::kLearner) {
    role.finished = true;
    return {true, 0, "the learner's schedule ended"};
  }
  if (clean && role.spec.kind == RoleKind::kActor) {
    // An actor ends by itself only when the learner's schedule has ended or its own episode
    // budget is spent: restarting it would only run episodes nobody learns from.
    role.finished = true;
    return {};
  }
  const double now = clock_.now_s();
  auto& times = role.restarts_s;
  while (!times.empty() && now - times.front() > settings_.restart_window_s) times.pop_front();
  if (static_cast<int>(times.size()) >= settings_.max_restarts) {
    return {true, 1,
            fmt::format("{} failed {} times within {} (see {})", role.spec.name, times.size() + 1,
                        format_duration(settings_.restart_window_s), role.spec.log_path)};
  }
  const double backoff_s =
      std::min(settings_.max_backoff_s,
               settings_.first_backoff_s * std::pow(2.0, static_cast<double>(times.size())));
  say() << fmt::format("{} ended ({}); restarting in {:g} s\n", role.spec.name,
                       describe_status(status), backoff_s);
  times.push_back(now);
  role.waiting_restart = true;
  role.restart_due_s = now + backoff_s;
  return {};
}

SupervisionOutcome Supervisor::poll() {
  const bool heard = anyone_heard();
  SupervisionOutcome outcome;
  for (auto& role : roles_) {
    if (role->finished || (!role->proc && !role->waiting_restart)) continue;
    if (role->waiting_restart) {
      if (clock_.now_s() >= role->restart_due_s) {
        role->waiting_restart = false;
        say() << "restarting " << role->spec.name << "\n";
        start(*role);
      }
      continue;
    }
    if (role->proc->running()) {
      watch_hang(*role, heard);
      continue;
    }
    const SupervisionOutcome ended = on_exit(*role);
    if (ended.exit_code != 0) return ended;  // giving up: the rest waits for the stop
    if (ended.stop) outcome = ended;         // the learner is done: the others still count
  }
  // After the exits above: a listener that has just ended does not count as listening.
  if (!outcome.stop) start_after_listeners();
  return outcome;
}

void Supervisor::stop(RoleKind kind, double grace_s) {
  for (auto& role : roles_) {
    if (role->spec.kind == kind && role->proc) role->proc->terminate(grace_s);
  }
}

int Supervisor::pid(const std::string& name) const {
  for (const auto& role : roles_) {
    if (role->spec.name == name && role->proc) return role->proc->pid();
  }
  return -1;
}

std::size_t Supervisor::restarts(const std::string& name) const {
  for (const auto& role : roles_) {
    if (role->spec.name == name) return role->restarts_s.size();
  }
  return 0;
}

}  // namespace auvrl::launcher
