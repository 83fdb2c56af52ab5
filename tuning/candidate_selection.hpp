// Choosing on a validation draw of the robustness suite: among fine-tuning candidates (several
// searches from the same trained policy, each with a seed of its own), the one whose kept
// weights pass the most groups against the PID baseline; between the trained policies (the last
// and the best seen), the one that flips less. The suite is drawn at a validation seed of the
// pipeline's own (finetune.selection_seed), never at the evaluation's: the choice sees the
// suite's kinds of conditions, not the draws it is scored on.
#pragma once

#include <cstdint>
#include <vector>

#include "common/nn/mlp.hpp"
#include "common/task/task.hpp"
#include "eval/robustness.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::tuning {

/// The search seed of candidate `index` (from 0) of a run: the run's seed plus the index, so that
/// the first candidate is the fine-tuning with one search.
std::uint64_t candidate_seed(std::uint64_t run_seed, int index);

/// Scores policies by the robustness groups they pass against the PID baseline
/// (eval::compare_robustness with the default bar), on the suite drawn at one seed. The PID's
/// episodes run once, when it is made. The model must outlive it.
class SuiteSelector {
 public:
  /// Throws std::invalid_argument when seed is the evaluation's own (eval::EvaluationConfig's
  /// default seed, the suite's draws the bar is read on).
  SuiteSelector(const sim::VehicleModel& model, const task::TaskConfig& task, std::uint64_t seed,
                int episodes_per_group = eval::kRobustnessEpisodesPerGroup);
  /// The comparison, group by group, of the policy (integral action as the task says, as it
  /// drives) with the PID.
  std::vector<eval::GroupComparison> compare(const nn::Mlp& policy) const;
  /// The groups the policy passes.
  int groups_passing(const nn::Mlp& policy) const;
  /// The suite's groups.
  int groups() const { return static_cast<int>(pid_groups_.size()); }

 private:
  const sim::VehicleModel& model_;
  task::TaskConfig task_;
  std::uint64_t seed_;
  int episodes_per_group_;
  std::vector<eval::GroupMetrics> pid_groups_;
};

/// The candidate to keep: the most groups passing, ties to the earliest. Throws
/// std::invalid_argument when there is none.
std::size_t choose_candidate(const std::vector<int>& groups_passing);

/// The failures (flips and blow-ups) of the policy, driving as the task says, over the
/// robustness suite drawn at `seed`: a validation draw of the pipeline's own. Throws
/// std::invalid_argument when seed is the evaluation's own draw, as SuiteSelector does.
int suite_failures(const sim::VehicleModel& model, const task::TaskConfig& task, std::uint64_t seed,
                   const nn::Mlp& policy,
                   int episodes_per_group = eval::kRobustnessEpisodesPerGroup);

}  // namespace auvrl::tuning
