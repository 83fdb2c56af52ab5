// auv_logger with auv_sim as real processes in a private network namespace: two clients drive
// two vehicles in lockstep as fast as auv_sim answers (thousands of steps), policy weights are
// sent in a burst; SIGTERM stops the logger. The log must hold exactly what was sent and
// received (per channel), the weights throttled to one; `auv_log export` must give the same
// counts; lcm-logplayer must replay the log so that a subscriber receives it all again.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/sim_client.hpp"
#include "logger/event_log.hpp"
#include "logger/logger.hpp"
#include "logger/sample.hpp"
#include "logger/schema.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;
namespace fs = std::filesystem;
using Counts = std::map<std::string, std::int64_t>;
using Clock = std::chrono::steady_clock;

const std::string kVehicleFile = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
constexpr int kStepsPerVehicle = 1500;

Counts count_log(const std::vector<std::string>& files) {
  Counts counts;
  for (const std::string& file : files) {
    logger::LogReader reader(file);
    logger::LogEvent event;
    while (reader.next(event)) ++counts[event.channel];
    EXPECT_TRUE(reader.damage().empty()) << file << ": " << reader.damage().front().what;
  }
  return counts;
}

/// Rows (lines minus the header) of a CSV file.
std::int64_t csv_rows(const std::string& path) {
  std::ifstream in(path);
  std::int64_t lines = 0;
  std::string line;
  while (std::getline(in, line)) ++lines;
  return lines - 1;
}

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

std::int64_t total(const Counts& counts) {
  std::int64_t n = 0;
  for (const auto& [channel, count] : counts) n += count;
  return n;
}

