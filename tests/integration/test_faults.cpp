// Faults under auvrl train (a real run of the fast preset over LCM, inside this test's private
// network namespace), in the order a run meets them: kill -9 of a simulator and of the logger,
// a simulator and the learner that hang (SIGSTOP) and are noticed by their missing heartbeat,
// an actor that hangs. After each the role is back and working; the learner resumes exactly
// the newest checkpoint (update count and replay content as the file holds them); the log
// files the killed logger wrote are readable to their last complete event. Another system's
// simulator heartbeat on the same bus is named once and changes nothing. test_launcher
// covers kill -9 of an actor and of the learner over both transports.
#include <gtest/gtest.h>
#include <signal.h>

#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/transport.hpp"
#include "learner/checkpoint.hpp"
#include "learner/learner_config.hpp"
#include "learner/learner_node.hpp"
#include "logger/event_log.hpp"
#include "run_files.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using test_support::ChildProcess;
using test_support::read_csv;
using test_support::read_pid;
using test_support::read_text;
using test_support::wait_for;

constexpr int kEndSimTimeout = 5;  // episode_report_t::END_SIM_TIMEOUT
/// A process id no process of the run has (beyond Linux's largest, 2^22).
constexpr int kStrangerPid = 99999999;

/// The fast preset with checkpoints every `checkpoint_s` and a hang watch of 8 s; no quick
/// evaluations.
std::string faults_config(const std::string& dir, int checkpoint_s = 2) {
  return test_support::write_preset_copy(
      AUVRL_CONFIG_DIR, "fast", dir + "/fast_faults.yaml", [checkpoint_s](std::string& line) {
        if (line.find("checkpoint_period_s:") != std::string::npos) {
          line = "  checkpoint_period_s: " + std::to_string(checkpoint_s);
        } else if (line.rfind("run:", 0) == 0) {
          line += "\n  heartbeat_timeout_s: 8\n  best_eval_period_s: 100000";
        }
      });
}

/// Whether actor `id` finished an episode that really stepped (not ended by a lockstep
/// timeout) after wall time `after` (the run's wall_s).
bool actor_stepped_after(const fs::path& run, const std::string& id, double after) {
  for (const auto& row : read_csv(run / "episodes.csv")) {
    if (row.at("actor_id") == id && std::atof(row.at("wall_s").c_str()) > after &&
        std::atoi(row.at("end_reason").c_str()) != kEndSimTimeout) {
      return true;
    }
  }
  return false;
}

double last_wall(const fs::path& run) {
  const auto rows = read_csv(run / "episodes.csv");
  return rows.empty() ? 0.0 : std::atof(rows.back().at("wall_s").c_str());
}

std::vector<fs::path> log_files(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".lcmlog") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// The log files a killed logger wrote are readable to their last complete event: damage, if
/// any, only at the very end of the last file (the one being written).
void expect_readable_to_last_event(const std::vector<fs::path>& files) {
  for (const fs::path& file : files) {
    logger::LogReader reader(file.string());
    logger::LogEvent event;
    std::int64_t events = 0;
    while (reader.next(event)) ++events;
    EXPECT_GT(events, 0) << file;
    ASSERT_LE(reader.damage().size(), 1u) << file;
    if (!reader.damage().empty()) {
      const logger::LogDamage& d = reader.damage().front();
      EXPECT_EQ(file, files.back()) << "only the file being written can be torn";
      EXPECT_EQ(d.offset + d.bytes_skipped, reader.file_size()) << file << ": " << d.what;
    }
  }
}

/// The checkpoint in `checkpoint_dir`, read in this process by a learner configured from
/// `config_file`, holds the update count and replay size the resumed learner reported.
void expect_checkpoint_holds(const std::string& config_file, const std::string& checkpoint_dir,
                             std::int64_t updates, std::int64_t transitions) {
  learner::LearnerNodeConfig config;
  learner::read_learner_config_file(config_file, config);
  config.checkpoint_dir = checkpoint_dir;
  config.max_actors = 2;
  auto transport = transport::make_in_process_transport();
  std::ostringstream log;
  learner::LearnerNode node(config, *transport, log);
  node.resume();
  EXPECT_EQ(node.updates(), updates) << log.str();
  EXPECT_EQ(static_cast<std::int64_t>(node.replay().size()), transitions);
  EXPECT_GT(transitions, 0);
}

