// `auvrl finetune`: the fine-tuning stage run again on a trained run's policy, with the run's own
// `finetune:` section or another configuration's, into a directory of its own, then the
// evaluation (scenarios and robustness suite, the policy against the PID). Training takes
// minutes and the fine-tuning seconds: this is how a fine-tuning setting is tried on the same
// trained policy.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

namespace auvrl::launcher {

/// What `auvrl finetune` was asked.
struct RefinetuneOptions {
  std::string run_dir;      ///< the trained run: its config.yaml (task, vehicle) and policy
  std::string config_path;  ///< "": the run's config.yaml; else its finetune: section is used
  /// "": the policy the run's fine-tuning started from (RUN/finetune_start.txt), else the one
  /// its evaluation named (eval/selected_policy.txt), else RUN/policy.nn.
  std::string policy_path;
  std::string out_dir;  ///< created (or empty): finetune.csv, policy_finetuned.nn, eval/
  int iterations = -1;  ///< overrides finetune.iterations when >= 0
  int candidates = 0;   ///< overrides finetune.candidates when >= 1
  /// The fine-tuning's seed (its way-points) when >= 0; else the run's: the seed its command
  /// line gave (command_line.yaml), or its configuration's run.seed.
  std::int64_t seed = -1;
  std::string source_dir;  ///< the source tree (scripts/ for the plots)
  /// Also write every validated iterate to out_dir/iterates/ (FinetuneStageInput::keep_iterates).
  bool keep_iterates = false;
};

/// Fine-tunes and evaluates as `auvrl train`'s stages do; the output directory gets the run's
/// configuration (config.yaml) and the one whose finetune: section was used
/// (finetune_config.yaml, when another). Returns 0, or 1 when the policy cannot be read. Throws
/// std::invalid_argument for a missing run, policy or configuration, a non-empty out_dir, or
/// fine-tuning settings out of range (those of --config or of the options above), before it
/// writes anything.
int refinetune(const RefinetuneOptions& options, std::ostream& out);

}  // namespace auvrl::launcher
