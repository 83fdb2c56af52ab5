// auvrl train --reproducible through the real processes (inside this test's private network
// namespace): the same seed gives byte-identical checkpoints, policies and evaluation, another
// seed does not, and a run whose learner or actor is killed with SIGKILL and comes back, or
// that is stopped with Ctrl-C and resumed, ends with the same bytes as the run left alone. Over
// LCM with one actor and two, and over DDS.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "run_files.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using test_support::ChildProcess;
using test_support::read_pid;
using test_support::read_text;
using test_support::wait_for;

constexpr int kMaxUpdates = 20000;

/// The fast preset, short: updates from 2000 transitions on, a checkpoint every 2000 updates
/// and a snapshot for the best policy every 5000.
std::string short_config(const std::string& dir) {
  return test_support::write_preset_copy(
      AUVRL_CONFIG_DIR, "fast", dir + "/fast_short.yaml", [](std::string& line) {
        if (line.find("warmup_transitions:") != std::string::npos) {
          line = "  warmup_transitions: 2000\n  checkpoint_every_updates: 2000";
        }
        if (line.rfind("  max_train_s:", 0) == 0) line = "  best_eval_every_updates: 5000";
      });
}

/// What a run leaves that must be the same bytes from run to run.
struct RunBytes {
  std::string policy;
  std::string last_checkpoint;
  std::string selected;  ///< the evaluated policy's file name and bytes
  std::string summary;   ///< eval/policy/summary.csv
  std::string robustness;
};

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

RunBytes run_bytes(const fs::path& run) {
  RunBytes b;
  b.policy = file_bytes(run / "policy.nn");
  b.last_checkpoint =
      file_bytes(run / "checkpoints" / fmt::format("checkpoint-{:012d}.ckpt", kMaxUpdates));
  std::string name = read_text(run / "eval" / "selected_policy.txt");
  while (!name.empty() && (name.back() == '\n')) name.pop_back();
  b.selected = fs::path(name).filename().string() + ":" + file_bytes(name);
  b.summary = file_bytes(run / "eval" / "policy" / "summary.csv");
  b.robustness = file_bytes(run / "eval" / "policy" / "robustness.csv");
  return b;
}

/// What the run's processes are, and which one to kill once training is under way.
struct RunSpec {
  std::string transport;
  int actors = 1;
  int seed = 1;
  std::string kill;  ///< "", "learner" or "actor0"
};

class ReproducibleRun : public ::testing::TestWithParam<std::pair<std::string, int>> {
 protected:
  /// auvrl train --reproducible's command line for a new run.
  static std::vector<std::string> train_command(const std::string& tmp, const fs::path& run,
                                                const RunSpec& spec) {
    return {test_support::bin_path("auvrl"),
            "train",
            "--config",
            short_config(tmp),
            "--run-dir",
            run.string(),
            "--network",
            "host",
            "--reproducible",
            "--max-updates",
            std::to_string(kMaxUpdates),
            "--seed",
            std::to_string(spec.seed),
            "--actors",
            std::to_string(spec.actors),
            "--finetune-iterations",
            "4",
            "--transport",
            spec.transport};
  }

  /// Runs auvrl train --reproducible to the end; returns the run directory.
  fs::path train(const std::string& tmp, const std::string& name, const RunSpec& spec) {
    const fs::path run = fs::path(tmp) / name;
    ChildProcess train(train_command(tmp, run, spec), run.string() + ".log");
    if (!spec.kill.empty()) kill_once_under_way(run, spec.kill, train);
    const int status = train.wait_for_exit(std::chrono::seconds(240));
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << train.log();
    return run;
  }