TEST(LauncherFaults, KilledAndHungProcessesComeBackAndNothingIsLost) {
  const std::string tmp = test_support::make_temp_dir("auvrl_faults_");
  const std::string dir = tmp + "/run";
  const fs::path run(dir);
  ChildProcess train(
      {test_support::bin_path("auvrl"), "train", "--config", faults_config(tmp), "--run-dir", dir,
       "--network", "host", "--actors", "2", "--max-seconds", "240", "--no-eval"},
      dir + ".log");
  const auto pid_of = [&](const std::string& role) {
    return read_pid(run / "processes" / (role + ".pid"));
  };
  const auto launcher_says = [&](const std::string& text) {
    return train.log().find(text) != std::string::npos;
  };
  ASSERT_TRUE(wait_for([&] { return read_csv(run / "episodes.csv").size() >= 10; }, 60))
      << train.log();

  // kill -9 of a simulator: restarted; its actor times out its step, resets and steps again.
  {
    const int sim = pid_of("sim0");
    const double at = last_wall(run);
    ASSERT_EQ(kill(sim, SIGKILL), 0);
    EXPECT_TRUE(wait_for([&] { return launcher_says("sim0 ended (signal 9); restarting"); }, 10))
        << train.log();
    EXPECT_TRUE(wait_for([&] { return actor_stepped_after(run, "0", at + 1.0); }, 30))
        << train.log();
    EXPECT_NE(pid_of("sim0"), sim);
  }

  // kill -9 of the logger: restarted, writing a new file; what it wrote before is readable to
  // its last complete event (damage, if any, only at the very end of the last file).
  {
    const std::vector<fs::path> before = log_files(run / "logs");
    ASSERT_FALSE(before.empty());
    ASSERT_EQ(kill(pid_of("logger"), SIGKILL), 0);
    EXPECT_TRUE(wait_for([&] { return launcher_says("logger ended (signal 9); restarting"); }, 10))
        << train.log();
    EXPECT_TRUE(wait_for([&] { return log_files(run / "logs").size() > before.size(); }, 15))
        << "the restarted logger starts a new file";
    expect_readable_to_last_event(before);
  }

  // A simulator that hangs: its heartbeat stops, the launcher kills and restarts it.
  {
    const int sim = pid_of("sim1");
    const double at = last_wall(run);
    ASSERT_EQ(kill(sim, SIGSTOP), 0);
    EXPECT_TRUE(wait_for([&] { return launcher_says("sim1 silent for"); }, 20)) << train.log();
    EXPECT_TRUE(wait_for([&] { return launcher_says("sim1 ended (signal 9); restarting"); }, 10))
        << train.log();
    EXPECT_TRUE(wait_for([&] { return actor_stepped_after(run, "1", at + 1.0); }, 30))
        << train.log();
  }

  // The learner hangs after a checkpoint: frozen, its newest checkpoint is final; the launcher
  // notices, kills it and the new learner resumes exactly that checkpoint.
  {
    ASSERT_TRUE(
        wait_for([&] { return !learner::list_checkpoints(dir + "/checkpoints").empty(); }, 30));
    ASSERT_EQ(kill(pid_of("learner"), SIGSTOP), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // a rename under way lands
    const learner::CheckpointFile newest = learner::list_checkpoints(dir + "/checkpoints").front();
    const std::string copy_dir = tmp + "/checkpoint_copy";
    fs::create_directories(copy_dir);
    fs::copy_file(newest.path, fs::path(copy_dir) / fs::path(newest.path).filename());

    EXPECT_TRUE(wait_for([&] { return launcher_says("learner silent for"); }, 20)) << train.log();
    std::smatch m;
    const std::regex resumed("resumed from (\\S+) \\((\\d+) updates, (\\d+) transitions");
    ASSERT_TRUE(wait_for(
        [&] {
          const std::string log = read_text(run / "processes" / "learner.log");
          return std::regex_search(log, m, resumed) && m[1] == newest.path;
        },
        40))
        << train.log() << read_text(run / "processes" / "learner.log");
    const std::int64_t resumed_updates = std::stoll(m[2]);
    const std::int64_t resumed_transitions = std::stoll(m[3]);
    EXPECT_EQ(resumed_updates, newest.updates);
    expect_checkpoint_holds(dir + "/config.yaml", copy_dir, newest.updates, resumed_transitions);
  }

  // An actor that hangs: no more episode reports; killed and restarted.
  {
    const double at = last_wall(run);
    ASSERT_EQ(kill(pid_of("actor0"), SIGSTOP), 0);
    EXPECT_TRUE(wait_for([&] { return launcher_says("actor0 silent for"); }, 25)) << train.log();
    EXPECT_TRUE(wait_for([&] { return actor_stepped_after(run, "0", at + 1.0); }, 30))
        << train.log();
  }

  // Another system's simulator on the same bus: named once, counted, and nothing else is
  // (the late messages of the processes the launcher replaced above are its own).
  {
    auto bus = transport::make_transport({});
    auvrl_lcm::sim_heartbeat_t stranger{};
    stranger.pid = kStrangerPid;
    stranger.vehicle_name = "another";
    stranger.steps_per_s = 1e9;
    EXPECT_TRUE(wait_for(
        [&] {
          transport::publish(*bus, channels::kSimHeartbeat, stranger);
          return launcher_says("ignoring");
        },
        10))
        << train.log();
  }

  train.signal(SIGINT);
  const int status = train.wait_for_exit(std::chrono::seconds(90));
  ASSERT_TRUE(WIFEXITED(status)) << train.log();
  EXPECT_EQ(WEXITSTATUS(status), 130) << train.log();
  EXPECT_FALSE(launcher_says("times within")) << "no role gave up: " << train.log();
  const std::string log = train.log();
  EXPECT_NE(log.find("ignoring SIM_HEARTBEAT from process " + std::to_string(kStrangerPid)),
            std::string::npos)
      << log;
  EXPECT_EQ(log.find("ignoring"), log.rfind("ignoring")) << "named once: " << log;
  EXPECT_TRUE(std::regex_search(log, std::regex("ignored +[1-9][0-9]* messages from outside")))
      << log;
  // Its rate and its vehicle were not taken: no mismatch stopped the run, and the status
  // line's rate stayed the run's.
  for (const auto& row : read_csv(run / "progress.csv")) {
    EXPECT_LT(std::stod(row.at("env_steps_per_s")), 1e6);
  }
}

// A learner killed while it wrote its first checkpoint leaves only the temporary file: the
// launcher must restart it afresh (not with --resume, which finds no checkpoint and fails).
TEST(LauncherFaults, LearnerKilledBeforeItsFirstCheckpointStartsAfresh) {
  const std::string tmp = test_support::make_temp_dir("auvrl_faults_first_");
  const std::string dir = tmp + "/run";
  const fs::path run(dir);
  ChildProcess train(
      {test_support::bin_path("auvrl"), "train", "--config", faults_config(tmp, 100000),
       "--run-dir", dir, "--network", "host", "--actors", "1", "--max-seconds", "120", "--no-eval"},
      dir + ".log");
  ASSERT_TRUE(wait_for([&] { return read_csv(run / "episodes.csv").size() >= 5; }, 60))
      << train.log();
  // What a checkpoint write cut short by SIGKILL leaves behind.
  std::ofstream(run / "checkpoints" / "checkpoint-000000000100.ckpt.tmp") << "partial";
  ASSERT_EQ(kill(read_pid(run / "processes" / "learner.pid"), SIGKILL), 0);
  ASSERT_TRUE(
      wait_for([&] { return train.log().find("restarting learner") != std::string::npos; }, 15))
      << train.log();
  // The new learner runs: it reports again, and never fails for want of a checkpoint.
  const std::size_t rows = read_csv(run / "learner.csv").size();
  EXPECT_TRUE(wait_for([&] { return read_csv(run / "learner.csv").size() > rows + 3; }, 30))
      << train.log();
  const std::string learner_log = read_text(run / "processes" / "learner.log");
  EXPECT_EQ(learner_log.find("no checkpoint-"), std::string::npos) << learner_log;
  EXPECT_EQ(train.log().find("learner ended (exit"), std::string::npos) << train.log();
  train.signal(SIGINT);
  EXPECT_GE(train.wait_for_exit(std::chrono::seconds(90)), 0);
}

}  // namespace
