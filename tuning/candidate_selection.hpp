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

/// Way-points straight behind a start at rest (the facing_away group of eval/robustness.hpp)
/// that the choice among candidates draws besides the suite: a search may learn to back towards
/// such a way-point for seconds before it turns, which the suite's random headings rarely show.
constexpr int kBehindEpisodes = 100;
/// A candidate is late on one of them when it arrives more than this after the PID (s), or not
/// at all where the PID does.
constexpr double kBehindLateMarginS = 0.3;
/// The behind criterion passes when at most this fraction of them is late.
constexpr double kBehindLateFractionMax = 0.1;

/// What the choice among candidates knows of one.
struct CandidateScore {
  int groups_passing = 0;   ///< robustness groups passing against the PID
  int behind_late = 0;      ///< way-points straight behind reached late (kBehindLateMarginS)
  int behind_episodes = 0;  ///< of these
  /// At most kBehindLateFractionMax of the way-points straight behind late.
  bool behind_passes() const { return behind_late <= kBehindLateFractionMax * behind_episodes; }
  /// The groups passing, plus one when the behind criterion passes.
  int criteria_passing() const { return groups_passing + (behind_passes() ? 1 : 0); }
};

/// Scores policies by the robustness groups they pass against the PID baseline
/// (eval::compare_robustness with the default bar), on the suite drawn at one seed, and by how
/// many of kBehindEpisodes way-points straight behind (drawn at the same seed) they reach late.
/// The PID's episodes run once, when it is made. The model must outlive it.
class SuiteSelector {
 public:
  /// Throws std::invalid_argument when seed is the evaluation's own (eval::EvaluationConfig's
  /// default seed, the suite's draws the bar is read on).
  /// Its episodes run on `threads` threads (the same scores on any number).
  SuiteSelector(const sim::VehicleModel& model, const task::TaskConfig& task, std::uint64_t seed,
                int episodes_per_group = eval::kRobustnessEpisodesPerGroup, int threads = 1);
  /// The comparison, group by group, of the policy (integral action as the task says, as it
  /// drives) with the PID.
  std::vector<eval::GroupComparison> compare(const nn::Mlp& policy) const;
  /// The groups the policy passes.
  int groups_passing(const nn::Mlp& policy) const;
  /// The groups it passes and its way-points straight behind reached late.
  CandidateScore score(const nn::Mlp& policy) const;
  /// The suite's groups.
  int groups() const { return static_cast<int>(pid_groups_.size()); }

 private:
  const sim::VehicleModel& model_;
  task::TaskConfig task_;
  std::uint64_t seed_;
  int episodes_per_group_;
  int threads_;
  std::vector<eval::GroupMetrics> pid_groups_;
  std::vector<eval::EvaluationEpisode> behind_;
  std::vector<eval::SummaryRow> pid_behind_;
};

/// The candidate to keep: the most criteria passing (CandidateScore::criteria_passing), ties to
/// the fewest way-points straight behind reached late, then to the earliest. Throws
/// std::invalid_argument when there is none.
std::size_t choose_candidate(const std::vector<CandidateScore>& scores);

/// Whether the searches' mean weights (finetune.average_candidates) are kept rather than the
/// search choose_candidate chose: unless that search passes more criteria. Ties go to the mean:
/// at equal scores on the selection draw the mean passed more groups on validation draws
/// (docs/lab-notes/2026-12-03-the-searches-mean.md).
bool keep_mean(const CandidateScore& mean, const CandidateScore& chosen_search);

/// The failures (flips and blow-ups) of the policy, driving as the task says, over the
/// robustness suite drawn at `seed`: a validation draw of the pipeline's own. Throws
/// std::invalid_argument when seed is the evaluation's own draw, as SuiteSelector does.
int suite_failures(const sim::VehicleModel& model, const task::TaskConfig& task, std::uint64_t seed,
                   const nn::Mlp& policy,
                   int episodes_per_group = eval::kRobustnessEpisodesPerGroup);

}  // namespace auvrl::tuning
