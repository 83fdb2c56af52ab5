// The Cyclone DDS transport (runs inside scripts/netns.sh: DDS opens sockets on lo). In one
// process (two transports in one domain) and across processes (tests/common/dds_peer.cpp):
// regex filtering, large messages, back-pressure without loss on the queue class, the newest
// weights for a late joiner without a request, configuration errors and the off-host refusal.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/transport.hpp"
#include "common/transport_dds.hpp"

namespace {

using namespace auvrl;
using transport::RawMessage;
using transport::TransportConfig;
using transport::TransportError;
using Clock = std::chrono::steady_clock;

TransportConfig dds_config(int domain = 0) {
  TransportConfig c;
  c.kind = transport::TransportKind::kDds;
  c.dds.domain_id = domain;
  return c;
}

std::vector<std::uint8_t> message(std::int64_t version, std::size_t size) {
  std::vector<std::uint8_t> bytes(std::max(size, sizeof version));
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  std::memcpy(bytes.data(), &version, sizeof version);
  return bytes;
}

std::int64_t version_of(const RawMessage& m) {
  std::int64_t v = -1;
  if (m.size >= sizeof v) std::memcpy(&v, m.data, sizeof v);
  return v;
}

/// Handles t until done() or timeout; true if done.
template <class Done>
bool handle_until(transport::Transport& t, Done done, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!done() && Clock::now() < deadline) t.handle(10);
  return done();
}

/// The names of the topics a subscription to regex reads.
std::vector<std::string> topics_of(const std::string& regex) {
  std::vector<std::string> names;
  for (int t : transport::topics_possibly_matching(regex)) {
    names.push_back(channels::kDdsTopics[t].name);
  }
  return names;
}

TEST(DdsTransport, TopicsOfARegex) {
  using channels::ChannelClass;
  using V = std::vector<std::string>;
  EXPECT_EQ(topics_of(".*").size(), static_cast<std::size_t>(channels::kDdsTopicCount));
  EXPECT_EQ(topics_of(channels::kSimCommandPattern), V{"auvrl_sim_command"});
  EXPECT_EQ(topics_of(channels::sim_state(3)), V{"auvrl_sim_state"});
  EXPECT_EQ(topics_of(channels::kPolicyWeights), V{"auvrl_weights"});
  EXPECT_EQ(topics_of(channels::kExperience), V{"auvrl_experience"});
  EXPECT_EQ(topics_of(channels::kLearnerStats), V{"auvrl_learner_stats"});
  EXPECT_EQ(topics_of(channels::kMissionStatus), V{"auvrl_mission_status"});
  EXPECT_EQ(topics_of(channels::mission(2)), V{"auvrl_mission"});
  // The families of SIM_ and the topic of channels of no family.
  EXPECT_EQ(topics_of("SIM_.*"), (V{"auvrl_sim_command", "auvrl_sim_reset", "auvrl_sim_state",
                                    "auvrl_sim_event", "auvrl_heartbeat", "auvrl_other"}));
  EXPECT_EQ(topics_of("MY_CHANNEL"), V{"auvrl_other"});
  // An optional character shortens the literal prefix; an alternation gives each branch's.
  EXPECT_EQ(topics_of("POLICY_WEIGHTS?"), V{"auvrl_weights"});
  EXPECT_EQ(topics_of("EXPERIENCE|LEARNER_STATS"), (V{"auvrl_experience", "auvrl_learner_stats"}));
  EXPECT_EQ(topics_of("(POLICY_WEIGHTS|SIM_HEARTBEAT)"), (V{"auvrl_weights", "auvrl_heartbeat"}));
  EXPECT_EQ(topics_of("(EPISODE)|(SIM_STATE_[0-9]+)"), (V{"auvrl_experience", "auvrl_sim_state"}));
  EXPECT_EQ(topics_of("EPISODE|[|]").size(), static_cast<std::size_t>(channels::kDdsTopicCount));
  EXPECT_EQ(topics_of("SIM_(CMD|STATE)_1").size(),
            static_cast<std::size_t>(channels::kDdsTopicCount))
      << "nested: everything";
  // Every channel of the system is on a topic of its family (none on auvrl_other).
  for (const std::string& c :
       {channels::kPolicySummary, channels::kEpisode, channels::kWeightsRequest,
        channels::sim_reset(1), channels::sim_fault(1), channels::sim_current(1),
        channels::kSimHeartbeat, channels::kLoggerHeartbeat}) {
    EXPECT_NE(channels::dds_topic_of(c), channels::kOtherDdsTopic) << c;
    EXPECT_EQ(topics_of(c).size(), 1u) << c;
  }
  EXPECT_EQ(channels::channel_class(channels::kPolicySummary), ChannelClass::kState);
  EXPECT_EQ(channels::channel_class(channels::kWeightsRequest), ChannelClass::kQueue);
  EXPECT_EQ(channels::channel_class(channels::sim_fault(12)), ChannelClass::kLockstep);
  EXPECT_EQ(channels::channel_class(channels::kSimHeartbeat), ChannelClass::kOther);
}

