#include "launcher/refinetune.hpp"

#include <filesystem>
#include <optional>
#include <stdexcept>

#include "launcher/launcher.hpp"
#include "launcher/pipeline.hpp"
#include "launcher/run_config.hpp"
#include "launcher/run_directory.hpp"
#include "launcher/run_signing.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

/// The policy to fine-tune when none is given: the one the run's own fine-tuning started from
/// (RUN/finetune_start.txt), so that the new search is comparable with the run's and, with the
/// run's settings and seed, repeats it; for a run that was not fine-tuned, the one its evaluation
/// named (eval/selected_policy.txt); else RUN/policy.nn.
std::string run_policy(const std::string& run_dir, std::ostream& out) {
  if (std::optional<std::string> start = finetune_start(run_dir)) {
    out << "auvrl finetune: from the policy the run's fine-tuning started from ("
        << kFinetuneStartFile << ")\n";
    return *start;
  }
  if (std::optional<std::string> evaluated = policy_named_in(run_dir, kSelectedPolicyFile)) {
    out << "auvrl finetune: from the policy the run's evaluation used (" << kSelectedPolicyFile
        << ")\n";
    return *evaluated;
  }
  return (fs::path(run_dir) / "policy.nn").string();
}

}  // namespace

int refinetune(const RefinetuneOptions& o, std::ostream& out) {
  const fs::path run_config = fs::path(o.run_dir) / "config.yaml";
  if (!fs::exists(run_config)) {
    throw std::invalid_argument(o.run_dir + " has no config.yaml: not an `auvrl train` run");
  }
  const std::string policy = o.policy_path.empty() ? run_policy(o.run_dir, out) : o.policy_path;
  if (!fs::exists(policy)) throw std::invalid_argument(policy + " not found");
  if (directory_in_use(o.out_dir)) {
    throw std::invalid_argument(o.out_dir + " already exists and is not empty");
  }
  // The run's configuration and vehicle as `auvrl train` loads them, then this directory's.
  TrainOptions train;
  train.run_dir = o.run_dir;
  train.source_dir = o.source_dir;
  // The run's seed: the one its command line gave, where it gave one, else its configuration's.
  train.seed = o.seed >= 0 ? o.seed : command_line_seed(o.run_dir).value_or(-1);
  RunContext ctx = load_run_context(train, ContextUse::kAfterTraining);
  if (!o.config_path.empty()) ctx.rc.finetune = read_run_config(o.config_path).finetune;
  if (o.iterations >= 0) ctx.rc.finetune.iterations = o.iterations;
  if (o.candidates >= 1) ctx.rc.finetune.candidates = o.candidates;
  ctx.rc.finetune.validate();  // the command line's values too, before anything is written
  ctx.run_dir = o.out_dir;
  fs::create_directories(fs::path(o.out_dir) / "processes");
  ctx.config_path = (fs::path(o.out_dir) / "config.yaml").string();
  fs::copy_file(run_config, ctx.config_path);
  if (!o.config_path.empty()) {
    fs::copy_file(o.config_path, fs::path(o.out_dir) / "finetune_config.yaml");
  }
  out << "auvrl finetune: " << policy << " (run " << o.run_dir << ") into " << o.out_dir << "\n";
  const std::string kept = finetune_if_configured(ctx, policy, out, o.keep_iterates);
  sign_policies(o.out_dir, ensure_run_key(o.run_dir), out);  // the trained run's key
  const EvaluationResult evaluation = evaluate_stage(ctx, kept, out);
  report_stage(ctx, kept, evaluation, out);
  return 0;
}

}  // namespace auvrl::launcher
