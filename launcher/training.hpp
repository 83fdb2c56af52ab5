// The training stage of `auvrl train`: opens the transport, starts and supervises the
// processes, writes the run's telemetry, shows the status line and keeps the best policy until
// the budget is used, the learner's schedule ends, the user stops it or a role keeps failing;
// then stops the processes in order.
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "launcher/best_policy.hpp"
#include "launcher/launcher.hpp"
#include "launcher/run_config.hpp"
#include "launcher/supervisor.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {

/// What every stage knows of the run: its directory, configuration (with the command line's
/// overrides) and vehicle.
struct RunContext {
  TrainOptions options;
  std::string run_dir;
  std::string config_path;  ///< <run_dir>/config.yaml
  RunConfig rc;
  sim::VehicleModel model;
  int cpus = 1;    ///< CPUs online
  int actors = 1;  ///< actor (and simulator) processes
};

/// What a run's context is loaded for.
enum class ContextUse {
  kTraining,       ///< `auvrl train`: the training budget is checked
  kAfterTraining,  ///< fine-tuning or evaluating a trained run (`auvrl finetune`)
};

/// Reads the run's configuration and vehicle and applies the command line's overrides. For
/// training, a reproducible run without a budget in updates or episodes is refused
/// (check_reproducible_budget).
RunContext load_run_context(const TrainOptions& options, ContextUse use = ContextUse::kTraining);

/// Applies the command line's overrides (--actors, --max-seconds, --seed, --reproducible,
/// --max-updates, --finetune-iterations) to a run configuration.
void apply_train_options(const TrainOptions& options, RunConfig& rc);

/// A reproducible run counts its budget in updates (learner.max_updates) or episodes
/// (learner.max_episodes), never in seconds: throws std::runtime_error naming what to set when
/// it has neither. Nothing for an asynchronous run.
void check_reproducible_budget(const RunConfig& rc);

/// Where the learner writes the mean of its recent actors (learner.average_window_updates), in
/// the run directory.
inline constexpr const char* kAveragePolicyFile = "policy_average.nn";

/// Where the learner writes its snapshots in reproducible mode: <run_dir>/snapshots.
std::string snapshot_dir(const std::string& run_dir);

/// The command lines of the roles, in start order: the logger, one simulator per actor, the
/// learner (with --resume when a checkpoint exists at its start), the actors. transport_args
/// are appended to each (before the learner's --resume). A --max-updates override reaches the
/// learner as its flag. In reproducible mode the learner and the actors get --reproducible and
/// --round-weights-every-steps, the learner --snapshot-dir <run>/snapshots and
/// --snapshot-every-updates (run.best_eval_every_updates), and a restarted actor keeps its seed.
std::vector<RoleSpec> make_roles(const RunContext& ctx,
                                 const std::vector<std::string>& transport_args);

/// How the training stage ended.
struct TrainingResult {
  int exit_code = 0;  ///< 0: budget used or schedule ended; 130: stopped by the user; 1: failed
  /// The best policy by the quick evaluation (also used to choose the policy afterwards).
  std::unique_ptr<BestPolicyKeeper> best;
};

/// Runs the training stage (inside the run's network namespace, or with --network host) and
/// prints its summary of the run directory.
TrainingResult train(const RunContext& ctx, std::ostream& out);

}  // namespace auvrl::launcher