TEST(DdsTransport, RoundTripOnMatchingChannelsOnlyInOneProcess) {
  auto a = transport::make_transport(dds_config());
  auto b = transport::make_transport(dds_config());
  std::vector<std::pair<std::string, std::int64_t>> got;
  b->subscribe("SIM_CMD_[0-9]+",
               [&](const RawMessage& m) { got.emplace_back(m.channel, version_of(m)); });
  std::vector<std::string> all;
  b->subscribe(".*", [&](const RawMessage& m) { all.push_back(m.channel); });
  // Every class, and channels the first regex does not fully match.
  for (const std::string ch : {"SIM_CMD_2", "SIM_STATE_2", "SIM_CMD_2x", "POLICY_SUMMARY",
                               "EXPERIENCE", "LEARNER_STATS", "SIM_CMD_15"}) {
    const auto bytes = message(static_cast<std::int64_t>(ch.size()), 64);
    a->publish(ch, bytes.data(), bytes.size());
  }
  ASSERT_TRUE(handle_until(
      *b, [&] { return all.size() >= 7 && got.size() >= 2; }, std::chrono::seconds(5)))
      << "got " << got.size() << ", all " << all.size();
  EXPECT_EQ(got, (std::vector<std::pair<std::string, std::int64_t>>{{"SIM_CMD_2", 9},
                                                                    {"SIM_CMD_15", 10}}));
  b->handle(100);
  EXPECT_EQ(all.size(), 7u) << "each message once, to each matching subscription";
}

TEST(DdsTransport, TypedHelpersAndUnsubscribe) {
  auto t = transport::make_transport(dds_config());
  int calls = 0;
  const auto id = t->subscribe("LEARNER_STATS", [&](const RawMessage&) { ++calls; });
  const auto bytes = message(1, 16);
  t->publish("LEARNER_STATS", bytes.data(), bytes.size());
  ASSERT_TRUE(handle_until(
      *t, [&] { return calls == 1; }, std::chrono::seconds(5)));
  t->unsubscribe(id);
  t->publish("LEARNER_STATS", bytes.data(), bytes.size());
  t->handle(200);
  EXPECT_EQ(calls, 1);
  EXPECT_FALSE(t->handle_one(0));
}

TEST(DdsTransport, LargeMessageArrivesIntact) {
  auto a = transport::make_transport(dds_config());
  auto b = transport::make_transport(dds_config());
  const auto sent = message(42, 500 * 1024);
  std::vector<std::uint8_t> received;
  b->subscribe(channels::kPolicyWeights,
               [&](const RawMessage& m) { received.assign(m.data, m.data + m.size); });
  a->publish(channels::kPolicyWeights, sent.data(), sent.size());
  ASSERT_TRUE(handle_until(
      *b, [&] { return !received.empty(); }, std::chrono::seconds(5)));
  EXPECT_EQ(received, sent);
}

TEST(DdsTransport, QueueClassWaitsForASlowReaderInsteadOfLosing) {
  // A reader holding at most 20 messages, drained slowly in its own thread, and a writer
  // publishing 2000 as fast as it can: every one arrives, in order.
  constexpr int kMessages = 2000;
  std::atomic<bool> ready{false};
  std::vector<std::int64_t> got;
  std::thread reader([&] {
    auto b = transport::make_transport(dds_config());
    b->subscribe(
        channels::kExperience, [&](const RawMessage& m) { got.push_back(version_of(m)); }, 20);
    ready = true;
    const auto deadline = Clock::now() + std::chrono::seconds(30);
    while (static_cast<int>(got.size()) < kMessages && Clock::now() < deadline) {
      if (b->handle_one(10) && got.size() % 100 == 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // falls behind
      }
    }
  });
  while (!ready) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  auto a = transport::make_transport(dds_config());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // discovery in the process
  for (int i = 0; i < kMessages; ++i) {
    const auto bytes = message(i, 1000);
    a->publish(channels::kExperience, bytes.data(), bytes.size());
  }
  reader.join();
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kMessages));
  for (int i = 0; i < kMessages; ++i) ASSERT_EQ(got[static_cast<std::size_t>(i)], i);
}

