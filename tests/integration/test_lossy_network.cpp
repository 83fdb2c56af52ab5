// The LCM system on a lossy loopback (the CI form of scripts/netem.sh): this test's private
// network namespace loses 10 % of UDP datagrams (tc netem with 5 ms +- 5 ms delay where the
// kernel has netem, else an nftables drop rule without delay), and a short auvrl train run
// with actor.lockstep_timeout_ms 10 must not deadlock: lost lockstep commands or states are
// sent again (or the episode ends and the next resets), steps go on to the end, whole
// episodes and their experience reach the learner, and the run stops cleanly on its budget.
// Skipped (with the reason) when neither netem nor nft is available, and when the namespace
// has any interface besides lo: the host's network is never touched.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "child_process.hpp"
#include "run_files.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using test_support::ChildProcess;
using test_support::read_csv;

/// Runs a command, returns its exit status (its output in the log).
int run(const std::vector<std::string>& argv, const std::string& log) {
  ChildProcess p(argv, log);
  return p.wait_for_exit(std::chrono::seconds(20));
}

/// True when this process's network namespace has no interface but lo (scripts/netns.sh's
/// private namespace): nothing done to it can reach the host's network.
bool only_loopback() {
  std::ifstream dev("/proc/self/net/dev");
  std::string line;
  int interfaces = 0;
  for (int n = 0; std::getline(dev, line); ++n) {
    if (n < 2) continue;  // two header lines
    std::istringstream fields(line);
    std::string name;
    fields >> name;
    if (name != "lo:") return false;
    ++interfaces;
  }
  return interfaces == 1;
}

TEST(LossyNetwork, TrainingGoesOnWithTenPercentDatagramLoss) {
  if (!only_loopback()) {
    GTEST_SKIP() << "interfaces besides lo (not in a private network namespace; "
                    "AUVRL_NETWORK=host?): the loss rule would touch the host's network";
  }
  const std::string tmp = test_support::make_temp_dir("auvrl_lossy_");
  std::string impairment;
  if (run({"/usr/sbin/tc", "qdisc", "add", "dev", "lo", "root", "netem", "loss", "10%", "delay",
           "5ms", "5ms"},
          tmp + "/tc.log") == 0) {
    impairment = "netem loss 10% delay 5ms 5ms";
  } else if (fs::exists("/usr/sbin/nft") &&
             run({"/usr/sbin/nft", "add", "table", "inet", "auvrl_loss"}, tmp + "/nft1.log") == 0 &&
             run({"/usr/sbin/nft", "add", "chain", "inet", "auvrl_loss", "in",
                  "{ type filter hook input priority 0; }"},
                 tmp + "/nft2.log") == 0 &&
             run({"/usr/sbin/nft", "add", "rule", "inet", "auvrl_loss", "in", "meta", "l4proto",
                  "udp", "numgen", "random", "mod", "100", "<", "10", "drop"},
                 tmp + "/nft3.log") == 0) {
    impairment = "nftables: 10% of UDP datagrams dropped on input (no netem in this kernel)";
  } else {
    GTEST_SKIP() << "neither tc netem nor nft can impair lo here";
  }
  std::cout << "impairment: " << impairment << "\n";

  // The fast preset with the lockstep timeout for a lossy link: each lost command or state
  // costs one timeout (10 ms instead of the default 200 ms).
  const std::string config = tmp + "/fast_lossy.yaml";
  {
    std::ifstream in(std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml");
    std::ofstream out(config);
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("vehicle:", 0) == 0) {
        line = "vehicle: " + std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
      } else if (line.rfind("actor:", 0) == 0) {
        line += "\n  lockstep_timeout_ms: 10";
      }
      out << line << "\n";
    }
  }
  const std::string dir = tmp + "/run";
  ChildProcess train(
      {test_support::bin_path("auvrl"), "train", "--config", config, "--run-dir", dir, "--network",
       "host", "--actors", "1", "--max-seconds", "30", "--no-eval"},
      dir + ".log");
  const int status = train.wait_for_exit(std::chrono::seconds(120));
  ASSERT_TRUE(WIFEXITED(status)) << train.log();
  EXPECT_EQ(WEXITSTATUS(status), 0) << train.log();
  EXPECT_NE(train.log().find("training budget of"), std::string::npos) << train.log();
  EXPECT_EQ(train.log().find("restarting"), std::string::npos) << "nothing hung: " << train.log();

  // Steps to the end (none in the last 10 s would mean a deadlock), and experience arrives.
  const auto progress = read_csv(fs::path(dir) / "progress.csv");
  ASSERT_FALSE(progress.empty()) << train.log();
  double steps = 0, late_steps = 0;
  for (const auto& row : progress) {
    steps += std::atof(row.at("env_steps_per_s").c_str());
    if (std::atof(row.at("wall_s").c_str()) > 20.0) {
      late_steps += std::atof(row.at("env_steps_per_s").c_str());
    }
  }
  EXPECT_GT(late_steps, 0.0) << "no steps in the last 10 s: " << train.log();
  const auto learner = read_csv(fs::path(dir) / "learner.csv");
  ASSERT_FALSE(learner.empty());
  EXPECT_GT(std::atol(learner.back().at("transitions_received").c_str()), 0);
  const auto episodes = read_csv(fs::path(dir) / "episodes.csv");
  EXPECT_GE(episodes.size(), 3u) << "whole episodes, lockstep retried: " << train.log();
  std::cout << "lossy loopback: " << episodes.size() << " episodes, mean env steps/s "
            << steps / progress.size() << ", transitions received "
            << learner.back().at("transitions_received") << "\n";
}

}  // namespace
