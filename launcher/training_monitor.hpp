// What `auvrl train` learns of a run from its participants' traffic: episode outcomes, the
// learner's figures, the simulators' rates, and which actor keeps discarding its episodes.
// Only the run's own participants count: a message from a process the launcher did not start
// (another system on the same bus, a process it restarted since) or from an actor id outside
// the run is left out of every figure, so that the figures are the run's and the state kept
// stays bounded by the run's size, whatever arrives. The launcher's TrainingSession feeds it;
// tests and fuzz/fuzz_training_monitor.cpp drive it directly.
#pragma once

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "launcher/supervisor.hpp"

namespace auvrl::launcher {

/// Whether the monitor took a message, or why not.
enum class Heard {
  kTaken,      ///< from a participant; counted
  kFormer,     ///< from a process of the run that has since been replaced (a late message)
  kForeign,    ///< from a process id or actor id that is not the run's
  kMalformed,  ///< a participant's message with a figure that is not a finite number
};

/// An actor whose every episode for a while was discarded (blow-up or simulator timeout).
struct DiscardingRun {
  int actor_id = -1;
  double for_s = 0;           ///< since its first discarded episode in a row, s
  std::int64_t episodes = 0;  ///< discarded episodes in a row
  int last_end_reason = 0;    ///< episode_report_t.end_reason of the last one
};

/// The figures of a training run, from its participants' messages.
class TrainingMonitor {
 public:
  /// Episode outcomes the success rate is taken over.
  static constexpr std::size_t kRecentEpisodes = 100;
  /// Former processes remembered (a long run's restarts); beyond it the lowest ids are
  /// forgotten (their late messages then count as foreign).
  static constexpr std::size_t kMaxFormerPids = 1024;

  /// A run of `actors` actors (ids 0..actors-1, simulators "sim0".."sim<actors-1>"); times
  /// come from clock.
  TrainingMonitor(int actors, const Clock& clock);

  /// The launcher started role `name` ("logger", "learner", "sim<i>", "actor<i>") as process
  /// pid; the role's previous process, if any, becomes a former participant.
  void started(const std::string& name, int pid);

  Heard take_episode(const auvrl_lcm::episode_report_t& report);
  Heard take_learner_stats(const auvrl_lcm::learner_stats_t& stats);
  Heard take_sim_heartbeat(const auvrl_lcm::sim_heartbeat_t& heartbeat);
  Heard take_logger_heartbeat(const auvrl_lcm::logger_heartbeat_t& heartbeat);

  /// Share of the last 100 episodes that reached the goal, 0..1 (0 before any).
  double success_rate() const;
  /// Control steps per second of the run's current simulators together (their last
  /// heartbeats; a restarted simulator's former process no longer counts).
  double env_steps_per_s() const;
  /// The newest goal radius an actor reported, m.
  double beta_m() const { return beta_m_; }
  /// Episode reports taken by this monitor.
  std::int64_t episodes_seen() const { return episodes_seen_; }
  /// The learner's newest figures.
  const std::optional<auvrl_lcm::learner_stats_t>& learner_stats() const { return stats_; }
  /// Of those: the episodes it has taken in and its updates per second (0 before any).
  std::int64_t learner_episodes() const { return stats_ ? stats_->episodes : 0; }
  double updates_per_s() const { return stats_ ? stats_->updates_per_s : 0.0; }

  /// The first actor whose episodes have all been discarded for at least discard_fault_s
  /// while its simulator was heard within the last 3 s (a hung simulator is the supervisor's).
  std::optional<DiscardingRun> discarding_actor(double discard_fault_s) const;

  /// Messages not taken, by kind (kForeign and kMalformed; late ones of former processes are
  /// expected and not counted).
  std::int64_t foreign() const { return foreign_; }
  std::int64_t malformed() const { return malformed_; }
  /// Entries the monitor keeps per participant (for tests of its bound).
  std::size_t entries() const;

 private:
  /// The role whose current process is pid, among those named role_prefix...
  std::optional<std::string> role_of(int pid, const std::string& role_prefix) const;
  /// What a message from pid, not a current participant's, is: kFormer or kForeign (counted).
  Heard not_taken(int pid);
  void note_discarded(const auvrl_lcm::episode_report_t& report);

  /// The last heartbeat of a simulator process.
  struct SimHeard {
    double steps_per_s = 0;
    double heard_s = 0;
  };
  struct Discarding {
    double since_s = 0;
    std::int64_t episodes = 0;
    int last_reason = 0;
  };

  int actors_;
  const Clock& clock_;
  std::map<std::string, int> pid_by_role_;  ///< the current process of each role started
  std::set<int> former_pids_;               ///< processes replaced by a restart (bounded)
  std::map<std::string, SimHeard> sims_;    ///< by role name, of its current process
  std::map<int, Discarding> discarding_;    ///< by actor id
  std::deque<bool> recent_success_;
  std::int64_t episodes_seen_ = 0;
  double beta_m_ = 0;
  std::optional<auvrl_lcm::learner_stats_t> stats_;
  std::int64_t foreign_ = 0;
  std::int64_t malformed_ = 0;
};

}  // namespace auvrl::launcher
