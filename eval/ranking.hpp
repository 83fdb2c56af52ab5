// The one rule that ranks policies by their scores on validation way-points. `auvrl train`
// keeps its best policy by it (the newest weights as they arrive, then policy.nn against
// policy_best.nn) and the fine-tuning keeps its best weights by it.
#pragma once

#include <optional>

#include "eval/evaluation.hpp"

namespace auvrl::eval {

/// How two ValidationScores are compared. In order: more way-points reached; then, when priced,
/// the smaller priced time (below); otherwise a mean hold error within max_hold_m (both
/// outside: the smaller hold error); then, when worst_ratio_first, the smaller worst ratio of
/// time to reach to the PID's; then the shorter mean time.
struct Ranking {
  /// A mean hold error within this counts as holding, m (`run.best_eval_max_hold_m`).
  double max_hold_m = 0.15;
  /// Compare the worst time ratio to the PID before the mean time. The training's choice: the
  /// evaluation compares the policy with the PID scenario by scenario, so a policy much faster
  /// on most way-points can still lose on one. The fine-tuning ranks without it: over one
  /// way-point of 40 the worst ratio moves by 0.1-0.2 between neighbouring iterations and would
  /// turn down a whole second off the mean time, which is what the fine-tuning lowers.
  bool worst_ratio_first = true;
  /// A fine-tuning that prices thrust keeps its weights by the same prices (its objective's):
  /// mean time + hold_weight x mean hold error + energy_weight x mean thrust energy +
  /// smoothness_weight x mean smoothness, s. Ranked by time and hold alone, an early iterate that
  /// arrives as soon but spends more thrust and chatters would be kept over the frugal one the
  /// objective was lowering.
  struct Prices {
    double hold_weight = 0.0;  ///< s per m
    double energy_weight = 0.0;
    double smoothness_weight = 0.0;
  };
  std::optional<Prices> prices;
};

/// The priced time of a score (see Ranking::prices), s.
double priced_time_s(const ValidationScore& score, const Ranking::Prices& prices);

/// Whether `a` ranks above `b` (strictly) under `ranking`.
bool ranks_above(const ValidationScore& a, const ValidationScore& b, const Ranking& ranking);

}  // namespace auvrl::eval