TEST(DdsTransport, LateJoinerGetsOnlyTheNewestStateWithoutAsking) {
  auto a = transport::make_transport(dds_config());
  for (int v = 1; v <= 100; ++v) {
    const auto bytes = message(v, 1000);
    a->publish(channels::kPolicyWeights, bytes.data(), bytes.size());
  }
  // A volatile channel's old messages are gone for a late joiner.
  const auto stats = message(7, 100);
  a->publish(channels::kLearnerStats, stats.data(), stats.size());
  auto b = transport::make_transport(dds_config());
  std::vector<std::int64_t> versions;
  int stats_seen = 0;
  b->subscribe(channels::kPolicyWeights,
               [&](const RawMessage& m) { versions.push_back(version_of(m)); });
  b->subscribe(channels::kLearnerStats, [&](const RawMessage&) { ++stats_seen; });
  ASSERT_TRUE(handle_until(
      *b, [&] { return !versions.empty(); }, std::chrono::seconds(5)));
  b->handle(200);
  EXPECT_EQ(versions, std::vector<std::int64_t>{100});
  EXPECT_EQ(stats_seen, 0);
}

TEST(DdsTransport, LatestHelperKeepsTheNewest) {
  auto a = transport::make_transport(dds_config());
  auto b = transport::make_transport(dds_config());
  std::int64_t newest = 0, count = 0;
  b->subscribe(channels::kPolicySummary, [&](const RawMessage& m) {
    newest = version_of(m);
    ++count;
  });
  for (int v = 1; v <= 50; ++v) {
    const auto bytes = message(v, 100);
    a->publish(channels::kPolicySummary, bytes.data(), bytes.size());
  }
  ASSERT_TRUE(handle_until(
      *b, [&] { return newest == 50; }, std::chrono::seconds(5)));
  EXPECT_LE(count, 50);
}

TEST(DdsTransport, BadConfigurationsAreErrors) {
  TransportConfig c = dds_config(233);
  EXPECT_THROW(transport::make_transport(c), TransportError) << "domain id out of range";
  c = dds_config();
  c.dds.peers.clear();
  EXPECT_THROW(transport::make_transport(c), TransportError) << "no peers";
  c = dds_config();
  c.dds.peers = {"127.0.0.1\"/><Peer address=\"x"};
  EXPECT_THROW(transport::make_transport(c), TransportError) << "XML in a peer";
  c = dds_config(7);
  c.allow_off_host = true;
  c.dds.config_path = "/nonexistent/cyclone.xml";
  EXPECT_THROW(transport::make_transport(c), TransportError) << "missing file";
  const std::string dir = test_support::make_temp_dir("auvrl_dds_config_");
  std::ofstream(dir + "/bad.xml") << "<CycloneDDS><Domain><NoSuchElement>1</NoSuchElement>";
  c.dds.config_path = dir + "/bad.xml";
  EXPECT_THROW(transport::make_transport(c), TransportError) << "broken XML";
  auto t = transport::make_transport(dds_config());
  EXPECT_THROW(t->subscribe("SIM_(", [](const RawMessage&) {}), TransportError);
  EXPECT_THROW(transport::parse_transport_kind("zeromq"), TransportError);
}

TEST(DdsTransport, AGoodConfigurationFileIsUsed) {
  const std::string dir = test_support::make_temp_dir("auvrl_dds_config_");
  transport::DdsSettings settings;
  std::ofstream(dir + "/cyclone.xml") << transport::dds_default_config_xml(settings);
  TransportConfig c = dds_config(3);
  c.dds.config_path = dir + "/cyclone.xml";
  EXPECT_THROW(transport::make_transport(c), TransportError) << "a file needs --allow-off-host";
  c.allow_off_host = true;
  auto a = transport::make_transport(c);
  auto b = transport::make_transport(c);
  int got = 0;
  b->subscribe("X", [&](const RawMessage&) { ++got; });
  const auto bytes = message(1, 10);
  a->publish("X", bytes.data(), bytes.size());
  EXPECT_TRUE(handle_until(
      *b, [&] { return got == 1; }, std::chrono::seconds(5)));
}

TEST(DdsTransport, RefusesPeersOffThisHost) {
  using transport::check_dds_settings;
  transport::DdsSettings s;
  EXPECT_NO_THROW(check_dds_settings(s, false));
  s.peers = {"127.0.0.1", "localhost", "::1"};
  EXPECT_NO_THROW(check_dds_settings(s, false));
  s.peers = {"127.0.0.1", "10.0.0.2"};
  EXPECT_THROW(check_dds_settings(s, false), TransportError);
  EXPECT_NO_THROW(check_dds_settings(s, true));
  TransportConfig c = dds_config();
  c.dds.peers = {"192.168.1.20"};
  EXPECT_THROW(transport::make_transport(c), TransportError);
  // Off-host peers: Cyclone chooses the interface (not lo).
  EXPECT_EQ(transport::dds_default_config_xml(s).find("name=\"lo\""), std::string::npos);
  EXPECT_NE(transport::dds_default_config_xml({}).find("<NetworkInterface name=\"lo\"/>"),
            std::string::npos);
}

