#include "launcher/best_policy.hpp"

#include <filesystem>

#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "eval/ranking.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

BestPolicyKeeper::BestPolicyKeeper(const sim::VehicleModel& model, const task::TaskConfig& task,
                                   int suite_episodes, double max_hold_m, std::string run_dir)
    : quick_(model, task, suite_episodes), max_hold_m_(max_hold_m), run_dir_(std::move(run_dir)) {}

std::string BestPolicyKeeper::best_path() const {
  return (fs::path(run_dir_) / "policy_best.nn").string();
}

void BestPolicyKeeper::restore(std::ostream& out) {
  if (!fs::exists(best_path())) return;
  try {
    best_ = quick_.evaluate(nn::network_from_bytes(nn::read_file(best_path()), 1));
    best_version_ = 0;
  } catch (const std::exception& e) {
    out << "auvrl train: " << best_path() << " not used as the best so far: " << e.what() << "\n";
  }
}

void BestPolicyKeeper::consider(const nn::Mlp& net, std::int64_t version, double wall_s,
                                QuickEvalSink& quick_eval) {
  const eval::ValidationScore score = quick_.evaluate(net);
  const bool keep = best_version_ < 0 || eval::ranks_above(score, best_, {max_hold_m_, true});
  if (keep) {
    best_ = score;
    best_version_ = version;
    nn::save_network_file(best_path(), net);
  }
  quick_eval.add(wall_s, version, score, keep);
}

bool BestPolicyKeeper::best_ranks_above(const std::string& path) const {
  const nn::Mlp last = nn::network_from_bytes(nn::read_file(path), 1);
  return eval::ranks_above(best_, quick_.evaluate(last), {max_hold_m_, true});
}

}  // namespace auvrl::launcher
