// The quick evaluation of candidate policies on validation way-points of their own (never the
// reported scenarios), scored against the PID baseline on the same way-points: how `auvrl
// train` keeps its best policy and judges the fine-tuning's weights.
#pragma once

#include <cstdint>
#include <vector>

#include "common/nn/mlp.hpp"
#include "common/task/task.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::eval {

/// Seed of the quick evaluation's way-points (the reported suite uses seed 1).
constexpr std::uint64_t kValidationSeed = 0x7A11DA7E;

/// The quick evaluation that keeps the best policy: the validation way-points, run once by the
/// PID baseline at construction and by each candidate policy on demand. With turned > 0, that
/// many more way-points start facing a random heading (as test2 does; the fine-tuning's
/// choice, which must not trade the turn for speed).
class QuickEvaluator {
 public:
  QuickEvaluator(const sim::VehicleModel& model, const task::TaskConfig& task, int suite_episodes,
                 int turned = 0);

  /// Runs the policy on the validation way-points and scores it against the PID's runs, on
  /// `threads` threads (the same score on any number).
  ValidationScore evaluate(const nn::Mlp& network, int threads = 1) const;

 private:
  std::vector<SummaryRow> run(agent::Controller& controller) const;

  const sim::VehicleModel& model_;
  task::TaskConfig task_;
  EvaluationConfig config_;
  std::vector<EvaluationEpisode> episodes_;
  std::vector<SummaryRow> reference_;
};

}  // namespace auvrl::eval
