// What a training run writes as it goes, each through the project's CSV writer: episodes.csv
// (one row per episode report), learner.csv (the learner's figures), progress.csv (the status
// line's figures, once a second), quick_eval.csv (every quick evaluation), finetune.csv (the
// fine-tuning's iterations) and objective_terms.csv (the fine-tuning's objective by price,
// written whole once the fine-tuning ends). Rows are appended over --resume. Columns and number
// formats are the run directory's interface to scripts/plot_run.py and the tests: keep them.
#pragma once

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/csv.hpp"
#include "eval/evaluation.hpp"
#include "tuning/policy_finetune.hpp"

namespace auvrl::launcher {

/// episodes.csv: one row per EPISODE report.
class EpisodeSink {
 public:
  explicit EpisodeSink(const std::string& path);
  /// One episode, wall_s into the run's training time.
  void add(double wall_s, const auvrl_lcm::episode_report_t& e);
  /// The file's writer (flush, path).
  csv::Writer& writer() { return writer_; }

 private:
  csv::Writer writer_;
};

/// learner.csv: one row per LEARNER_STATS message.
class LearnerSink {
 public:
  explicit LearnerSink(const std::string& path);
  /// The learner's figures, wall_s into the run's training time.
  void add(double wall_s, const auvrl_lcm::learner_stats_t& s);
  /// The file's writer (flush, path).
  csv::Writer& writer() { return writer_; }

 private:
  csv::Writer writer_;
};

/// One row of progress.csv: the status line's figures.
struct ProgressRow {
  double wall_s = 0;              ///< training time of the run, s
  std::int64_t episodes = 0;      ///< episodes the learner counted
  double success_rate = 0;        ///< over the last 100 episodes, 0..1
  double beta_m = 0;              ///< goal radius, m
  double env_steps_per_s = 0;     ///< simulator steps per second, all simulators
  double updates_per_s = 0;       ///< the learner's updates per second
  double best_suite_success = 0;  ///< the best policy's share of the quick evaluation reached
};

/// progress.csv: the status line's figures once a second. (best_suite_success is written with
/// no decimals, as it always was.)
class ProgressSink {
 public:
  explicit ProgressSink(const std::string& path);
  /// One row.
  void add(const ProgressRow& row);
  /// The file's writer (flush, path).
  csv::Writer& writer() { return writer_; }

 private:
  csv::Writer writer_;
};

/// quick_eval.csv: every quick evaluation of the newest weights. An existing file with other
/// columns (a run resumed from an older version) is moved to quick_eval.old.csv first.
class QuickEvalSink {
 public:
  explicit QuickEvalSink(const std::string& path);
  /// One evaluation of policy `version` at wall_s; kept: it became the best so far.
  void add(double wall_s, std::int64_t version, const eval::ValidationScore& score, bool kept);
  /// The file's writer (flush, path).
  csv::Writer& writer() { return writer_; }

 private:
  csv::Writer writer_;
};

/// finetune.csv: one row per fine-tuning iteration, the validation columns empty where the
/// iteration was not validated.
class FinetuneSink {
 public:
  explicit FinetuneSink(const std::string& path);
  /// One iteration; validation: its validation score, or nullptr when not validated.
  void add(int iteration, double objective_s, double elapsed_s,
           const eval::ValidationScore* validation);
  /// The file's writer (flush, path).
  csv::Writer& writer() { return writer_; }

 private:
  csv::Writer writer_;
};

/// One controller's fine-tuning objective by price (objective_terms.csv).
struct ObjectiveTermsRow {
  std::string controller;  ///< pid, start (the trained policy) or finetuned
  tuning::ObjectiveTerms terms;
};

/// Writes objective_terms.csv: one row per controller, each price's mean over the fine-tuning's
/// way-points, s. Throws std::runtime_error naming the file when it cannot be written.
void write_objective_terms(const std::string& path, const std::vector<ObjectiveTermsRow>& rows);

/// One fine-tuning candidate (candidates.csv).
struct CandidatesRow {
  int candidate = 0;         ///< from 1
  std::uint64_t seed = 0;    ///< its search's seed
  int kept_iteration = 0;    ///< the validated iteration it kept; 0: none (the trained policy)
  double objective_s = 0.0;  ///< the lowest mean objective its search saw, s
  int groups_passing = 0;    ///< robustness groups passing against the PID at the selection seed
  int groups = 0;            ///< the suite's groups
  int behind_late = 0;       ///< way-points straight behind reached late (tuning::CandidateScore)
  int behind_episodes = 0;   ///< of these
  bool chosen = false;       ///< the one kept
  bool mean = false;  ///< the searches' mean (finetune.average_candidates): no seed or iteration
};

/// Writes candidates.csv: one row per candidate. Throws std::runtime_error naming the file when
/// it cannot be written.
void write_candidates(const std::string& path, const std::vector<CandidatesRow>& rows);

/// The four files written while training, in run_dir.
class TrainingTelemetry {
 public:
  explicit TrainingTelemetry(const std::string& run_dir);
  /// Flushes every file; on a failure returns the stop message naming the file and the error
  /// (disk full, read-only), nothing otherwise.
  std::optional<std::string> flush();

  EpisodeSink episodes;
  LearnerSink learner;
  ProgressSink progress;
  QuickEvalSink quick_eval;

 private:
  std::string run_dir_;
};

/// The training time of earlier invocations of the run in run_dir (the last row of its
/// progress.csv), s; 0 for a new run.
double trained_before_s(const std::string& run_dir);

}  // namespace auvrl::launcher
