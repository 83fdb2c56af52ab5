// The LCM system on a lossy loopback (the CI form of scripts/netem.sh): this test's private
// network namespace loses 10 % of UDP datagrams and delays the rest 5 ms +- 5 ms (tc netem
// where the kernel has netem, else auv_netdelay on an iptables NFQUEUE rule, else an nftables
// drop rule without delay), and a short auvrl train run (actor.lockstep_timeout_ms 30 with
// the delay, 10 without; 100-step episodes with the delay) must not deadlock: lost lockstep
// commands or states are sent again (or the episode ends and the next resets), steps go on to
// the end, whole episodes and their experience reach the learner, and the run stops cleanly on
// its budget. With auv_netdelay the delays it drew average 5 ms +- 1. Skipped (with the
// reason) when nothing can impair lo, and when the namespace has any interface besides lo: the
// host's network is never touched.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
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
  bool delayed = false;  // 5 ms +- 5 ms each way: round trips up to ~20 ms
  std::unique_ptr<ChildProcess> netdelay;
  const std::string netdelay_bin = test_support::bin_path("auv_netdelay");
  if (run({"/usr/sbin/tc", "qdisc", "add", "dev", "lo", "root", "netem", "loss", "10%", "delay",
           "5ms", "5ms"},
          tmp + "/tc.log") == 0) {
    impairment = "netem loss 10% delay 5ms 5ms";
    delayed = true;
  } else if (fs::exists(netdelay_bin) && fs::exists("/usr/sbin/iptables") &&
             run({"/usr/sbin/iptables", "-A", "OUTPUT", "-o", "lo", "-p", "udp", "-j", "NFQUEUE",
                  "--queue-num", "7", "--queue-bypass"},
                 tmp + "/iptables.log") == 0) {
    netdelay = std::make_unique<ChildProcess>(
        std::vector<std::string>{netdelay_bin, "--queue", "7", "--delay", "5ms", "--jitter", "5ms",
                                 "--loss", "10%", "--seed", "1"},
        tmp + "/netdelay.log");
    for (int i = 0; i < 100 && netdelay->log().find("bound") == std::string::npos; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_NE(netdelay->log().find("bound"), std::string::npos) << netdelay->log();
    impairment = "auv_netdelay (NFQUEUE, no netem in this kernel): loss 10%, delay 5ms +- 5ms";
    delayed = true;
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
    GTEST_SKIP() << "neither tc netem, auv_netdelay with iptables nor nft can impair lo here";
  }
  std::cout << "impairment: " << impairment << "\n";

  // The fast preset with the lockstep timeout for a lossy link: each lost command or state
  // costs one timeout (10 ms instead of the default 200 ms; 30 ms above the delayed round
  // trip). With the delay a step takes ~15 ms: 100-step episodes, so that several end in 30 s.
  const std::string config = test_support::write_preset_copy(
      AUVRL_CONFIG_DIR, "fast", tmp + "/fast_lossy.yaml", [delayed](std::string& line) {
        if (line.rfind("actor:", 0) == 0) {
          line += delayed ? "\n  lockstep_timeout_ms: 30" : "\n  lockstep_timeout_ms: 10";
        } else if (delayed && line.rfind("  max_steps:", 0) == 0) {
          line = "  max_steps: 100";
        }
      });
  const std::string dir = tmp + "/run";
  ChildProcess train(
      {test_support::bin_path("auvrl"), "train", "--config", config, "--run-dir", dir, "--network",
       "host", "--actors", "1", "--max-seconds", "30", "--finetune-iterations", "0", "--no-eval"},
      dir + ".log");
  const int status = train.wait_for_exit(std::chrono::seconds(120));
  ASSERT_TRUE(WIFEXITED(status)) << train.log();
  EXPECT_EQ(WEXITSTATUS(status), 0) << train.log();
  EXPECT_NE(train.log().find("training budget of"), std::string::npos) << train.log();
  // 30 s on a lossy link is far short of the preset's TD3 phase: the log says how far it got.
  EXPECT_NE(train.log().find("of learner.max_updates 300000 updates"), std::string::npos)
      << train.log();
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
  if (netdelay) {
    // The tool drew the delays it was asked for, and dropped some datagrams.
    netdelay->terminate();
    const std::string log = netdelay->log();
    std::cout << log;
    unsigned long long packets = 0, held = 0, dropped = 0;
    double mean_ms = -1;
    const auto at = log.find("auv_netdelay: ", log.find("bound"));
    ASSERT_NE(at, std::string::npos) << log;
    ASSERT_EQ(std::sscanf(log.c_str() + at,
                          "auv_netdelay: %llu packets: %llu delayed (mean %lf ms), %llu dropped",
                          &packets, &held, &mean_ms, &dropped),
              4)
        << log;
    EXPECT_GT(held, 1000u) << log;
    EXPECT_GT(dropped, 0u) << log;
    EXPECT_NEAR(mean_ms, 5.0, 1.0) << log;
  }
  std::cout << "lossy loopback: " << episodes.size() << " episodes, mean env steps/s "
            << steps / progress.size() << ", transitions received "
            << learner.back().at("transitions_received") << "\n";
}

}  // namespace
