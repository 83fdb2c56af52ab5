// The logger's logic over LCM's in-process transport (memq://): every message of the chosen
// channels reaches the log and is counted per channel; throttled channels are written at most
// once per interval and the rest counted; the heartbeat and the summary tell the same counts;
// rotation by size loses nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/transport.hpp"
#include "logger/event_log.hpp"
#include "logger/logger.hpp"

namespace {

using namespace auvrl;
using namespace auvrl::logger;
namespace fs = std::filesystem;

std::map<std::string, std::int64_t> count_log(const std::string& dir) {
  std::map<std::string, std::int64_t> counts;
  for (const std::string& file : expand_log_paths({dir})) {
    LogReader reader(file);
    LogEvent event;
    while (reader.next(event)) ++counts[event.channel];
    EXPECT_TRUE(reader.damage().empty()) << file;
  }
  return counts;
}

const ChannelCounts* find_channel(const Logger& logger, const std::string& name) {
  for (const ChannelCounts& c : logger.channels()) {
    if (c.channel == name) return &c;
  }
  return nullptr;
}

class LoggerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test_support::make_temp_dir("auvrl_logger_");
    transport_ = transport::make_in_process_transport();
  }
  void TearDown() override { fs::remove_all(dir_); }

  void publish(const std::string& channel, std::size_t size, std::uint8_t fill = 1) {
    std::vector<std::uint8_t> data(size, fill);
    transport_->publish(channel, data.data(), data.size());
  }
  void poll_all(Logger& logger) {
    for (int i = 0; i < 5; ++i) logger.poll(0);
  }

  std::string dir_;
  std::unique_ptr<transport::Transport> transport_;
};

TEST_F(LoggerTest, EveryMessageIsWrittenAndCountedPerChannel) {
  LoggerConfig config;
  config.dir = dir_ + "/logs";
  Logger logger(*transport_, config);
  std::map<std::string, std::int64_t> sent;
  for (int i = 0; i < 600; ++i) {
    const std::string channel = "SIM_STATE_" + std::to_string(i % 3);
    publish(channel, 100 + static_cast<std::size_t>(i));
    ++sent[channel];
    if (i % 50 == 0) poll_all(logger);
  }
  poll_all(logger);
  const std::string summary = logger.finish(nullptr);
  auto logged = count_log(config.dir);
  const std::int64_t heartbeats = logged[channels::kLoggerHeartbeat];
  EXPECT_GE(heartbeats, 1);  // its own heartbeat is traffic too
  logged.erase(channels::kLoggerHeartbeat);
  EXPECT_EQ(logged, sent);
  for (const auto& [channel, count] : sent) {
    const ChannelCounts* c = find_channel(logger, channel);
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->received, count);
    EXPECT_EQ(c->written, count);
    EXPECT_EQ(c->throttled, 0);
  }
  EXPECT_EQ(logger.written(), 600 + heartbeats);
  EXPECT_EQ(logger.write_errors(), 0);

  // The summary names every channel with its counts.
  std::ifstream in(summary);
  ASSERT_TRUE(in) << summary;
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("messages received " + std::to_string(logger.received()) + " written " +
                            std::to_string(logger.written()) + " throttled 0"),
            std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("SIM_STATE_2"), std::string::npos);
  EXPECT_EQ(summary, config.dir + "/lcmlog-0000-summary.txt");
}

TEST_F(LoggerTest, HeartbeatCarriesTheCountsPerChannel) {
  LoggerConfig config;
  config.dir = dir_;
  Logger logger(*transport_, config);
  publish("A", 10);
  publish("B", 20);
  publish("B", 20);
  poll_all(logger);
  const auto hb = logger.heartbeat();
  EXPECT_EQ(hb.log_dir, dir_);
  EXPECT_EQ(hb.files_written, 1);
  EXPECT_EQ(hb.current_file, dir_ + "/lcmlog-0000.lcmlog");
  ASSERT_EQ(hb.num_channels, static_cast<int>(hb.channel.size()));
  std::map<std::string, std::int64_t> written;
  for (int i = 0; i < hb.num_channels; ++i) {
    written[hb.channel[static_cast<std::size_t>(i)]] = hb.written[static_cast<std::size_t>(i)];
    EXPECT_EQ(hb.received[static_cast<std::size_t>(i)],
              hb.written[static_cast<std::size_t>(i)] + hb.throttled[static_cast<std::size_t>(i)]);
  }
  EXPECT_EQ(written["A"], 1);
  EXPECT_EQ(written["B"], 2);
  EXPECT_EQ(hb.messages_received, logger.received());
  EXPECT_EQ(static_cast<std::uint64_t>(hb.bytes_written), logger.writer().bytes_written());
}

