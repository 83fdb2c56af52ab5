// The best policy of a training run: the newest weights are scored now and then by a quick
// evaluation (eval::QuickEvaluator) and the best by eval::ranks_above is kept in
// policy_best.nn.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "common/nn/mlp.hpp"
#include "eval/evaluation.hpp"
#include "eval/quick_evaluator.hpp"
#include "launcher/telemetry.hpp"

namespace auvrl::launcher {

/// Keeps the best policy seen by the quick evaluation in <run_dir>/policy_best.nn.
class BestPolicyKeeper {
 public:
  /// suite_episodes validation way-points; a best policy holds within max_hold_m on them.
  BestPolicyKeeper(const sim::VehicleModel& model, const task::TaskConfig& task, int suite_episodes,
                   double max_hold_m, std::string run_dir);

  /// A resumed run keeps its policy_best.nn (as version 0) unless a newer one scores better;
  /// an unreadable one is reported on out and ignored.
  void restore(std::ostream& out);
  /// Scores the weights of `version`, keeps them if they rank above the best so far, and
  /// records the evaluation in quick_eval.
  void consider(const nn::Mlp& net, std::int64_t version, double wall_s, QuickEvalSink& quick_eval);
  /// Whether the best policy ranks above the policy at path (the last one): the choice between
  /// them at the end of training. Throws if it cannot be read.
  bool best_ranks_above(const std::string& path) const;

  /// Whether a best policy exists (evaluated this run or restored).
  bool has_best() const { return best_version_ >= 0; }
  /// The best policy's score (meaningful when has_best()).
  const eval::ValidationScore& best() const { return best_; }
  /// The best policy's version: 0 from before a resume, -1 none.
  std::int64_t best_version() const { return best_version_; }
  /// The best's path.
  std::string best_path() const;
  /// The ranking's hold limit, m.
  double max_hold_m() const { return max_hold_m_; }

 private:
  eval::QuickEvaluator quick_;
  double max_hold_m_;
  std::string run_dir_;
  eval::ValidationScore best_;
  std::int64_t best_version_ = -1;
};

}  // namespace auvrl::launcher
