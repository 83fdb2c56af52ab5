// The best policy of a training run: the newest weights are scored now and then by a quick
// evaluation (eval::QuickEvaluator) and the best by eval::ranks_above is kept in
// policy_best.nn. In reproducible mode the weights scored are the learner's snapshots
// (<run>/snapshots/policy-<updates>.nn), each of them, in update order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "common/nn/mlp.hpp"
#include "eval/evaluation.hpp"
#include "eval/quick_evaluator.hpp"
#include "launcher/telemetry.hpp"
#include "learner/checkpoint.hpp"

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

// The learner's snapshots: named and listed where the learner writes them.
using learner::list_snapshots;
using learner::PolicySnapshot;

/// Hands the learner's snapshots in dir to a BestPolicyKeeper, each once and in update order,
/// and deletes each file once considered, so that the best policy of a reproducible run does
/// not depend on the machine's speed.
class SnapshotReviewer {
 public:
  /// dir: where the learner writes its snapshots (<run>/snapshots).
  explicit SnapshotReviewer(std::string dir) : dir_(std::move(dir)) {}

  /// Considers the oldest max_count snapshots in dir (version = their updates, at wall_s) and
  /// deletes them. A snapshot at or below the updates of one considered before is deleted
  /// unread (a learner restarted from an older checkpoint writes it again). One that cannot be
  /// read, or whose evaluation fails, is reported on out and deleted: the learner writes
  /// atomically, so an unreadable one is damage. Returns how many files were taken.
  std::size_t review(BestPolicyKeeper& keeper, double wall_s, QuickEvalSink& quick_eval,
                     std::ostream& out, std::size_t max_count);

  /// The updates of the last snapshot considered (-1: none yet).
  std::int64_t last_updates() const { return last_updates_; }

 private:
  /// Deletes a snapshot's file; a failure is reported on out.
  static void remove(const PolicySnapshot& snapshot, std::ostream& out);

  std::string dir_;
  std::int64_t last_updates_ = -1;
};

}  // namespace auvrl::launcher