TEST_F(LoggerTest, PolicyWeightsAreThrottledByDefaultAndRulesCanChangeIt) {
  LoggerConfig config;
  config.dir = dir_;
  config.throttles = {parse_throttle_rule("FAST_.*=0.2")};
  Logger logger(*transport_, config);
  // 50 weights within a fraction of a second: only the first is written (10 s rule).
  for (int i = 0; i < 50; ++i) {
    publish(channels::kPolicyWeights, 5000, static_cast<std::uint8_t>(i));
    publish(channels::kPolicySummary, 40);  // the small companion is never throttled
  }
  poll_all(logger);
  // FAST_1 at ~100 Hz for ~1 s with a 0.2 s rule: about 5 written.
  const auto start = std::chrono::steady_clock::now();
  int fast_sent = 0;
  while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(1000)) {
    publish("FAST_1", 100);
    ++fast_sent;
    logger.poll(0);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  logger.finish(nullptr);
  const ChannelCounts* weights = find_channel(logger, channels::kPolicyWeights);
  ASSERT_NE(weights, nullptr);
  EXPECT_EQ(weights->received, 50);
  EXPECT_EQ(weights->written, 1);
  EXPECT_EQ(weights->throttled, 49);
  EXPECT_EQ(find_channel(logger, channels::kPolicySummary)->written, 50);
  const ChannelCounts* fast = find_channel(logger, "FAST_1");
  EXPECT_EQ(fast->received, fast_sent);
  EXPECT_GE(fast->written, 4);
  EXPECT_LE(fast->written, 6);
  EXPECT_EQ(fast->written + fast->throttled, fast->received);
  auto logged = count_log(dir_);
  EXPECT_EQ(logged[channels::kPolicyWeights], 1);
  EXPECT_EQ(logged["FAST_1"], fast->written);
  // The one weights message written is the first one.
  LogReader reader(expand_log_paths({dir_}).front());
  LogEvent event;
  while (reader.next(event) && event.channel != channels::kPolicyWeights) {
  }
  EXPECT_EQ(event.data.front(), 0);
}

TEST_F(LoggerTest, ARuleOfZeroTurnsTheDefaultThrottleOff) {
  LoggerConfig config;
  config.dir = dir_;
  config.throttles = {parse_throttle_rule("POLICY_WEIGHTS=0")};
  Logger logger(*transport_, config);
  for (int i = 0; i < 20; ++i) publish(channels::kPolicyWeights, 1000);
  poll_all(logger);
  logger.finish(nullptr);
  EXPECT_EQ(find_channel(logger, channels::kPolicyWeights)->written, 20);
}

TEST_F(LoggerTest, OnlyChannelsMatchingThePatternAreLogged) {
  LoggerConfig config;
  config.dir = dir_;
  config.channels = "SIM_.*";
  Logger logger(*transport_, config);
  publish("SIM_CMD_0", 10);
  publish("OTHER", 10);
  publish("XSIM_CMD_0", 10);  // a full match is needed
  poll_all(logger);
  logger.finish(nullptr);
  const auto logged = count_log(dir_);
  EXPECT_EQ(logged, (std::map<std::string, std::int64_t>{{"SIM_CMD_0", 1}}));
}

TEST_F(LoggerTest, RotatesBySizeWithoutLosingMessages) {
  LoggerConfig config;
  config.dir = dir_;
  config.max_file_mb = 0.05;  // 50 kB
  Logger logger(*transport_, config);
  for (int i = 0; i < 400; ++i) {
    publish("DATA", 1000);
    if (i % 20 == 0) poll_all(logger);
  }
  poll_all(logger);
  logger.finish(nullptr);
  const auto files = expand_log_paths({dir_});
  EXPECT_GE(files.size(), 8u);
  for (const auto& file : files) EXPECT_LE(fs::file_size(file), 50000u) << file;
  EXPECT_EQ(count_log(dir_)["DATA"], 400);
}

TEST_F(LoggerTest, ChannelsBeyondTheLimitAreLoggedAndCountedTogether) {
  LoggerConfig config;
  config.dir = dir_;
  config.max_channels = 10;
  config.throttles = {{"FLOOD_.*", 100.0}};  // would throttle them, one by one
  Logger logger(*transport_, config);
  for (int i = 0; i < 500; ++i) {
    publish("FLOOD_" + std::to_string(i), 8);
    if (i % 50 == 0) poll_all(logger);
  }
  publish("FLOOD_0", 8);  // a channel counted on its own keeps its throttle
  poll_all(logger);
  ASSERT_EQ(logger.channels().size(), 11u);
  const ChannelCounts* other = find_channel(logger, kOtherChannels);
  ASSERT_NE(other, nullptr);
  // The logger's own heartbeat and FLOOD_0..FLOOD_8 fill the ten.
  EXPECT_EQ(other->received, 491);
  EXPECT_EQ(other->written, 491);
  EXPECT_EQ(other->throttled, 0);
  EXPECT_EQ(find_channel(logger, "FLOOD_0")->throttled, 1);
  const auto hb = logger.heartbeat();
  EXPECT_EQ(hb.num_channels, 11);
  logger.finish(nullptr);
  const auto logged = count_log(dir_);
  std::int64_t flood = 0;
  for (const auto& [channel, count] : logged) flood += channel.rfind("FLOOD_", 0) == 0 ? count : 0;
  EXPECT_EQ(flood, 500);  // every distinct channel's message is in the log
  config.max_channels = 0;
  EXPECT_THROW(Logger(*transport_, config), std::invalid_argument);
}

TEST_F(LoggerTest, FlushPeriodPutsEventsOnDiskWhileRunning) {
  LoggerConfig config;
  config.dir = dir_;
  config.flush_period_s = 0.05;
  Logger logger(*transport_, config);
  publish("X", 100);
  logger.poll(0);
  std::this_thread::sleep_for(std::chrono::milliseconds(80));
  logger.poll(0);
  // Readable by another reader before the logger closes the file.
  EXPECT_EQ(count_log(dir_)["X"], 1);
}

TEST(ThrottleRule, ParsesAndRefusesWithClearErrors) {
  const ThrottleRule rule = parse_throttle_rule("A=B=2.5");
  EXPECT_EQ(rule.pattern, "A=B");
  EXPECT_EQ(rule.interval_s, 2.5);
  for (const char* bad : {"POLICY_WEIGHTS", "=3", "X=", "X=-1", "X=abc", "(=1"}) {
    try {
      parse_throttle_rule(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("throttle"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