TEST(DdsTransport, DescribeNamesTheTransport) {
  TransportConfig c = dds_config(4);
  c.dds.peers = {"127.0.0.1", "127.0.0.2"};
  EXPECT_EQ(transport::describe(c), "dds domain 4, peers 127.0.0.1,127.0.0.2");
  EXPECT_EQ(transport::describe(TransportConfig{}), transport::kDefaultLcmUrl);
}

TEST(DdsTransportProcesses, RoundTripThroughAnotherProcess) {
  const std::string dir = test_support::make_temp_dir("auvrl_dds_peer_");
  auto t = transport::make_transport(dds_config());
  std::vector<std::vector<std::uint8_t>> echoed;
  t->subscribe("PONG", [&](const RawMessage& m) { echoed.emplace_back(m.data, m.data + m.size); });
  test_support::ChildProcess peer(
      {test_support::bin_path("dds_peer"), "echo", "PING_[0-9]+", "PONG"}, dir + "/peer.log");
  // Keep asking until the peer has been discovered and answers (no lost first message is
  // promised before discovery, as with LCM before a subscriber starts).
  const auto small = message(1, 200);
  ASSERT_TRUE(handle_until(
      *t,
      [&] {
        if (echoed.empty()) t->publish("PING_1", small.data(), small.size());
        return !echoed.empty();
      },
      std::chrono::seconds(10)))
      << peer.log();
  echoed.clear();
  const auto large = message(2, 500 * 1024);
  const auto unmatched = message(3, 200);
  t->publish("PING_22", large.data(), large.size());
  t->publish("PING_X", unmatched.data(), unmatched.size());  // not matched by the peer
  const auto large_echoed = [&] { return std::count(echoed.begin(), echoed.end(), large); };
  ASSERT_TRUE(handle_until(
      *t, [&] { return large_echoed() > 0; }, std::chrono::seconds(5)));
  t->handle(200);
  EXPECT_EQ(large_echoed(), 1);
  EXPECT_EQ(std::count(echoed.begin(), echoed.end(), unmatched), 0);
  // Anything else is a late echo of a discovery ping sent before the first echo came back.
  EXPECT_EQ(static_cast<std::size_t>(large_echoed()) +
                static_cast<std::size_t>(std::count(echoed.begin(), echoed.end(), small)),
            echoed.size());
  EXPECT_EQ(peer.terminate(), 0) << peer.log();
}

TEST(DdsTransportProcesses, LateJoiningProcessGetsTheNewestWeightsWithoutAsking) {
  const std::string dir = test_support::make_temp_dir("auvrl_dds_late_");
  auto t = transport::make_transport(dds_config());
  // 100 versions of ~500 kB weights before the late joiner exists.
  for (int v = 1; v <= 100; ++v) {
    const auto bytes = message(v, 500 * 1024);
    t->publish(channels::kPolicyWeights, bytes.data(), bytes.size());
  }
  test_support::ChildProcess late(
      {test_support::bin_path("dds_peer"), "latest", channels::kPolicyWeights, "5000"},
      dir + "/late.log");
  int status = -1;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (status == -1 && Clock::now() < deadline) {
    t->handle(20);  // this process keeps serving (it is the writer)
    status = late.wait_for_exit(std::chrono::milliseconds(0));
  }
  const std::string log = late.log();
  EXPECT_EQ(status, 0) << log;
  EXPECT_NE(log.find("count=1 size=512000 version=100"), std::string::npos) << log;
  std::cout << "late joiner: " << log;
}

TEST(DdsTransportProcesses, WeightsDoNotWaitForAKilledReader) {
  // Keep-last state: a reader that died without a word (its lease has not yet expired) must
  // not hold the learner's broadcasts up.
  const std::string dir = test_support::make_temp_dir("auvrl_dds_killed_");
  auto t = transport::make_transport(dds_config());
  int pongs = 0;
  t->subscribe("PONG", [&](const RawMessage&) { ++pongs; });
  test_support::ChildProcess peer(
      {test_support::bin_path("dds_peer"), "echo", channels::kPolicyWeights, "PONG"},
      dir + "/peer.log");
  const auto weights = message(1, 500 * 1024);
  ASSERT_TRUE(handle_until(
      *t,
      [&] {
        t->publish(channels::kPolicyWeights, weights.data(), weights.size());
        return pongs > 0;
      },
      std::chrono::seconds(10)))
      << peer.log();
  peer.signal(SIGKILL);
  double slowest_ms = 0;
  for (int i = 0; i < 40; ++i) {
    const auto start = Clock::now();
    t->publish(channels::kPolicyWeights, weights.data(), weights.size());
    slowest_ms = std::max(slowest_ms,
                          std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    t->handle(25);
  }
  EXPECT_LT(slowest_ms, 50.0);
}

}  // namespace
