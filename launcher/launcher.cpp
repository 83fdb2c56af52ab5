#include "launcher/launcher.hpp"

#include <chrono>

#include "launcher/namespace_exec.hpp"
#include "launcher/pipeline.hpp"
#include "launcher/run_signing.hpp"
#include "launcher/training.hpp"

namespace auvrl::launcher {

int run_training(const TrainOptions& options, std::ostream& out) {
  out << std::unitbuf;  // progress and supervision lines must reach a log file as they happen
  const auto training_start = std::chrono::steady_clock::now();
  const RunContext ctx = load_run_context(options);
  // Made before training, so that a full disk or a read-only run stops it at once.
  const std::string key = ensure_run_key(ctx.run_dir);
  const TrainingResult trained = train(ctx, out);
  if (trained.exit_code != 0) {
    sign_policies(ctx.run_dir, key, out);  // a stopped run's policies are usable too
    return trained.exit_code;
  }
  const std::optional<std::string> selected = select_policy(
      ctx.run_dir, *trained.best, {ctx.model, ctx.rc.task, ctx.rc.finetune.selection_seed},
      ctx.rc.learner_average_window_updates > 0, out);
  if (!selected) {
    out << "auvrl train: no policy was written; nothing to fine-tune or evaluate\n";
    return 1;
  }
  const std::string policy_path =
      finetune_if_configured(ctx, *selected, out, false, training_start);
  sign_policies(ctx.run_dir, key, out);
  if (!options.evaluate) return 0;
  const EvaluationResult evaluation = evaluate_stage(ctx, policy_path, out);
  report_stage(ctx, policy_path, evaluation, out);
  return 0;
}

std::vector<std::string> namespace_command(const TrainOptions& options) {
  std::vector<std::string> args = netns_prefix(options.source_dir, options.run_dir);
  args.insert(args.end(), {options.bin_dir + "/auvrl", "train", "--resume", options.run_dir});
  const auto pass = [&args](const char* flag, const std::string& value) {
    args.insert(args.end(), {flag, value});
  };
  if (options.actors >= 0) pass("--actors", std::to_string(options.actors));
  if (options.max_train_s >= 0) pass("--max-seconds", std::to_string(options.max_train_s));
  if (options.seed >= 0) pass("--seed", std::to_string(options.seed));
  if (options.reproducible) args.push_back("--reproducible");
  if (options.max_updates >= 0) pass("--max-updates", std::to_string(options.max_updates));
  if (options.finetune_iterations >= 0) {
    pass("--finetune-iterations", std::to_string(options.finetune_iterations));
  }
  if (!options.evaluate) args.push_back("--no-eval");
  pass("--bin-dir", options.bin_dir);
  args.insert(args.end(), options.transport_args.begin(), options.transport_args.end());
  return args;
}

int start_training(TrainOptions options, bool host_network, std::ostream& out) {
  const bool in_namespace = in_private_namespace();
  if (!in_namespace) prepare_run_directory(options);
  if (host_network || in_namespace) return run_training(options, out);
  exec_in_namespace(namespace_command(options));
}

}  // namespace auvrl::launcher