  /// Stops a run with Ctrl-C once the learner has checkpointed, then continues it with
  /// `auvrl train --resume RUN` alone (the run keeps its command line's settings).
  fs::path interrupt_and_resume(const std::string& tmp, const std::string& name,
                                const RunSpec& spec) {
    const fs::path run = fs::path(tmp) / name;
    {
      ChildProcess train(train_command(tmp, run, spec), run.string() + ".log");
      EXPECT_TRUE(wait_for([&] { return has_checkpoint(run); }, 120)) << train.log();
      train.signal(SIGINT);
      const int status = train.wait_for_exit(std::chrono::seconds(120));
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 130) << train.log();
    }
    ChildProcess resume(
        {test_support::bin_path("auvrl"), "train", "--resume", run.string(), "--network", "host"},
        run.string() + ".resume.log");
    const int status = resume.wait_for_exit(std::chrono::seconds(240));
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << resume.log();
    EXPECT_NE(read_text(run / "processes" / "learner.log").find("resumed from"), std::string::npos);
    return run;
  }

  static bool has_checkpoint(const fs::path& run) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(run / "checkpoints", ec)) {
      if (e.path().extension() == ".ckpt") return true;
    }
    return false;
  }

  /// Kills `role` with SIGKILL once the learner has written a checkpoint (the learner then
  /// resumes from it; the actor comes back as the same actor) and checks it came back.
  void kill_once_under_way(const fs::path& run, const std::string& role, ChildProcess& train) {
    ASSERT_TRUE(wait_for([&] { return has_checkpoint(run); }, 120)) << train.log();
    const int pid = read_pid(run / "processes" / (role + ".pid"));
    ASSERT_GT(pid, 0);
    ASSERT_EQ(kill(pid, SIGKILL), 0);
    ASSERT_TRUE(wait_for(
        [&] {
          return train.log().find(role + " ended (signal 9); restarting") != std::string::npos;
        },
        30))
        << train.log();
    if (role == "learner") {
      ASSERT_TRUE(wait_for(
          [&] {
            return read_text(run / "processes" / "learner.log").find("resumed from") !=
                   std::string::npos;
          },
          30));
    }
  }
};

void expect_same_bytes(const RunBytes& a, const RunBytes& b, const std::string& what) {
  EXPECT_FALSE(a.policy.empty()) << what;
  EXPECT_FALSE(a.last_checkpoint.empty()) << what;
  EXPECT_FALSE(a.summary.empty()) << what;
  EXPECT_TRUE(a.policy == b.policy) << what << ": policy.nn differs";
  EXPECT_TRUE(a.last_checkpoint == b.last_checkpoint) << what << ": the last checkpoint differs";
  EXPECT_TRUE(a.selected == b.selected) << what << ": the evaluated policy differs";
  EXPECT_TRUE(a.summary == b.summary) << what << ": eval/policy/summary.csv differs";
  EXPECT_TRUE(a.robustness == b.robustness) << what << ": eval/policy/robustness.csv differs";
}

TEST_P(ReproducibleRun, SameSeedSameBytesAlsoAfterAKilledLearnerOrActor) {
  const auto [transport, actors] = GetParam();
  const std::string tmp = test_support::make_temp_dir("auvrl_reproducible_");
  const RunBytes alone = run_bytes(train(tmp, "alone", {transport, actors, 1, ""}));
  const RunBytes again = run_bytes(train(tmp, "again", {transport, actors, 1, ""}));
  expect_same_bytes(alone, again, "the same seed");
  const RunBytes learner = run_bytes(train(tmp, "learner", {transport, actors, 1, "learner"}));
  expect_same_bytes(alone, learner, "the learner killed and resumed");
  const RunBytes actor = run_bytes(train(tmp, "actor", {transport, actors, 1, "actor0"}));
  expect_same_bytes(alone, actor, "an actor killed and restarted");
  if (transport == "lcm" && actors == 1) {
    const RunBytes stopped =
        run_bytes(interrupt_and_resume(tmp, "stopped", {transport, actors, 1, ""}));
    expect_same_bytes(alone, stopped, "stopped with Ctrl-C and resumed");
    const RunBytes other = run_bytes(train(tmp, "other", {transport, actors, 2, ""}));
    EXPECT_FALSE(other.policy.empty());
    EXPECT_TRUE(other.policy != alone.policy) << "seed 2 gave seed 1's policy";
    EXPECT_TRUE(other.summary != alone.summary) << "seed 2 gave seed 1's evaluation";
  }
}

INSTANTIATE_TEST_SUITE_P(Transports, ReproducibleRun,
                         ::testing::Values(std::make_pair(std::string("lcm"), 1),
                                           std::make_pair(std::string("lcm"), 2),
                                           std::make_pair(std::string("dds"), 2)),
                         [](const auto& info) {
                           return info.param.first + "_" + std::to_string(info.param.second) +
                                  "_actors";
                         });

}  // namespace
