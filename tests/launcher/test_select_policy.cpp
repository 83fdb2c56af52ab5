// The select stage after training: of the last policy and the best the quick evaluation saw,
// the one with fewer flips and blow-ups on the selection draw of the robustness suite, even
// where the quick evaluation ranks the other above it. The pair in data/ is a real one: an
// asynchronous run of the fast preset (`auvrl train --seed 3`, 2026-11-29) whose kept snapshot
// (234350 updates) flips on deep dives and whose last weights do not. With weight averaging
// (learner.average_window_updates) the learner's mean goes on unless that one fails less.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "child_process.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "launcher/best_policy.hpp"
#include "launcher/pipeline.hpp"
#include "launcher/run_config.hpp"
#include "run_files.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {
namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(AUVRL_SOURCE_DIR) + "/tests/launcher/data/";

/// A run directory whose policy.nn is `last` and whose best seen policy is `best`, as the
/// quick evaluation of the fast preset keeps it.
class SelectPolicyTest : public ::testing::Test {
 protected:
  SelectPolicyTest()
      : rc_(read_run_config(std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml")),
        model_(sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml")),
        run_(test_support::make_temp_dir("auvrl_select_")) {
    task::apply_vehicle(model_.facts(), rc_.task);
  }
  BestPolicyKeeper keeper(const std::string& last, const std::string& best) {
    fs::copy_file(last, run_ / "policy.nn");
    BestPolicyKeeper kept(model_, rc_.task, rc_.run.best_eval_suite, rc_.run.best_eval_max_hold_m,
                          run_.string());
    QuickEvalSink sink((run_ / "quick_eval.csv").string());
    kept.consider(nn::network_from_bytes(nn::read_file(best), 1), 234350, 1.0, sink);
    return kept;
  }
  SelectionDraw draw(std::uint64_t seed) const { return {model_, rc_.task, seed}; }

  RunConfig rc_;
  sim::VehicleModel model_;
  fs::path run_;
};

TEST_F(SelectPolicyTest, FewerFailuresOnTheSelectionDrawWinOverTheQuickEvaluation) {
  const BestPolicyKeeper kept =
      keeper(kData + "async_seed3_last.nn", kData + "async_seed3_best.nn");
  // The quick evaluation's few way-points rank the flipping snapshot above the last weights.
  ASSERT_TRUE(kept.best_ranks_above((run_ / "policy.nn").string()));
  std::ostringstream out;
  const auto selected =
      select_policy(run_.string(), kept, draw(rc_.finetune.selection_seed), false, out);
  ASSERT_TRUE(selected);
  EXPECT_EQ(*selected, (run_ / "policy.nn").string()) << out.str();
  EXPECT_NE(out.str().find("selected policy.nn: flips and blow-ups in the robustness suite at "
                           "seed 7890: policy_best.nn 6, policy.nn 0"),
            std::string::npos)
      << out.str();
}

TEST_F(SelectPolicyTest, TheSameWeightsAreNotCountedAndTheEvaluationsDrawIsRefused) {
  {
    const BestPolicyKeeper kept =
        keeper(kData + "async_seed3_best.nn", kData + "async_seed3_best.nn");
    std::ostringstream out;
    const auto selected = select_policy(run_.string(), kept, draw(7890), false, out);
    ASSERT_TRUE(selected);
    EXPECT_EQ(out.str(), "");  // one policy: nothing to count
  }
  fs::remove(run_ / "policy.nn");
  const BestPolicyKeeper kept =
      keeper(kData + "async_seed3_last.nn", kData + "async_seed3_best.nn");
  std::ostringstream out;
  const auto selected = select_policy(run_.string(), kept, draw(1), false, out);
  ASSERT_TRUE(selected);
  // Seed 1 is the evaluation's own draw: not counted there; the quick evaluation's choice stays.
  EXPECT_EQ(*selected, kept.best_path());
  EXPECT_NE(out.str().find("failures not counted"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("evaluation's own draw"), std::string::npos) << out.str();
}

TEST_F(SelectPolicyTest, TheWeightAverageGoesOnUnlessItFailsMoreOnTheSelectionDraw) {
  const BestPolicyKeeper kept =
      keeper(kData + "async_seed3_last.nn", kData + "async_seed3_best.nn");
  {
    std::ostringstream out;  // averaging on, but no average written (a short run): as before
    const auto selected = select_policy(run_.string(), kept, draw(7890), true, out);
    ASSERT_TRUE(selected);
    EXPECT_EQ(*selected, (run_ / "policy.nn").string()) << out.str();
  }
  // A mean that flips where the last weights do not: the last weights.
  fs::copy_file(kData + "async_seed3_best.nn", run_ / kAveragePolicyFile);
  {
    std::ostringstream out;
    const auto selected = select_policy(run_.string(), kept, draw(7890), true, out);
    ASSERT_TRUE(selected);
    EXPECT_EQ(*selected, (run_ / "policy.nn").string());
    EXPECT_NE(out.str().find("selected policy.nn: flips and blow-ups in the robustness suite at "
                             "seed 7890: policy_average.nn 6, policy.nn 0"),
              std::string::npos)
        << out.str();
  }
  // A mean that fails no more often: the mean.
  fs::copy_file(kData + "async_seed3_last.nn", run_ / kAveragePolicyFile,
                fs::copy_options::overwrite_existing);
  std::ostringstream out;
  const auto selected = select_policy(run_.string(), kept, draw(7890), true, out);
  ASSERT_TRUE(selected);
  EXPECT_EQ(*selected, (run_ / kAveragePolicyFile).string()) << out.str();
  std::ostringstream off;  // averaging off: a stale file from another configuration is not used
  EXPECT_EQ(*select_policy(run_.string(), kept, draw(7890), false, off),
            (run_ / "policy.nn").string());
}

}  // namespace
}  // namespace auvrl::launcher
