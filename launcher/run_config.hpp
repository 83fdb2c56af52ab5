// The run configuration as the launcher reads it: the `run:` section (its own), and what it
// needs of the others (vehicle, task, learner.max_episodes, max_updates and
// average_window_updates, transport, finetune).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/config/table.hpp"
#include "common/task/task.hpp"
#include "common/transport_options.hpp"
#include "tuning/policy_finetune.hpp"

namespace auvrl::launcher {

/// The `run:` section of a run configuration.
struct RunSettings {
  int actors = 0;            ///< 0: one per CPU
  std::uint64_t seed = 1;    ///< actor i uses seed * 1000 + i (+ a restart offset)
  double max_train_s = 0.0;  ///< wall-clock training budget, s (0: until the learner ends)
  /// The same seed, configuration and build give byte-identical checkpoints, policies and
  /// evaluation: the learner and the actors run deterministically (a restarted actor keeps its
  /// seed), budgets count updates (learner.max_updates or max_episodes), not seconds
  /// (max_train_s is not used), and the best policy is chosen from the learner's snapshots.
  bool reproducible = false;
  /// In reproducible mode an actor switches to the learner's next weights every this many of
  /// its steps.
  int round_weights_every_steps = 100;
  /// In reproducible mode the quick evaluation of the best policy looks at the learner's
  /// weights every this many updates (the learner's snapshots).
  std::int64_t best_eval_every_updates = 40000;
  double best_eval_period_s = 5.0;  ///< quick evaluation of the newest weights, s
  int best_eval_suite = 40;         ///< validation way-points in that quick evaluation
  /// The best policy holds within this on average on them, m (eval::ranks_above):
  /// half the evaluation's 0.3 m target, so that a faster policy does not win by drifting.
  double best_eval_max_hold_m = 0.15;
  /// CPU the learner is pinned to (-1: not pinned); actors then use the other CPUs.
  int learner_cpu = -1;
  /// Each simulator and its actor talk on a bus of their own (port 7668 + i), so nobody else
  /// receives their ~2 x 20k messages/s; false puts everything on the system's bus.
  bool private_lockstep_bus = true;
  int max_restarts = 5;             ///< a role restarted more often than this within...
  double restart_window_s = 120.0;  ///< ...this many seconds stops the run
  /// A process silent for this long after its first sign of life is taken as hung, killed
  /// (SIGKILL) and restarted like a crashed one, s (0: not watched). Signs of life: the
  /// simulator's SIM_HEARTBEAT, the logger's LOGGER_HEARTBEAT, the learner's LEARNER_STATS
  /// (each ~1 Hz) and an actor's EPISODE reports.
  double heartbeat_timeout_s = 60.0;
  /// An actor whose every episode is discarded (blow-up, simulator timeout) for this long while
  /// its simulator sends heartbeats ends the run as a fault, s.
  double discard_fault_s = 10.0;
};

/// Everything the launcher reads from the run configuration.
struct RunConfig {
  RunSettings run;
  task::TaskConfig task;
  std::string vehicle_path;
  std::int64_t learner_max_episodes = 0;  ///< learner.max_episodes (0: never)
  std::int64_t learner_max_updates = 0;   ///< learner.max_updates (0: never)
  /// learner.average_window_updates (0: off): the learner writes RUN/policy_average.nn, the
  /// policy that goes on.
  std::int64_t learner_average_window_updates = 0;
  transport::TransportConfig transport;  ///< the `transport:` section (LCM by default)
  tuning::FinetuneConfig finetune;       ///< the `finetune:` section (off by default)
};

/// Reads and checks a run configuration; throws config::ConfigError naming file, key and line.
RunConfig read_run_config(const std::string& path);

/// The keys of a `run:` section.
const config::Table<RunSettings>& run_table();
/// The keys of a `finetune:` section (tuning::FinetuneConfig).
const config::Table<tuning::FinetuneConfig>& finetune_table();

}  // namespace auvrl::launcher
