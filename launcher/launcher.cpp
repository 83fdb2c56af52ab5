#include "launcher/launcher.hpp"

#include "launcher/pipeline.hpp"
#include "launcher/training.hpp"

namespace auvrl::launcher {

int run_training(const TrainOptions& options, std::ostream& out) {
  out << std::unitbuf;  // progress and supervision lines must reach a log file as they happen
  const RunContext ctx = load_run_context(options);
  const TrainingResult trained = train(ctx, out);
  if (trained.exit_code != 0) return trained.exit_code;
  const std::optional<std::string> selected = select_policy(ctx.run_dir, *trained.best);
  if (!selected) {
    out << "auvrl train: no policy was written; nothing to fine-tune or evaluate\n";
    return 1;
  }
  const std::string policy_path = finetune_if_configured(ctx, *selected, out);
  if (!options.evaluate) return 0;
  const EvaluationResult evaluation = evaluate_stage(ctx, policy_path, out);
  report_stage(ctx, policy_path, evaluation, out);
  return 0;
}

}  // namespace auvrl::launcher
