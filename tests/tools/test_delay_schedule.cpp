// DelaySchedule (auv_netdelay's decisions) with a fake clock: delays within the bounds, release
// order by due time, loss share, clamping at 0, parsers.
#include <gtest/gtest.h>

#include <stdexcept>

#include "delay_schedule.hpp"

namespace {

using namespace auvrl::netdelay;
using std::chrono::milliseconds;

TEST(DelaySchedule, ReleasesEachPacketWithinDelayPlusMinusJitter) {
  DelaySchedule schedule({5.0, 5.0, 0.0, 42});
  const Clock::time_point t0{};
  for (std::uint32_t id = 0; id < 1000; ++id) ASSERT_TRUE(schedule.admit(id, t0));
  EXPECT_EQ(schedule.pending(), 1000u);
  std::vector<std::uint32_t> out;
  EXPECT_EQ(schedule.release_due(t0 - milliseconds(1), out), 0u);
  // Nothing is due after 10 ms (5 + 5); all is due then.
  schedule.release_due(t0 + milliseconds(10), out);
  EXPECT_EQ(out.size(), 1000u);
  EXPECT_EQ(schedule.pending(), 0u);
  EXPECT_FALSE(schedule.next_due().has_value());
  const double mean = schedule.stats().delay_sum_ms / 1000.0;
  EXPECT_NEAR(mean, 5.0, 0.5);  // uniform in [0, 10]: sd of the mean 0.09 ms
}

TEST(DelaySchedule, ReleasesInDueOrderAndStepByStep) {
  DelaySchedule schedule({5.0, 4.0, 0.0, 7});
  const Clock::time_point t0{};
  for (std::uint32_t id = 0; id < 200; ++id) schedule.admit(id, t0 + milliseconds(id % 3));
  std::vector<std::uint32_t> out;
  Clock::time_point previous = t0;
  std::size_t total = 0;
  for (int ms = 0; ms <= 12; ++ms) {
    const auto now = t0 + milliseconds(ms);
    if (auto next = schedule.next_due()) {
      EXPECT_GE(*next, previous);  // the heap hands out due times in order
      previous = *next;
    }
    out.clear();
    total += schedule.release_due(now, out);
    if (auto next = schedule.next_due()) {
      EXPECT_GT(*next, now);
    }
    if (ms < 1) {
      EXPECT_TRUE(out.empty());  // at least 1 ms (5 - 4) held
    }
  }
  EXPECT_EQ(total, 200u);
  EXPECT_EQ(schedule.stats().released, 200u);
}

TEST(DelaySchedule, TiesLeaveInArrivalOrderAndZeroDelayIsImmediate) {
  DelaySchedule schedule({0.0, 0.0, 0.0, 1});
  const Clock::time_point t0{};
  for (std::uint32_t id = 10; id < 20; ++id) schedule.admit(id, t0);
  std::vector<std::uint32_t> out;
  schedule.release_due(t0, out);
  ASSERT_EQ(out.size(), 10u);
  for (std::uint32_t i = 0; i < 10; ++i) EXPECT_EQ(out[i], 10 + i);
}

TEST(DelaySchedule, JitterLargerThanDelayIsClampedAtZero) {
  DelaySchedule schedule({1.0, 10.0, 0.0, 3});
  const Clock::time_point t0{};
  for (std::uint32_t id = 0; id < 500; ++id) schedule.admit(id, t0);
  std::vector<std::uint32_t> out;
  schedule.release_due(t0, out);
  // P(delay <= 0) = 9/20: about 225 due at once, none before.
  EXPECT_GT(out.size(), 150u);
  EXPECT_LT(out.size(), 300u);
  schedule.release_due(t0 + milliseconds(11), out);
  EXPECT_EQ(out.size(), 500u);
}

TEST(DelaySchedule, DropsTheLossShareAndIsReproducibleFromTheSeed) {
  DelaySchedule a({5.0, 5.0, 0.1, 99}), b({5.0, 5.0, 0.1, 99});
  const Clock::time_point t0{};
  int dropped = 0;
  for (std::uint32_t id = 0; id < 10000; ++id) {
    const bool kept = a.admit(id, t0);
    EXPECT_EQ(kept, b.admit(id, t0));
    dropped += kept ? 0 : 1;
  }
  EXPECT_EQ(a.stats().dropped, static_cast<std::uint64_t>(dropped));
  EXPECT_NEAR(dropped, 1000, 120);  // binomial sd 30
  std::vector<std::uint32_t> out;
  EXPECT_EQ(a.release_all(out), 10000u - dropped);
}

TEST(DelaySchedule, Parsers) {
  EXPECT_DOUBLE_EQ(parse_fraction("10%"), 0.1);
  EXPECT_DOUBLE_EQ(parse_fraction("0.25"), 0.25);
  EXPECT_DOUBLE_EQ(parse_ms("5ms"), 5.0);
  EXPECT_DOUBLE_EQ(parse_ms("7"), 7.0);
  EXPECT_DOUBLE_EQ(parse_ms("500us"), 0.5);
  EXPECT_DOUBLE_EQ(parse_ms("0.1s"), 100.0);
  EXPECT_THROW(parse_fraction("150%"), std::invalid_argument);
  EXPECT_THROW(parse_fraction("-1"), std::invalid_argument);
  EXPECT_THROW(parse_ms("5 minutes"), std::invalid_argument);
  EXPECT_THROW(parse_ms("fast"), std::invalid_argument);
}

}  // namespace
