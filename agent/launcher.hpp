// `auvrl train`: the whole training system from one command. Starts auv_logger, one auv_sim
// per actor (pinned to the actor's CPU: a lockstep round trip between CPUs costs inter-
// processor interrupts on virtual machines), N auv_actor processes and auv_learner, each its
// own process, in a run directory; shows progress; restarts what crashes; keeps the best
// policy by a quick evaluation of the weights as they arrive; stops cleanly on Ctrl-C; then
// fine-tunes the trained policy (`finetune:`, agent/policy_finetune.hpp) and keeps it if it
// scores better on the quick evaluation; and at the end evaluates the policy and the PID
// baseline, draws the plots and writes the report.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace auvrl::agent {

/// The `run:` section of a run configuration.
struct RunSettings {
  int actors = 0;                   ///< 0: one per CPU
  std::uint64_t seed = 1;           ///< actor i uses seed * 1000 + i (+ a restart offset)
  double max_train_s = 0.0;         ///< wall-clock training budget, s (0: until the learner ends)
  double best_eval_period_s = 5.0;  ///< quick evaluation of the newest weights, s
  int best_eval_suite = 40;         ///< validation way-points in that quick evaluation
  /// The best policy holds within this on average on them, m (ValidationScore::better_than):
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
};

/// What `auvrl train` was asked.
struct TrainOptions {
  std::string config_path;       ///< a preset or configuration file (new runs)
  std::string run_dir;           ///< the run directory (created for new runs)
  bool resume = false;           ///< continue the run in run_dir
  int actors = -1;               ///< overrides run.actors when >= 0
  double max_train_s = -1;       ///< overrides run.max_train_s when >= 0
  std::int64_t seed = -1;        ///< overrides run.seed when >= 0
  int finetune_iterations = -1;  ///< overrides finetune.iterations when >= 0 (0: none)
  bool evaluate = true;          ///< evaluation, plots and report after training
  std::string bin_dir;           ///< where auv_sim, auv_actor, auv_learner, auv_logger are
  std::string source_dir;        ///< the source tree (scripts/ for plots)
  /// Transport flags given on the command line (--transport dds, --dds-peers ...): applied
  /// over the configuration's `transport:` section and passed to every process.
  std::vector<std::string> transport_args;
};

/// Creates the run directory of a new run (config copy, folders) or checks an existing one for
/// --resume; returns the path of the run's configuration. Throws std::runtime_error naming
/// what is wrong.
std::string prepare_run_directory(TrainOptions& options);

/// Runs training (already inside the network namespace, or with --network host), then the
/// evaluation. Returns the process exit code.
int run_training(const TrainOptions& options, std::ostream& out);

}  // namespace auvrl::agent
