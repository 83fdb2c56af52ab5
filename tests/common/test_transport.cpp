// The transport over LCM's in-process provider (memq://): typed publish/subscribe, decode
// failures counted, "keep newest" semantics, and the refusal of URLs that leave the host.
#include <gtest/gtest.h>

#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>

#include "common/transport.hpp"

namespace {

using namespace auvrl;

auvrl_lcm::thruster_cmd_t command(std::int64_t seq) {
  auvrl_lcm::thruster_cmd_t msg{};
  msg.vehicle_id = 2;
  msg.seq = seq;
  msg.num_thrusters = 3;
  msg.thrust_n = {1.0, -2.0, static_cast<double>(seq)};
  return msg;
}

TEST(Transport, TypedRoundTripOnMatchingChannelsOnly) {
  auto t = transport::make_in_process_transport();
  std::vector<std::pair<std::string, std::int64_t>> got;
  transport::DecodeStats stats;
  transport::subscribe<auvrl_lcm::thruster_cmd_t>(
      *t, "SIM_CMD_[0-9]+",
      [&](const std::string& ch, const auvrl_lcm::thruster_cmd_t& m) {
        got.emplace_back(ch, m.seq);
        EXPECT_EQ(m.thrust_n, command(m.seq).thrust_n);
      },
      &stats);
  transport::publish(*t, "SIM_CMD_2", command(5));
  transport::publish(*t, "SIM_STATE_2", command(6));  // not subscribed
  transport::publish(*t, "SIM_CMD_2x", command(7));   // regex is a full match
  EXPECT_EQ(t->handle(100), 1);
  EXPECT_EQ(t->drain(), 0);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].first, "SIM_CMD_2");
  EXPECT_EQ(got[0].second, 5);
  EXPECT_EQ(stats.decoded, 1);
}

TEST(Transport, UndecodableMessagesAreCountedAndDropped) {
  auto t = transport::make_in_process_transport();
  int calls = 0;
  transport::DecodeStats stats;
  transport::subscribe<auvrl_lcm::thruster_cmd_t>(
      *t, "CH", [&](const std::string&, const auvrl_lcm::thruster_cmd_t&) { ++calls; }, &stats);
  // Another type on the channel: wrong fingerprint.
  auvrl_lcm::vehicle_state_t other{};
  transport::publish(*t, "CH", other);
  // Garbage and a truncated message.
  const std::uint8_t garbage[5] = {1, 2, 3, 4, 5};
  t->publish("CH", garbage, sizeof garbage);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(command(1).getEncodedSize()));
  command(1).encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  t->publish("CH", bytes.data(), bytes.size() - 4);
  // Trailing bytes after a valid message.
  bytes.push_back(0);
  t->publish("CH", bytes.data(), bytes.size());
  // A negative array length (num_thrusters = -1) with a valid fingerprint.
  auvrl_lcm::thruster_cmd_t negative = command(1);
  negative.num_thrusters = 0;
  negative.thrust_n.clear();
  std::vector<std::uint8_t> neg(static_cast<std::size_t>(negative.getEncodedSize()));
  negative.encode(neg.data(), 0, static_cast<int>(neg.size()));
  neg.back() = 0xff;  // num_thrusters is the last field
  t->publish("CH", neg.data(), neg.size());
  t->handle(100);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(stats.failed, 5);
}

TEST(Transport, LatestKeepsOnlyTheNewest) {
  auto t = transport::make_in_process_transport();
  transport::Latest<auvrl_lcm::thruster_cmd_t> latest(*t, "W");
  EXPECT_FALSE(latest.take().has_value());
  for (int i = 1; i <= 10; ++i) transport::publish(*t, "W", command(i));
  t->drain();
  auto got = latest.take();
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->seq, 10);
  EXPECT_EQ(latest.received(), 10);
  EXPECT_FALSE(latest.take().has_value()) << "take() hands a value out once";
}

TEST(Transport, RefusesUrlsThatLeaveTheHost) {
  using transport::check_url_is_host_only;
  EXPECT_NO_THROW(check_url_is_host_only(transport::kDefaultLcmUrl, false));
  EXPECT_NO_THROW(check_url_is_host_only("udpm://239.255.76.67:7667", false));
  EXPECT_NO_THROW(check_url_is_host_only("memq://", false));
  EXPECT_NO_THROW(check_url_is_host_only("file:///tmp/x.lcmlog?mode=w", false));
  EXPECT_NO_THROW(check_url_is_host_only("tcpq://127.0.0.1:7700", false));
  EXPECT_THROW(check_url_is_host_only("udpm://239.255.76.67:7667?ttl=1", false),
               transport::TransportError);
  EXPECT_THROW(check_url_is_host_only("udpm://239.255.76.67:7667?recv_buf_size=1&ttl=255", false),
               transport::TransportError);
  EXPECT_THROW(check_url_is_host_only("tcpq://10.0.0.2:7700", false), transport::TransportError);
  EXPECT_THROW(check_url_is_host_only("bogus://x", false), transport::TransportError);
  EXPECT_NO_THROW(check_url_is_host_only("udpm://239.255.76.67:7667?ttl=1", true));
  transport::TransportConfig off_host;
  off_host.lcm_url = "udpm://239.255.76.67:7667?ttl=1";
  EXPECT_THROW(transport::make_transport(off_host), transport::TransportError);
}

}  // namespace
