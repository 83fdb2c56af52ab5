#include "launcher/training_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/task/task.hpp"

namespace auvrl::launcher {

namespace {

/// A simulator heard within this is answering, s.
constexpr double kSimAnswersWithin_s = 3.0;

}  // namespace

TrainingMonitor::TrainingMonitor(int actors, const Clock& clock)
    : actors_(std::max(actors, 0)), clock_(clock) {}

void TrainingMonitor::started(const std::string& name, int pid) {
  const auto [it, first] = pid_by_role_.try_emplace(name, pid);
  if (!first && it->second != pid) {
    if (former_pids_.size() >= kMaxFormerPids) former_pids_.erase(former_pids_.begin());
    former_pids_.insert(it->second);
    it->second = pid;
  }
  former_pids_.erase(pid);  // a reused id is the new process's
  sims_.erase(name);        // the new process is counted from its own first heartbeat on
}

std::optional<std::string> TrainingMonitor::role_of(int pid, const std::string& role_prefix) const {
  for (const auto& [name, role_pid] : pid_by_role_) {
    if (role_pid == pid && name.compare(0, role_prefix.size(), role_prefix) == 0) return name;
  }
  return std::nullopt;
}

Heard TrainingMonitor::not_taken(int pid) {
  if (former_pids_.count(pid) != 0) return Heard::kFormer;
  ++foreign_;
  return Heard::kForeign;
}

Heard TrainingMonitor::take_episode(const auvrl_lcm::episode_report_t& report) {
  if (report.actor_id < 0 || report.actor_id >= actors_) {
    ++foreign_;
    return Heard::kForeign;
  }
  if (!std::isfinite(report.beta_m)) {
    ++malformed_;
    return Heard::kMalformed;
  }
  ++episodes_seen_;
  beta_m_ = report.beta_m;
  recent_success_.push_back(report.success);
  if (recent_success_.size() > kRecentEpisodes) recent_success_.pop_front();
  note_discarded(report);
  return Heard::kTaken;
}

Heard TrainingMonitor::take_learner_stats(const auvrl_lcm::learner_stats_t& stats) {
  if (!role_of(stats.pid, "learner")) return not_taken(stats.pid);
  if (!std::isfinite(stats.updates_per_s) || stats.updates_per_s < 0) {
    ++malformed_;
    return Heard::kMalformed;
  }
  stats_ = stats;
  return Heard::kTaken;
}

Heard TrainingMonitor::take_sim_heartbeat(const auvrl_lcm::sim_heartbeat_t& heartbeat) {
  const std::optional<std::string> role = role_of(heartbeat.pid, "sim");
  if (!role) return not_taken(heartbeat.pid);
  if (!std::isfinite(heartbeat.steps_per_s) || heartbeat.steps_per_s < 0) {
    ++malformed_;
    return Heard::kMalformed;
  }
  sims_[*role] = {heartbeat.steps_per_s, clock_.now_s()};
  return Heard::kTaken;
}

Heard TrainingMonitor::take_logger_heartbeat(const auvrl_lcm::logger_heartbeat_t& heartbeat) {
  return role_of(heartbeat.pid, "logger") ? Heard::kTaken : not_taken(heartbeat.pid);
}

double TrainingMonitor::success_rate() const {
  if (recent_success_.empty()) return 0.0;
  const auto successes = std::count(recent_success_.begin(), recent_success_.end(), true);
  return static_cast<double>(successes) / static_cast<double>(recent_success_.size());
}

double TrainingMonitor::env_steps_per_s() const {
  double sum = 0;
  for (const auto& entry : sims_) sum += entry.second.steps_per_s;
  return sum;
}

void TrainingMonitor::note_discarded(const auvrl_lcm::episode_report_t& report) {
  const auto reason = static_cast<task::EndReason>(report.end_reason);
  if (reason != task::EndReason::kBlowUp && reason != task::EndReason::kSimTimeout) {
    discarding_.erase(report.actor_id);
    return;
  }
  auto [entry, first] = discarding_.try_emplace(report.actor_id);
  if (first) entry->second.since_s = clock_.now_s();
  ++entry->second.episodes;
  entry->second.last_reason = report.end_reason;
}

std::optional<DiscardingRun> TrainingMonitor::discarding_actor(double discard_fault_s) const {
  const double now = clock_.now_s();
  for (const auto& [actor, run] : discarding_) {
    if (now - run.since_s < discard_fault_s) continue;
    const auto sim = sims_.find("sim" + std::to_string(actor));
    if (sim == sims_.end() || now - sim->second.heard_s > kSimAnswersWithin_s) continue;
    return DiscardingRun{actor, now - run.since_s, run.episodes, run.last_reason};
  }
  return std::nullopt;
}

std::size_t TrainingMonitor::entries() const {
  return pid_by_role_.size() + former_pids_.size() + sims_.size() + discarding_.size() +
         recent_success_.size();
}

}  // namespace auvrl::launcher
