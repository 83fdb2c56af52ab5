// A mismatch stops the run at once, with one message naming both sides, through the real
// processes: a simulator serving another vehicle than the run's, a learner of other dimensions
// than its actors, an actor that discards every episode, a policy and a checkpoint of other
// sizes. The launcher is given a bin directory in which one program is wrapped to provoke the
// fault (auvrl train --bin-dir), as a misconfigured installation would.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include "child_process.hpp"
#include "run_files.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using test_support::ChildProcess;
using Clock = std::chrono::steady_clock;

const std::string kConfigDir = AUVRL_CONFIG_DIR;
const std::string kPreset = kConfigDir + "/presets/fast.yaml";

/// A bin directory with the real programs, except `wrapped`: a script that runs the real one
/// with its arguments passed through `rewrite` (a bash fragment over the array "args").
std::string bin_dir_wrapping(const std::string& tmp, const std::string& wrapped,
                             const std::string& rewrite) {
  const fs::path dir = fs::path(tmp) / "bin";
  fs::create_directories(dir);
  for (const char* name : {"auv_sim", "auv_actor", "auv_learner", "auv_logger"}) {
    if (name != wrapped) fs::create_symlink(test_support::bin_path(name), dir / name);
  }
  std::ofstream script(dir / wrapped);
  script << "#!/bin/bash\nargs=(\"$@\")\n"
         << rewrite << "\nexec " << test_support::bin_path(wrapped) << " \"${args[@]}\"\n";
  script.close();
  fs::permissions(dir / wrapped, fs::perms::owner_all);
  return dir.string();
}

/// How an auvrl train run ended.
struct Ending {
  int status = -1;         ///< wait status (-1: still running at the deadline)
  double stopping_s = -1;  ///< when "...; stopping" appeared, s after the start
  double exited_s = -1;    ///< when the launcher exited, s after the start
  std::string stop_line;   ///< the "auvrl train: <reason>; stopping" line
  std::string log;
};

/// Runs auvrl train with `extra` arguments and watches its output until it exits.
Ending train_until_it_stops(const std::string& tmp, const std::vector<std::string>& extra) {
  std::vector<std::string> argv = {test_support::bin_path("auvrl"),
                                   "train",
                                   "--config",
                                   kPreset,
                                   "--run-dir",
                                   tmp + "/run",
                                   "--network",
                                   "host",
                                   "--actors",
                                   "1",
                                   "--max-seconds",
                                   "90",
                                   "--no-eval"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  const auto start = Clock::now();
  ChildProcess train(argv, tmp + "/train.log");
  Ending e;
  const auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  while (seconds() < 60) {
    if (e.stopping_s < 0 && train.log().find("; stopping") != std::string::npos) {
      e.stopping_s = seconds();
    }
    if (!train.running()) {
      e.exited_s = seconds();
      e.status = train.wait_for_exit(std::chrono::milliseconds(0));
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  e.log = train.log();
  std::istringstream lines(e.log);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("; stopping") != std::string::npos) e.stop_line = line;
  }
  std::cout << "[ figures  ] stop line after " << e.stopping_s << " s, exit after " << e.exited_s
            << " s: " << e.stop_line << "\n";
  return e;
}

void expect_failed_promptly(const Ending& e) {
  ASSERT_GE(e.exited_s, 0) << "the run did not stop within 60 s\n" << e.log;
  EXPECT_TRUE(WIFEXITED(e.status) && WEXITSTATUS(e.status) != 0) << e.log;
  // Everything stopped within 2 s of the fault being seen (the final checkpoint included).
  EXPECT_LT(e.exited_s - e.stopping_s, 2.0) << e.log;
  EXPECT_EQ(e.log.find("continue it: auvrl train --resume"), std::string::npos) << e.log;
}

TEST(VehicleMismatch, ASimulatorOfAnotherVehicleStopsTheRunNamingBoth) {
  const std::string tmp = test_support::make_temp_dir("auvrl_mismatch_sim_");
  const std::string other = kConfigDir + "/vehicles/bluerov2_heavy.yaml";
  const std::string bin = bin_dir_wrapping(
      tmp, "auv_sim",
      "for i in \"${!args[@]}\"; do [ \"${args[$i]}\" = --vehicle ] && args[$((i+1))]=" + other +
          "; done");
  const Ending e = train_until_it_stops(tmp, {"--bin-dir", bin});
  expect_failed_promptly(e);
  // The first to see it says it: the actor at its first reset, or the launcher by the
  // simulator's heartbeat. Either names both vehicles, with file and thruster count.
  EXPECT_NE(e.stop_line.find("expects vehicle 'nessie7'"), std::string::npos) << e.log;
  EXPECT_NE(e.stop_line.find("nessie7.yaml: 6 thrusters"), std::string::npos) << e.log;
  EXPECT_NE(e.stop_line.find("'bluerov2_heavy' (8 thrusters"), std::string::npos) << e.log;
  // Within seconds of the start, not at the end of the budget.
  EXPECT_LT(e.exited_s, 20.0) << e.log;
}

TEST(VehicleMismatch, ALearnerOfOtherDimensionsStopsTheRunNamingBoth) {
  const std::string tmp = test_support::make_temp_dir("auvrl_mismatch_learner_");
  // The preset's layout is extended_thrust (29 inputs for six thrusters); this learner's is
  // extended (23).
  const std::string bin = bin_dir_wrapping(tmp, "auv_learner", "args+=(--layout extended)");
  const Ending e = train_until_it_stops(tmp, {"--bin-dir", bin});
  expect_failed_promptly(e);
  // The learner (experience of 29 inputs) or an actor (weights of 23) says it first.
  const bool learner_saw =
      e.stop_line.find(
          "has state 29 and action 6 values; this learner's networks take state "
          "23 and action 6") != std::string::npos;
  const bool actor_saw =
      e.stop_line.find("in=23") != std::string::npos &&
      e.stop_line.find("this actor's task needs in=29 out=6") != std::string::npos;
  EXPECT_TRUE(learner_saw || actor_saw) << e.log;
  EXPECT_NE(e.stop_line.find("'nessie7'"), std::string::npos) << e.log;
  EXPECT_LT(e.exited_s, 30.0) << e.log;
}

TEST(VehicleMismatch, AnActorThatDiscardsEveryEpisodeStopsTheRun) {
  const std::string tmp = test_support::make_temp_dir("auvrl_mismatch_discard_");
  // A vehicle whose blow-up limit is 1 mm/s: every episode ends in a blow-up at its first step,
  // and the actor sends nothing while its simulator answers every step.
  const std::string vehicle = tmp + "/fragile.yaml";
  {
    std::ifstream in(kConfigDir + "/vehicles/nessie7.yaml");
    std::ofstream out(vehicle);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("  max_linear_speed_mps:", 0) == 0) line = "  max_linear_speed_mps: 0.001";
      out << line << "\n";
    }
  }
  const Ending e = train_until_it_stops(tmp, {"--vehicle", vehicle});
  ASSERT_GE(e.exited_s, 0) << e.log;
  EXPECT_TRUE(WIFEXITED(e.status) && WEXITSTATUS(e.status) != 0) << e.log;
  EXPECT_NE(e.stop_line.find("actor0 discarded every episode for 10 s"), std::string::npos)
      << e.log;
  EXPECT_NE(e.stop_line.find("the last ended by blow_up"), std::string::npos) << e.log;
  EXPECT_LT(e.exited_s - e.stopping_s, 2.0) << e.log;
  EXPECT_LT(e.exited_s, 30.0) << e.log;
}

