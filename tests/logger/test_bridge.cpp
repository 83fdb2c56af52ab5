// The DDS -> LCM bridge (inside scripts/netns.sh: DDS and LCM open sockets on lo): in one
// process (logger/bridge.hpp between a DDS transport and LCM's memq://) and as the auv_bridge
// process between DDS and LCM multicast, where a bridge started late still passes on the
// newest policy summary (DDS keeps it for late joiners).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/transport.hpp"
#include "logger/bridge.hpp"

namespace {

using namespace auvrl;
using transport::RawMessage;
using Clock = std::chrono::steady_clock;

transport::TransportConfig dds_config() {
  transport::TransportConfig c;
  c.kind = transport::TransportKind::kDds;
  return c;
}

std::vector<std::uint8_t> bytes_of(std::int64_t version, std::size_t size) {
  std::vector<std::uint8_t> b(std::max(size, sizeof version));
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(i * 13 + 1);
  std::memcpy(b.data(), &version, sizeof version);
  return b;
}

TEST(Bridge, ForwardsMatchingChannelsByteForByte) {
  auto publisher = transport::make_transport(dds_config());
  auto from = transport::make_transport(dds_config());
  auto to = transport::make_in_process_transport();
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> got;
  to->subscribe(".*", [&](const RawMessage& m) {
    got.emplace_back(m.channel, std::vector<std::uint8_t>(m.data, m.data + m.size));
  });
  logger::Bridge bridge(*from, *to, {"POLICY_.*|EPISODE", 100});
  const auto weights = bytes_of(3, 500 * 1024);
  const auto episode = bytes_of(4, 300);
  publisher->publish(channels::sim_state(0), episode.data(), episode.size());  // not forwarded
  publisher->publish(channels::kPolicyWeights, weights.data(), weights.size());
  publisher->publish(channels::kEpisode, episode.data(), episode.size());
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (bridge.forwarded() < 2 && Clock::now() < deadline) bridge.poll(20);
  bridge.poll(200);
  to->drain();
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(bridge.forwarded(), 2);
  EXPECT_EQ(bridge.failed(), 0);
  EXPECT_EQ(bridge.bytes_forwarded(), static_cast<std::int64_t>(weights.size() + episode.size()));
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got[0].first, channels::kEpisode);
  EXPECT_EQ(got[0].second, episode);
  EXPECT_EQ(got[1].first, channels::kPolicyWeights);
  EXPECT_EQ(got[1].second, weights);
}

TEST(BridgeProcess, ShowsADdsSystemOnLcm) {
  const std::string dir = test_support::make_temp_dir("auvrl_bridge_");
  auto dds = transport::make_transport(dds_config());
  auto lcm = transport::make_transport({});
  std::vector<std::int64_t> summaries, episodes;
  const auto version = [](const RawMessage& m) {
    std::int64_t v = -1;
    if (m.size >= sizeof v) std::memcpy(&v, m.data, sizeof v);
    return v;
  };
  lcm->subscribe(channels::kPolicySummary,
                 [&](const RawMessage& m) { summaries.push_back(version(m)); });
  lcm->subscribe(channels::kEpisode, [&](const RawMessage& m) { episodes.push_back(version(m)); });
  // Ten summaries before the bridge exists: it passes on the newest, unasked.
  for (int v = 1; v <= 10; ++v) {
    const auto b = bytes_of(v, 200);
    dds->publish(channels::kPolicySummary, b.data(), b.size());
  }
  test_support::ChildProcess bridge({test_support::bin_path("auv_bridge"), "--from", "dds", "--to",
                                     "lcm", "--channels", "POLICY_SUMMARY|EPISODE"},
                                    dir + "/bridge.log");
  const auto until = [&](auto done, std::chrono::seconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (!done() && Clock::now() < deadline) {
      lcm->handle(20);
      dds->handle(0);
    }
    return done();
  };
  ASSERT_TRUE(until([&] { return !summaries.empty(); }, std::chrono::seconds(10))) << bridge.log();
  EXPECT_EQ(summaries, std::vector<std::int64_t>{10});
  // Episodes are not kept for late joiners: the bridge has been discovered by now (it sent the
  // summary), so every one of these arrives.
  for (int e = 1; e <= 50; ++e) {
    const auto b = bytes_of(e, 400);
    dds->publish(channels::kEpisode, b.data(), b.size());
  }
  ASSERT_TRUE(until([&] { return episodes.size() >= 50; }, std::chrono::seconds(10)))
      << bridge.log();
  for (int e = 1; e <= 50; ++e) EXPECT_EQ(episodes[static_cast<std::size_t>(e - 1)], e);
  EXPECT_EQ(bridge.terminate(), 0) << bridge.log();
}

}  // namespace
