// The stages after training: select (the last policy or the best seen) -> fine-tune ->
// evaluate (the policy and the PID baseline) -> report (plots, summary tables).
#pragma once

#include <chrono>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "eval/evaluation.hpp"
#include "eval/quick_evaluator.hpp"
#include "eval/robustness.hpp"
#include "launcher/best_policy.hpp"
#include "launcher/telemetry.hpp"
#include "launcher/training.hpp"

namespace auvrl::launcher {

/// Where the trained policies' failures are counted: the robustness suite drawn at `seed`, a
/// validation draw of the pipeline's own (finetune.selection_seed).
struct SelectionDraw {
  const sim::VehicleModel& model;
  const task::TaskConfig& task;
  std::uint64_t seed;  ///< finetune.selection_seed
};

/// The trained policy to go on with: policy.nn, or policy_best.nn when the best seen ranks
/// above the last one on the quick evaluation (or the last one cannot be read); but of two
/// different files, the one with fewer failures (flips, blow-ups) on the selection draw, which
/// the quick evaluation's few way-points can miss (a TD3 snapshot that flips on deep dives).
/// Says what it counted on out. Nothing when neither file exists. With `average` (the run sets
/// learner.average_window_updates) and the learner's mean of its recent actors written
/// (kAveragePolicyFile): the mean, unless that choice has fewer failures on the same draw.
std::optional<std::string> select_policy(const std::string& run_dir, const BestPolicyKeeper& best,
                                         const SelectionDraw& draw, bool average,
                                         std::ostream& out);

/// What the fine-tuning stage needs besides the policy.
struct FinetuneStageInput {
  const sim::VehicleModel& model;
  const task::TaskConfig& task;
  const tuning::FinetuneConfig& config;
  std::uint64_t seed = 1;
  const eval::QuickEvaluator& validation;  ///< scores candidate weights
  double max_hold_m = 0.15;                ///< the ranking's hold limit, m
  std::string run_dir;
  /// When true, the weights scored on the validation way-points are also written to
  /// run_dir/iterates/iteration_NNN.nn (the iteration's number, three digits at least;
  /// candidate K's to iterates_candidateK/), for evaluating how the fine-tuning went beyond what
  /// it keeps.
  bool keep_iterates = false;
  /// A reproducible run: every candidate is searched, and every iteration, whatever
  /// finetune.candidates_within_s and max_search_s say.
  bool reproducible = false;
  /// When the training began (its TD3 phase, or `auvrl finetune`): finetune.candidates_within_s
  /// counts from here.
  std::chrono::steady_clock::time_point training_start = std::chrono::steady_clock::now();
};

/// Fine-tunes the policy at start_path (progress to finetune.csv) and returns the path of the
/// policy to keep. The weights are scored on validation way-points every validate_every
/// iterations and at the end; the best of them, if better than the start there, is written to
/// policy_finetuned.nn and kept. (The fine-tuning's own way-points are few: a step that lowers
/// their objective can lose a way-point elsewhere.) With finetune.candidates > 1 the searches
/// run one after another (candidate K's progress to finetune_candidateK.csv; an asynchronous run
/// starts no further one that would end past finetune.candidates_within_s), and the one whose
/// kept weights pass the most criteria at finetune.selection_seed is kept (candidates.csv;
/// tuning::choose_candidate). Ctrl-C ends it after the iteration under
/// way.
std::string finetune_stage(const FinetuneStageInput& in, const std::string& start_path,
                           std::ostream& out);

/// Why the fine-tuning starts no further candidate after `done` searches, if so: an
/// asynchronous run where config.candidate_min_fraction of the next search (all of it at 1), at
/// the mean pace of the searches so far (searches_s for the `done` of them), would end past
/// config.candidates_within_s (when > 0) of training (training_s so far). Nothing before the
/// first search, when all are done (the loop ends anyway) or in a reproducible run, whose result
/// must not depend on the machine's speed.
std::optional<std::string> no_further_candidate(const tuning::FinetuneConfig& config,
                                                bool reproducible, double training_s,
                                                double searches_s, int done);

/// Why an asynchronous run's search ends after `done` iterations of its config.iterations, if
/// so: at the mean pace of those (search_s for them, from this search's start), the next would
/// end past config.max_search_s (when > 0) of this search, or, for a further candidate
/// (`further_candidate`: not the first search) with config.candidate_min_fraction below 1,
/// past config.candidates_within_s (when > 0) of training (training_s so far). Never in a
/// reproducible run, nor after the last iteration (the search ends there anyway).
std::optional<std::string> search_past_cap(const tuning::FinetuneConfig& config, bool reproducible,
                                           double search_s, int done, double training_s = 0,
                                           bool further_candidate = false);

/// The file in a run directory that names the policy its fine-tuning started from: relative to
/// the run directory when inside it, so that the run can be moved.
inline constexpr const char* kFinetuneStartFile = "finetune_start.txt";

/// The file in a run directory that names the policy its evaluation used.
inline constexpr const char* kSelectedPolicyFile = "eval/selected_policy.txt";

/// The policy that the record file `record` (relative to run_dir) names on its first line, a
/// relative name resolved against run_dir, when that policy file exists; nullopt otherwise.
std::optional<std::string> policy_named_in(const std::string& run_dir, const std::string& record);

/// The policy run_dir's fine-tuning started from (RUN/finetune_start.txt), when the file names
/// one that exists; nullopt otherwise (a run that was not fine-tuned, or older than the file).
std::optional<std::string> finetune_start(const std::string& run_dir);

/// Runs the fine-tuning stage when configured (keep_iterates: FinetuneStageInput's), first
/// recording policy_path in RUN/finetune_start.txt (a record: when it cannot be written the
/// stage says so and goes on); on a failure keeps policy_path. Returns the path of the policy
/// to evaluate. training_start: when the training began (finetune.candidates_within_s counts
/// from it).
std::string finetune_if_configured(
    const RunContext& ctx, const std::string& policy_path, std::ostream& out,
    bool keep_iterates = false,
    std::chrono::steady_clock::time_point training_start = std::chrono::steady_clock::now());

/// The evaluation of a policy and of the PID baseline on every scenario and on the robustness
/// suite.
struct EvaluationResult {
  std::vector<eval::SummaryRow> policy_rows;
  std::vector<eval::SummaryRow> pid_rows;
  /// The robustness suite, policy against the PID group by group (empty when it failed).
  std::vector<eval::GroupComparison> robustness;
  double robustness_policy_s = 0.0;  ///< wall-clock time of the policy's suite, s
  double robustness_pid_s = 0.0;     ///< and of the PID's
};

/// Evaluates the policy at policy_path and the PID baseline into <run_dir>/eval/: the five
/// scenarios (summary.csv, trajectories/), then the robustness suite (robustness.csv,
/// robustness_episodes.csv, and eval/robustness_comparison.md). A failure of the robustness
/// suite is reported on `out` and costs only its files.
EvaluationResult evaluate_stage(const RunContext& ctx, const std::string& policy_path,
                                std::ostream& out);

/// Draws the plots (scripts/plot_run.py, which also writes report.md with the robustness
/// table and figure) and prints the summary tables and the robustness verdict.
void report_stage(const RunContext& ctx, const std::string& policy_path,
                  const EvaluationResult& result, std::ostream& out);

}  // namespace auvrl::launcher