/// A burst of 20 policy weights (200 kB each) with their small summaries, counted in
/// `published`: the logger throttles the weights to one per 10 s and logs every summary.
void publish_weight_burst(transport::Transport& transport, Counts& published) {
  const logger::Schema schema = logger::Schema::from_directories({logger::default_types_dir()});
  const std::vector<std::uint8_t> summary_bytes =
      logger::make_sample_message(*schema.find_by_name("auvrl_lcm.policy_summary_t"), 1);
  logger::SampleOptions big;
  big.min_variable_length = big.max_variable_length = 200000;  // num_bytes of the network
  const std::vector<std::uint8_t> weights =
      logger::make_sample_message(*schema.find_by_name("auvrl_lcm.policy_weights_t"), 2, big);
  for (int i = 0; i < 20; ++i) {
    transport.publish(channels::kPolicyWeights, weights.data(), weights.size());
    transport.publish(channels::kPolicySummary, summary_bytes.data(), summary_bytes.size());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  published[channels::kPolicyWeights] = 20;
  published[channels::kPolicySummary] = 20;
}

/// auv_log export of `log_dir` (into dir/csv): one CSV per channel, as many rows as the log has
/// messages.
void expect_export_matches(const std::string& log_dir, const std::string& dir,
                           const Counts& logged) {
  const std::string csv_dir = dir + "/csv";
  ChildProcess exporter({test_support::bin_path("auv_log"), "export", log_dir, "--out", csv_dir},
                        dir + "/export.log");
  ASSERT_EQ(exit_code(exporter.wait_for_exit(std::chrono::seconds(60))), 0) << exporter.log();
  for (const auto& [channel, count] : logged) {
    // LCM's multicast self-test message ("lcm self test", no type), sent by a process when it
    // starts receiving, is logged when the logger is already listening; nothing decodes it.
    if (channel == "LCM_SELF_TEST") continue;
    EXPECT_EQ(csv_rows(csv_dir + "/" + channel + ".csv"), count) << channel;
  }
}

/// lcm-logplayer replays the log `files` (joined: the format has no header) to a subscriber on
/// `transport`, which must receive what was logged. auv_sim is gone, so the replayed commands
/// step nothing.
void expect_replay_matches(transport::Transport& transport, const std::vector<std::string>& files,
                           const std::string& dir, const Counts& logged) {
  const std::string joined = dir + "/joined.lcmlog";
  {
    std::ofstream out(joined, std::ios::binary);
    for (const std::string& file : files) out << std::ifstream(file, std::ios::binary).rdbuf();
  }
  Counts replayed;
  transport.subscribe(
      ".*", [&](const transport::RawMessage& raw) { ++replayed[raw.channel]; }, 100000);
  transport.drain();
  replayed.clear();
  ChildProcess player(
      {AUVRL_LCM_LOGPLAYER, "--speed=4", "--lcm-url=udpm://239.255.76.67:7667?ttl=0", joined},
      dir + "/logplayer.log");
  const auto replay_deadline = Clock::now() + std::chrono::seconds(120);
  while (player.running() && Clock::now() < replay_deadline) transport.handle(20);
  ASSERT_FALSE(player.running()) << "lcm-logplayer did not finish";
  const auto tail = Clock::now() + std::chrono::milliseconds(500);
  while (Clock::now() < tail) transport.handle(20);
  EXPECT_EQ(replayed, logged) << player.log();
  std::cout << "[ measured ] lcm-logplayer replayed " << total(replayed) << " of " << total(logged)
            << " messages\n";
}

TEST(LoggerProcess, LogsExactlyWhatWasSentExportsAndReplaysIt) {
  const std::string dir = test_support::make_temp_dir("auvrl_logger_process_");
  const std::string log_dir = dir + "/logs";
  ChildProcess sim({test_support::bin_path("auv_sim"), "--vehicle", kVehicleFile, "--vehicles", "2",
                    "--heartbeat-period", "0.2"},
                   dir + "/auv_sim.log");
  // Small files, so that rotation runs in the real process too.
  ChildProcess logger_process({test_support::bin_path("auv_logger"), "--dir", log_dir,
                               "--max-file-mb", "0.5", "--heartbeat-period", "0.2"},
                              dir + "/auv_logger.log");
  auto transport = transport::make_transport({});

  // Counts of what this client publishes and receives.
  Counts published, received;
  transport->subscribe(
      "SIM_STATE_[0-9]+", [&](const transport::RawMessage& raw) { ++received[raw.channel]; },
      100000);
  transport::Latest<auvrl_lcm::logger_heartbeat_t> logger_heartbeat(*transport,
                                                                    channels::kLoggerHeartbeat);
  transport::Latest<auvrl_lcm::sim_heartbeat_t> sim_heartbeat(*transport, channels::kSimHeartbeat);
  // Both processes are up and listening once their heartbeats arrive.
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  bool logger_up = false, sim_up = false;
  while (Clock::now() < deadline && !(logger_up && sim_up)) {
    transport->handle(50);
    logger_up = logger_up || logger_heartbeat.take().has_value();
    sim_up = sim_up || sim_heartbeat.take().has_value();
  }
  ASSERT_TRUE(logger_up) << logger_process.log();
  ASSERT_TRUE(sim_up) << sim.log();

  // Lockstep on two vehicles, alternating, as fast as the sim answers.
  SimClient client0(*transport, 0), client1(*transport, 1);
  auvrl_lcm::vehicle_reset_t reset{};
  reset.position_ned_m[2] = 5.0;
  const auto drive_start = Clock::now();
  ASSERT_TRUE(client0.reset(reset).has_value());
  ASSERT_TRUE(client1.reset(reset).has_value());
  std::vector<double> thrust(6, 0.0);
  for (int k = 0; k < kStepsPerVehicle; ++k) {
    for (double& f : thrust) f = 20.0 * std::sin(0.01 * k);
    ASSERT_TRUE(client0.step(thrust).has_value()) << "step " << k;
    ASSERT_TRUE(client1.step(thrust).has_value()) << "step " << k;
  }
  const double drive_s = std::chrono::duration<double>(Clock::now() - drive_start).count();
  // Every publication, retries included (a retry is a message on the wire too; the logger
  // must have it). Without retries: one reset and kStepsPerVehicle commands per vehicle.
  EXPECT_EQ(client0.retries() + client1.retries(), 0) << "auv_sim missed answers";
  published[channels::sim_reset(0)] = 1;
  published[channels::sim_reset(1)] = 1;
  published[channels::sim_command(0)] = kStepsPerVehicle;
  published[channels::sim_command(1)] = kStepsPerVehicle;
  publish_weight_burst(*transport, published);
  // States still in flight are collected, then the logger is stopped.
  const auto settle = Clock::now() + std::chrono::milliseconds(500);
  while (Clock::now() < settle) transport->handle(20);
  const int status = logger_process.terminate(std::chrono::seconds(10));
  ASSERT_EQ(exit_code(status), 0) << logger_process.log();
  sim.terminate();

  const auto files = logger::expand_log_paths({log_dir});
  EXPECT_GE(files.size(), 2u) << "rotation at 0.5 MB expected";
  Counts logged = count_log(files);
  for (const auto& [channel, count] : published) {
    if (channel == channels::kPolicyWeights) continue;
    EXPECT_EQ(logged[channel], count) << channel;
  }
  EXPECT_EQ(logged[channels::kPolicyWeights], 1);
  for (const auto& [channel, count] : received) EXPECT_EQ(logged[channel], count) << channel;
  EXPECT_EQ(received[channels::sim_state(0)], kStepsPerVehicle + 1);
  EXPECT_EQ(received[channels::sim_state(1)], kStepsPerVehicle + 1);
  EXPECT_GE(logged[channels::kSimHeartbeat], 1);
  EXPECT_GE(logged[channels::kLoggerHeartbeat], 1);

  // The summary agrees: for each channel, received = written + throttled, nothing failed.
  std::ifstream summary_file(log_dir + "/lcmlog-0000-summary.txt");
  ASSERT_TRUE(summary_file) << logger_process.log();
  std::stringstream summary;
  summary << summary_file.rdbuf();
  const std::int64_t total_logged = total(logged);
  EXPECT_NE(summary.str().find("written " + std::to_string(total_logged) +
                               " throttled 19 "
                               "write_errors 0"),
            std::string::npos)
      << summary.str();
  EXPECT_NE(summary.str().find("auvrl_lcm.thruster_cmd_t"), std::string::npos) << summary.str();
  std::cout << "[ measured ] lockstep " << 2 * kStepsPerVehicle << " steps in " << drive_s << " s ("
            << 2 * kStepsPerVehicle / drive_s << " steps/s); retries "
            << client0.retries() + client1.retries() << "; logger wrote " << total_logged
            << " messages in " << files.size() << " files\n"
            << summary.str();

  expect_export_matches(log_dir, dir, logged);
  expect_replay_matches(*transport, files, dir, logged);
  fs::remove_all(dir);
}

}  // namespace