TEST(VehicleMismatch, APolicyOfOtherSizesIsRefusedNamingFileAndVehicle) {
  const std::string tmp = test_support::make_temp_dir("auvrl_mismatch_policy_");
  ChildProcess eval(
      {test_support::bin_path("auvrl"), "eval", "--policy", kConfigDir + "/policies/fast.nn",
       "--vehicle", kConfigDir + "/vehicles/bluerov2_heavy.yaml", "--scenario", "test1", "--out",
       tmp + "/eval"},
      tmp + "/eval.log");
  const int status = eval.wait_for_exit(std::chrono::seconds(30));
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << eval.log();
  EXPECT_NE(eval.log().find("policies/fast.nn (vehicle bluerov2_heavy): a policy with 29 inputs "
                            "fits no state layout for 8 thrusters"),
            std::string::npos)
      << eval.log();
}

TEST(VehicleMismatch, ACheckpointOfOtherSizesStopsTheLearnerNamingBoth) {
  const std::string tmp = test_support::make_temp_dir("auvrl_mismatch_checkpoint_");
  const std::string checkpoints = tmp + "/checkpoints";
  {
    // Nessie VII's learner (18 inputs, 6 outputs) writes its checkpoint as it stops.
    ChildProcess learner({test_support::bin_path("auv_learner"), "--checkpoint-dir", checkpoints,
                          "--hidden", "16-16"},
                         tmp + "/first.log");
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ASSERT_EQ(learner.terminate(), 0) << learner.log();
  }
  const auto start = Clock::now();
  ChildProcess learner(
      {test_support::bin_path("auv_learner"), "--checkpoint-dir", checkpoints, "--hidden", "16-16",
       "--resume", "--vehicle", kConfigDir + "/vehicles/bluerov2_heavy.yaml"},
      tmp + "/second.log");
  const int status = learner.wait_for_exit(std::chrono::seconds(20));
  const double stopped_s = std::chrono::duration<double>(Clock::now() - start).count();
  std::cout << "[ figures  ] the learner stopped " << stopped_s << " s after its start\n";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 78) << learner.log();
  EXPECT_NE(learner.log().find(checkpoints + "/checkpoint-"), std::string::npos) << learner.log();
  EXPECT_NE(learner.log().find("saved by a learner with algo ddpg, state_dim 18, action_dim 6"),
            std::string::npos)
      << learner.log();
  EXPECT_NE(learner.log().find("this learner has algo ddpg, state_dim 20, action_dim 8"),
            std::string::npos)
      << learner.log();
}

}  // namespace
