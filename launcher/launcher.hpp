// `auvrl train`: the whole training system from one command. Starts auv_logger, one auv_sim
// per actor (pinned to the actor's CPU: a lockstep round trip between CPUs costs inter-
// processor interrupts on virtual machines), N auv_actor processes and auv_learner, each its
// own process, in a run directory; shows progress; restarts what crashes; keeps the best
// policy by a quick evaluation of the weights as they arrive (in reproducible mode, of every
// snapshot the learner writes, --reproducible); stops cleanly on Ctrl-C; then
// fine-tunes the trained policy (`finetune:`, tuning/policy_finetune.hpp) and keeps it if it
// scores better on the quick evaluation; and at the end evaluates the policy and the PID
// baseline, draws the plots and writes the report.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "launcher/run_directory.hpp"

namespace auvrl::launcher {

/// What `auvrl train` was asked.
struct TrainOptions {
  std::string config_path;        ///< a preset or configuration file (new runs)
  std::string vehicle_path;       ///< replaces the configuration's vehicle: (new runs; "": keep)
  std::string run_dir;            ///< the run directory (created for new runs)
  bool resume = false;            ///< continue the run in run_dir
  int actors = -1;                ///< overrides run.actors when >= 0
  double max_train_s = -1;        ///< overrides run.max_train_s when >= 0
  std::int64_t seed = -1;         ///< overrides run.seed when >= 0
  bool reproducible = false;      ///< sets run.reproducible (false: the configuration's)
  std::int64_t max_updates = -1;  ///< overrides learner.max_updates when >= 0 (0: never)
  int finetune_iterations = -1;   ///< overrides finetune.iterations when >= 0 (0: none)
  bool evaluate = true;           ///< evaluation, plots and report after training
  std::string bin_dir;            ///< where auv_sim, auv_actor, auv_learner, auv_logger are
  std::string source_dir;         ///< the source tree (scripts/ for plots)
  /// Transport flags given on the command line (--transport dds, --dds-peers ...): applied
  /// over the configuration's `transport:` section and passed to every process.
  std::vector<std::string> transport_args;
};

/// `auvrl train` once its options are parsed: prepares the run directory (a new run) or checks
/// it (--resume), then runs the pipeline here when host_network is set or when this process
/// already runs inside the private network namespace (AUVRL_IN_NETNS=1); otherwise runs
/// `auvrl train --resume RUN` again inside a new private namespace (scripts/netns.sh, its PID
/// in RUN/netns.pid for lcm-spy and the log tools) and does not return. Returns the exit code.
int start_training(TrainOptions options, bool host_network, std::ostream& out);

/// The command line that runs this training again inside a private network namespace: the
/// run directory prepared, every option given passed on.
std::vector<std::string> namespace_command(const TrainOptions& options);

/// Runs the pipeline train -> select -> fine-tune -> evaluate -> report (already inside the
/// network namespace, or with --network host). Returns the process exit code.
int run_training(const TrainOptions& options, std::ostream& out);

}  // namespace auvrl::launcher
