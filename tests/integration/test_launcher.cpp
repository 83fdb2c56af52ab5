// auvrl train as a real process (inside this test's private network namespace): it supervises
// (an actor killed with SIGKILL is back within seconds; over LCM and over DDS), stops cleanly on
// Ctrl-C with a checkpoint and the policy written, resumes, and a short run of the fast preset
// learns: the evaluated policy does far better than an untrained one.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "child_process.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "eval/evaluation.hpp"
#include "run_files.hpp"
#include "sim/vehicle_model.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using test_support::ChildProcess;
using test_support::read_csv;
using test_support::read_pid;
using test_support::wait_for;

const std::string kPreset = std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml";

/// The fast preset with checkpoints every 2 s (so a killed learner has one to resume from).
std::string quick_checkpoint_config(const std::string& dir) {
  return test_support::write_preset_copy(
      AUVRL_CONFIG_DIR, "fast", dir + "/fast_quick_checkpoints.yaml", [](std::string& line) {
        if (line.find("checkpoint_period_s:") != std::string::npos) {
          line = "  checkpoint_period_s: 2";
        }
      });
}

/// The supervision test runs once per transport (lcm, dds): auvrl train --transport NAME.
class LauncherSupervision : public ::testing::TestWithParam<std::string> {};

TEST_P(LauncherSupervision, RestartsKilledProcessesStopsCleanlyAndResumes) {
  const std::string tmp = test_support::make_temp_dir("auvrl_launcher_");
  const std::string dir = tmp + "/run";
  ChildProcess train(
      {test_support::bin_path("auvrl"), "train", "--config", quick_checkpoint_config(tmp),
       "--run-dir", dir, "--network", "host", "--actors", "2", "--max-seconds", "60", "--no-eval",
       "--transport", GetParam()},
      dir + ".log");
  const auto learner_log = [&] {
    std::ifstream in(fs::path(dir) / "processes" / "learner.log");
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const fs::path run(dir);
  ASSERT_TRUE(wait_for([&] { return read_csv(run / "episodes.csv").size() >= 20; }, 30))
      << train.log();
  // The actors started once the learner and the logger said they listen, not after a wait.
  EXPECT_EQ(train.log().find("not listening"), std::string::npos) << train.log();
  const int actor = read_pid(run / "processes" / "actor0.pid");
  ASSERT_GT(actor, 0);
  ASSERT_EQ(kill(actor, SIGKILL), 0);
  const double killed_at = std::atof(read_csv(run / "episodes.csv").back()["wall_s"].c_str());
  // Back within seconds, and reporting episodes again.
  ASSERT_TRUE(wait_for(
      [&] {
        for (const auto& row : read_csv(run / "episodes.csv")) {
          if (row.at("actor_id") == "0" && std::atof(row.at("wall_s").c_str()) > killed_at + 0.5) {
            return true;
          }
        }
        return false;
      },
      15))
      << train.log();
  EXPECT_NE(train.log().find("actor0 ended (signal 9); restarting"), std::string::npos)
      << train.log();
  EXPECT_NE(read_pid(run / "processes" / "actor0.pid"), actor);

  // The learner killed after its first checkpoint comes back from that checkpoint (a finished
  // one: a learner killed while writing its first leaves only the temporary file and starts
  // afresh, see test_faults).
  const auto finished_checkpoint = [&] {
    for (const auto& e : fs::directory_iterator(run / "checkpoints")) {
      if (e.path().extension() == ".ckpt") return true;
    }
    return false;
  };
  ASSERT_TRUE(wait_for(finished_checkpoint, 20)) << train.log();
  ASSERT_EQ(kill(read_pid(run / "processes" / "learner.pid"), SIGKILL), 0);
  ASSERT_TRUE(wait_for([&] { return learner_log().find("resumed from") != std::string::npos; }, 20))
      << train.log() << learner_log();
  EXPECT_NE(train.log().find("learner ended (signal 9); restarting"), std::string::npos);
  {
    // It resumed a whole checkpoint: the update count restored is the one the file is named
    // after (test_faults also checks the replay content against the file).
    std::smatch m;
    const std::string log = learner_log();
    ASSERT_TRUE(std::regex_search(
        log, m, std::regex("resumed from \\S+checkpoint-0*(\\d+)\\.ckpt \\((\\d+) updates")))
        << log;
    EXPECT_EQ(m[1].str(), m[2].str()) << log;
  }
  // Training goes on after it: more episodes arrive.
  const std::size_t episodes_now = read_csv(run / "episodes.csv").size();
  EXPECT_TRUE(
      wait_for([&] { return read_csv(run / "episodes.csv").size() > episodes_now + 5; }, 20));

  // Ctrl-C: everything stops, the learner checkpoints and writes the policy.
  train.signal(SIGINT);
  const int status = train.wait_for_exit(std::chrono::seconds(60));
  ASSERT_TRUE(WIFEXITED(status)) << train.log();
  EXPECT_EQ(WEXITSTATUS(status), 130) << train.log();
  EXPECT_NE(train.log().find("continue it: auvrl train --resume"), std::string::npos);
  EXPECT_TRUE(fs::exists(run / "policy.nn"));
  EXPECT_FALSE(fs::is_empty(run / "checkpoints"));
  EXPECT_FALSE(fs::is_empty(run / "logs"));
  const auto learner_rows = read_csv(run / "learner.csv");
  ASSERT_FALSE(learner_rows.empty());
  const long updates_before = std::atol(learner_rows.back().at("updates").c_str());

  // --resume continues from the newest checkpoint: wait for the learner to say so, then stop
  // the run (a fixed short budget raced with the learner's start, slower over DDS).
  const auto count_resumes = [&] {
    std::size_t n = 0, pos = 0;
    const std::string log = learner_log();
    while ((pos = log.find("resumed from", pos)) != std::string::npos) ++n, ++pos;
    return n;
  };
  const std::size_t resumes_before = count_resumes();
  ChildProcess resumed({test_support::bin_path("auvrl"), "train", "--resume", dir, "--network",
                        "host", "--max-seconds", "120", "--no-eval", "--transport", GetParam()},
                       dir + "-resume.log");
  EXPECT_TRUE(wait_for([&] { return count_resumes() == resumes_before + 1; }, 60))
      << resumed.log() << learner_log();
  resumed.signal(SIGINT);
  ASSERT_GE(resumed.wait_for_exit(std::chrono::seconds(60)), 0) << resumed.log();
  EXPECT_GT(updates_before, 0);
  EXPECT_NE(train.log().find(GetParam() == "dds" ? "dds domain 0" : "udpm://"), std::string::npos)
      << "the run's transport";
}

INSTANTIATE_TEST_SUITE_P(Transports, LauncherSupervision, ::testing::Values("lcm", "dds"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

TEST(Launcher, AShortRunLearnsFarBeyondTheUntrainedPolicy) {
  const std::string dir = test_support::make_temp_dir("auvrl_launcher_learn_") + "/run";
  ChildProcess train({test_support::bin_path("auvrl"), "train", "--config", kPreset, "--run-dir",
                      dir, "--network", "host", "--max-seconds", "60"},
                     dir + ".log");
  const int status = train.wait_for_exit(std::chrono::seconds(240));
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << train.log();
  const auto rows = read_csv(fs::path(dir) / "eval" / "policy" / "summary.csv");
  int reached = 0, suite = 0;
  double final_error = 0;
  for (const auto& row : rows) {
    if (row.at("scenario") != "suite") continue;
    ++suite;
    reached += row.at("reached") == "1";
    final_error += std::atof(row.at("final_error_m").c_str());
  }
  ASSERT_EQ(suite, 100) << train.log();
  final_error /= suite;
  // The fine-tuning ran after the TD3 phase, every iteration it ran in finetune.csv.
  EXPECT_NE(train.log().find("auvrl train: fine-tuned: objective"), std::string::npos)
      << train.log();
  std::ifstream finetune_csv(fs::path(dir) / "finetune.csv");
  std::string line;
  int finetune_lines = 0;
  while (std::getline(finetune_csv, line)) ++finetune_lines;
  // The preset's iteration count: the first "  iterations: N" after "finetune:".
  std::ifstream preset(kPreset);
  std::stringstream preset_text;
  preset_text << preset.rdbuf();
  std::smatch iterations;
  const std::string text = preset_text.str();
  ASSERT_TRUE(std::regex_search(text, iterations,
                                std::regex(R"(\nfinetune:\n(?:[ ]+#.*\n)*  iterations: (\d+))")))
      << kPreset;
  // A first search that the preset's cap on each search ended early (a busy machine) says
  // where (finetune.csv is the first search's).
  int iterations_run = std::stoi(iterations[1]);
  std::smatch ended;
  const std::string log = train.log();
  if (std::regex_search(
          log, ended,
          std::regex(
              R"(fine-tuning(?: candidate 1/\d+)?: ended after iteration (\d+) of (\d+))"))) {
    EXPECT_EQ(std::stoi(ended[2]), iterations_run) << log;
    iterations_run = std::stoi(ended[1]);
  }
  EXPECT_EQ(finetune_lines, 1 + iterations_run) << "the header and one row per iteration";
  // Beside it, the objective by price: the PID's, the trained policy's, the kept weights'.
  std::ifstream terms_csv(fs::path(dir) / "objective_terms.csv");
  std::stringstream terms;
  terms << terms_csv.rdbuf();
  EXPECT_EQ(terms.str().rfind("controller,objective_s,", 0), 0u) << terms.str();
  EXPECT_NE(terms.str().find("\npid,"), std::string::npos) << terms.str();
  EXPECT_NE(terms.str().find("\nstart,"), std::string::npos) << terms.str();
  EXPECT_EQ(terms.str().find("\nfinetuned,") != std::string::npos,
            train.log().find("  kept: ") != std::string::npos)
      << terms.str() << train.log();

  // The untrained policy: the same architecture, freshly initialised.
  const sim::VehicleModel model =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
  nn::Mlp trained =
      nn::network_from_bytes(nn::read_file((std::filesystem::path(dir) / "policy.nn").string()), 1);
  nn::Mlp untrained(trained.spec(), 1);
  nn::Rng rng(99);
  untrained.init_lillicrap(rng);
  eval::EvaluationConfig config;
  config.task.layout = eval::infer_layout(trained.spec().input_dim, 6);
  agent::PolicyController controller(untrained, config.task.state_dim(), 6);
  const auto baseline =
      eval::run_evaluation(model, config, controller, {eval::Scenario::kSuite}, "");
  int baseline_reached = 0;
  double baseline_error = 0;
  for (const auto& r : baseline) {
    baseline_reached += r.reached;
    baseline_error += r.final_error_m;
  }
  baseline_error /= baseline.size();
  std::cout << "suite reached: trained " << reached << "/100 (mean final error " << final_error
            << " m), untrained " << baseline_reached << "/100 (" << baseline_error << " m)\n";
  EXPECT_GE(reached, baseline_reached + 30);
  EXPECT_LT(final_error, 0.5 * baseline_error);
}

}  // namespace
