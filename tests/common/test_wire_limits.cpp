// Messages whose array lengths claim more elements than their bytes hold (a 60-byte message
// claiming 2^31 transitions, a 2 GB network, 2^31 channel names) are refused by decode_exact
// before the decoder allocates anything large: lcm-gen's decoder resized first and checked
// after, so one datagram could make a process zero gigabytes. Strings whose length is below
// one are refused too. Both found by the fuzzers, fixed by cmake/LcmBoundLengths.cmake. Its own
// executable: it replaces operator new to see the largest request.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/mission_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <cstdlib>
#include <new>

#include "common/transport.hpp"
#include "synthetic_experience.hpp"

namespace {

std::atomic<bool> g_tracking{false};
std::atomic<std::size_t> g_largest{0};

}  // namespace

void* operator new(std::size_t n) {
  if (g_tracking.load(std::memory_order_relaxed)) {
    std::size_t seen = g_largest.load(std::memory_order_relaxed);
    while (n > seen && !g_largest.compare_exchange_weak(seen, n)) {
    }
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
// Not inlined: gcc would otherwise see free() on what its own operator new returned and warn
// (-Wmismatched-new-delete), not knowing this operator new is malloc.
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace auvrl;
using Bytes = std::vector<std::uint8_t>;

template <class Msg>
Bytes encode(const Msg& msg) {
  Bytes out(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

/// Writes a big-endian int32 at offset (LCM's byte order).
void put_i32(Bytes& bytes, std::size_t offset, std::int32_t value) {
  const auto v = static_cast<std::uint32_t>(value);
  for (int i = 0; i < 4; ++i)
    bytes[offset + static_cast<std::size_t>(i)] = std::uint8_t(v >> (24 - 8 * i));
}

/// decode_exact of bytes as Msg, and the largest single allocation it asked for.
template <class Msg>
std::pair<bool, std::size_t> decode_tracked(const Bytes& bytes) {
  Msg msg;
  g_largest = 0;
  g_tracking = true;
  const bool ok = transport::decode_exact(bytes.data(), bytes.size(), msg);
  g_tracking = false;
  return {ok, g_largest.load()};
}

constexpr std::size_t kSmall = 64 * 1024;

TEST(WireLimits, ExperienceBatchWithAbsurdCountsIsRefusedBeforeAllocating) {
  // With no transitions the encoding ends with state_dim, action_dim, num_transitions.
  auvrl_lcm::experience_batch_t empty{};
  const Bytes base = encode(empty);
  const std::size_t n_at = base.size() - 4, state_dim_at = base.size() - 12;
  Bytes padded = base;
  padded.resize(base.size() + 40, 0);

  Bytes many = padded;  // 2^31 - 1 transitions of nothing: 24 bytes of vector each
  put_i32(many, n_at, INT32_MAX);
  auto [ok, largest] = decode_tracked<auvrl_lcm::experience_batch_t>(many);
  EXPECT_FALSE(ok);
  EXPECT_LT(largest, kSmall);

  Bytes wide = padded;  // one transition of 2^31 - 1 floats: 8 GB zeroed
  put_i32(wide, state_dim_at, INT32_MAX);
  put_i32(wide, n_at, 1);
  std::tie(ok, largest) = decode_tracked<auvrl_lcm::experience_batch_t>(wide);
  EXPECT_FALSE(ok);
  EXPECT_LT(largest, kSmall);

  Bytes negative = padded;
  put_i32(negative, n_at, -5);
  std::tie(ok, largest) = decode_tracked<auvrl_lcm::experience_batch_t>(negative);
  EXPECT_FALSE(ok);
}

TEST(WireLimits, PolicyWeightsClaimingAHugeNetworkIsRefusedBeforeAllocating) {
  auvrl_lcm::policy_weights_t empty{};
  Bytes bytes = encode(empty);  // ends with num_bytes
  put_i32(bytes, bytes.size() - 4, INT32_MAX);
  bytes.resize(bytes.size() + 100, 0);
  const auto [ok, largest] = decode_tracked<auvrl_lcm::policy_weights_t>(bytes);
  EXPECT_FALSE(ok);
  EXPECT_LT(largest, kSmall);
}

TEST(WireLimits, LoggerHeartbeatClaimingHugeChannelCountIsRefusedBeforeAllocating) {
  auvrl_lcm::logger_heartbeat_t empty{};
  Bytes bytes = encode(empty);  // ends with num_channels
  put_i32(bytes, bytes.size() - 4, INT32_MAX);
  bytes.resize(bytes.size() + 100, 0);
  const auto [ok, largest] = decode_tracked<auvrl_lcm::logger_heartbeat_t>(bytes);
  EXPECT_FALSE(ok);
  EXPECT_LT(largest, kSmall);
}

/// Where the length of the string `text` begins in `bytes` (LCM: a big-endian int32 of the
/// string's size plus its terminating NUL, then the characters).
std::size_t string_length_offset(const Bytes& bytes, const std::string& text) {
  Bytes pattern(4);
  put_i32(pattern, 0, static_cast<std::int32_t>(text.size() + 1));
  pattern.insert(pattern.end(), text.begin(), text.end());
  const auto at = std::search(bytes.begin(), bytes.end(), pattern.begin(), pattern.end());
  EXPECT_NE(at, bytes.end()) << "no string '" << text << "' in the encoding";
  return static_cast<std::size_t>(at - bytes.begin());
}

TEST(WireLimits, StringLengthsBelowOneAreRefused) {
  // lcm-gen 1.3.1 checks a string's length only against the bytes left, then copies length - 1
  // characters: a length of 0 or -5 made the copy throw (length_error, caught), and INT32_MIN
  // wrapped to 2^31 - 1, so that one datagram made the receiver read 2 GB past its buffer
  // (found by fuzz_controller_node; fixed by cmake/LcmBoundLengths.cmake).
  auvrl_lcm::vehicle_state_t state{};
  state.vehicle_name = "nessie7";
  const Bytes good_state = encode(state);
  const std::size_t name_at = string_length_offset(good_state, "nessie7");
  auvrl_lcm::mission_t mission{};
  mission.yaml = "name: m";
  const Bytes good_mission = encode(mission);
  const std::size_t yaml_at = string_length_offset(good_mission, "name: m");
  auvrl_lcm::logger_heartbeat_t heartbeat{};  // a string array
  heartbeat.num_channels = 1;
  heartbeat.channel = {"EPISODE"};
  heartbeat.received = heartbeat.written = heartbeat.throttled = {3};
  const Bytes good_heartbeat = encode(heartbeat);
  const std::size_t channel_at = string_length_offset(good_heartbeat, "EPISODE");
  for (const std::int32_t length : {INT32_MIN, -5, 0}) {
    Bytes bad_heartbeat = good_heartbeat;
    put_i32(bad_heartbeat, channel_at, length);
    EXPECT_FALSE(decode_tracked<auvrl_lcm::logger_heartbeat_t>(bad_heartbeat).first)
        << "channel name length " << length;
    Bytes bad_state = good_state;
    put_i32(bad_state, name_at, length);
    auto [ok, largest] = decode_tracked<auvrl_lcm::vehicle_state_t>(bad_state);
    EXPECT_FALSE(ok) << "vehicle_name length " << length;
    EXPECT_LT(largest, kSmall) << "vehicle_name length " << length;
    Bytes bad_mission = good_mission;
    put_i32(bad_mission, yaml_at, length);
    std::tie(ok, largest) = decode_tracked<auvrl_lcm::mission_t>(bad_mission);
    EXPECT_FALSE(ok) << "yaml length " << length;
    EXPECT_LT(largest, kSmall) << "yaml length " << length;
  }
  auvrl_lcm::vehicle_state_t got_state;
  EXPECT_TRUE(transport::decode_exact(good_state.data(), good_state.size(), got_state));
  EXPECT_EQ(got_state.vehicle_name, "nessie7");
  auvrl_lcm::mission_t got_mission;
  EXPECT_TRUE(transport::decode_exact(good_mission.data(), good_mission.size(), got_mission));
  EXPECT_EQ(got_mission.yaml, "name: m");
  auvrl_lcm::logger_heartbeat_t got_heartbeat;
  EXPECT_TRUE(transport::decode_exact(good_heartbeat.data(), good_heartbeat.size(), got_heartbeat));
  EXPECT_EQ(got_heartbeat.channel, heartbeat.channel);
}

TEST(WireLimits, RealMessagesStillDecode) {
  // The bound refuses only what cannot fit: full-size batches and weights decode as before.
  const auto batch = test_support::synthetic_experience_batch(3, 9, 256, 23, 6);
  auvrl_lcm::experience_batch_t got;
  const Bytes b = encode(batch);
  ASSERT_TRUE(transport::decode_exact(b.data(), b.size(), got));
  EXPECT_EQ(got.states, batch.states);
  EXPECT_EQ(got.step_index, batch.step_index);

  auvrl_lcm::policy_weights_t weights{};
  weights.num_bytes = 300000;
  weights.network.assign(300000, 7);
  auvrl_lcm::policy_weights_t got_weights;
  const Bytes w = encode(weights);
  ASSERT_TRUE(transport::decode_exact(w.data(), w.size(), got_weights));
  EXPECT_EQ(got_weights.network, weights.network);

  auvrl_lcm::thruster_cmd_t none{};  // zero-length arrays
  auvrl_lcm::thruster_cmd_t got_none;
  const Bytes c = encode(none);
  EXPECT_TRUE(transport::decode_exact(c.data(), c.size(), got_none));
}

}  // namespace
