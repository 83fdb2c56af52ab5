#include "launcher/best_policy.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>

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
  const bool keep =
      best_version_ < 0 || eval::ranks_above(score, best_, {max_hold_m_, true, std::nullopt});
  if (keep) {
    best_ = score;
    best_version_ = version;
    nn::save_network_file(best_path(), net);
  }
  quick_eval.add(wall_s, version, score, keep);
}

bool BestPolicyKeeper::best_ranks_above(const std::string& path) const {
  const nn::Mlp last = nn::network_from_bytes(nn::read_file(path), 1);
  return eval::ranks_above(best_, quick_.evaluate(last), {max_hold_m_, true, std::nullopt});
}

void SnapshotReviewer::remove(const PolicySnapshot& snapshot, std::ostream& out) {
  std::error_code ec;
  fs::remove(snapshot.path, ec);
  if (ec) out << "auvrl train: cannot delete " << snapshot.path << ": " << ec.message() << "\n";
}

std::size_t SnapshotReviewer::review(BestPolicyKeeper& keeper, double wall_s,
                                     QuickEvalSink& quick_eval, std::ostream& out,
                                     std::size_t max_count) {
  const std::vector<PolicySnapshot> snapshots = list_snapshots(dir_);
  const std::size_t count = std::min(max_count, snapshots.size());
  for (std::size_t i = 0; i < count; ++i) {
    const PolicySnapshot& snapshot = snapshots[i];
    if (snapshot.updates > last_updates_) {
      last_updates_ = snapshot.updates;
      std::optional<nn::Mlp> net;
      try {
        net.emplace(nn::network_from_bytes(nn::read_file(snapshot.path), 1));
      } catch (const std::exception& e) {
        out << "auvrl train: snapshot " << snapshot.path
            << " is damaged, not evaluated: " << e.what() << "\n";
      }
      try {
        if (net) keeper.consider(*net, snapshot.updates, wall_s, quick_eval);
      } catch (const std::exception& e) {
        out << "auvrl train: quick evaluation of " << snapshot.path << " failed: " << e.what()
            << "\n";
      }
    }
    remove(snapshot, out);
  }
  return count;
}

}  // namespace auvrl::launcher
