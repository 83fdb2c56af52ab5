#include "eval/ranking.hpp"

namespace auvrl::eval {

double priced_time_s(const ValidationScore& s, const Ranking::Prices& p) {
  return s.mean_time_s + p.hold_weight * s.mean_hold_m + p.energy_weight * s.mean_energy +
         p.smoothness_weight * s.mean_smoothness;
}

bool ranks_above(const ValidationScore& a, const ValidationScore& b, const Ranking& ranking) {
  if (a.reached != b.reached) return a.reached > b.reached;
  if (ranking.prices) return priced_time_s(a, *ranking.prices) < priced_time_s(b, *ranking.prices);
  const bool a_holds = a.mean_hold_m <= ranking.max_hold_m;
  const bool b_holds = b.mean_hold_m <= ranking.max_hold_m;
  if (a_holds != b_holds) return a_holds;
  if (!a_holds && a.mean_hold_m != b.mean_hold_m) return a.mean_hold_m < b.mean_hold_m;
  if (ranking.worst_ratio_first && a.max_time_ratio != b.max_time_ratio) {
    return a.max_time_ratio < b.max_time_ratio;
  }
  return a.mean_time_s < b.mean_time_s;
}

}  // namespace auvrl::eval
