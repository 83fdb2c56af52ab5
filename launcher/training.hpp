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

/// Reads the run's configuration and vehicle and applies the command line's overrides.
RunContext load_run_context(const TrainOptions& options);

/// The command lines of the roles, in start order: the logger, one simulator per actor, the
/// learner (with --resume when a checkpoint exists at its start), the actors. transport_args
/// are appended to each (before the learner's --resume).
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
