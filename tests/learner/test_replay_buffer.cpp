// Replay buffer: ring wrap, stored fields (expert labels included) and terminal flags, uniform
// seeded sampling, allocation-free use, and the checkpoint record (round trip, the version
// before expert labels still read, damage rejected).
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "common/nn/byte_io.hpp"
#include "learner/replay_buffer.hpp"

namespace auvrl::learner {
namespace {

constexpr int kS = 3;
constexpr int kA = 2;

// Transition number i: every field derived from i so that any slot can be checked.
// Odd transitions carry an expert label, even ones none.
void add_numbered(ReplayBuffer& rb, int i) {
  nn::Vector s(kS), a(kA), s1(kS), expert(kA);
  s << i, i + 0.25f, i + 0.5f;
  a << -0.01f * i, 0.01f * i;
  s1 << i + 1, i + 1.25f, i + 1.5f;
  expert << 0.001f * i, -0.5f;
  rb.add(TransitionView{s, a, static_cast<float>(-i), s1, i % 3 == 0,
                        Eigen::Vector3f(i, 2.0f * i, 3.0f * i), Eigen::Vector3f(7, 6, 10),
                        static_cast<std::uint64_t>(i / 4), static_cast<std::uint32_t>(i % 4),
                        i % 2 == 1 ? expert.data() : nullptr});
}

void expect_numbered(const ReplayBuffer& rb, std::size_t slot, int i) {
  EXPECT_EQ(rb.state(slot)[0], static_cast<float>(i)) << "slot " << slot;
  EXPECT_EQ(rb.state(slot)[2], i + 0.5f);
  EXPECT_EQ(rb.action(slot)[1], 0.01f * i);
  EXPECT_EQ(rb.reward(slot), static_cast<float>(-i));
  EXPECT_EQ(rb.next_state(slot)[1], i + 1.25f);
  EXPECT_EQ(rb.terminal(slot), i % 3 == 0);
  EXPECT_EQ(rb.achieved_position_ned_m(slot)[1], 2.0f * i);
  EXPECT_EQ(rb.goal_ned_m(slot)[2], 10.0f);
  EXPECT_EQ(rb.episode_id(slot), static_cast<std::uint64_t>(i / 4));
  EXPECT_EQ(rb.step_index(slot), static_cast<std::uint32_t>(i % 4));
  EXPECT_EQ(rb.has_expert(slot), i % 2 == 1);
  EXPECT_EQ(rb.expert_action(slot)[0], i % 2 == 1 ? 0.001f * i : 0.0f);
  EXPECT_EQ(rb.expert_action(slot)[1], i % 2 == 1 ? -0.5f : 0.0f);
}

TEST(ReplayBuffer, RingWrapKeepsTheNewest) {
  ReplayBuffer rb(kS, kA, 5);
  EXPECT_EQ(rb.size(), 0u);
  for (int i = 0; i < 3; ++i) add_numbered(rb, i);
  EXPECT_EQ(rb.size(), 3u);
  EXPECT_EQ(rb.next_slot(), 3u);
  for (int i = 3; i < 12; ++i) add_numbered(rb, i);
  EXPECT_EQ(rb.size(), 5u);
  EXPECT_EQ(rb.capacity(), 5u);
  EXPECT_EQ(rb.total_added(), 12u);
  EXPECT_EQ(rb.next_slot(), 2u);  // the oldest (7) sits there
  for (int i = 7; i < 12; ++i) expect_numbered(rb, static_cast<std::size_t>(i % 5), i);
  rb.clear();
  EXPECT_EQ(rb.size(), 0u);
  EXPECT_EQ(rb.next_slot(), 0u);
}

TEST(ReplayBuffer, SampleCopiesEveryFieldAndTheTerminalFlag) {
  ReplayBuffer rb(kS, kA, 8);
  add_numbered(rb, 3);  // terminal (3 % 3 == 0)
  Batch b(kS, kA, 4);
  nn::Rng rng(1);
  rb.sample(rng, 4, b);
  EXPECT_EQ(b.size, 4);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(b.state(1, k), 3.25f);
    EXPECT_EQ(b.action(0, k), -0.03f);
    EXPECT_EQ(b.reward(0, k), -3.0f);
    EXPECT_EQ(b.next_state(2, k), 4.5f);
    EXPECT_EQ(b.terminal(0, k), 1.0f);
    EXPECT_EQ(b.has_expert(0, k), 1.0f);
    EXPECT_EQ(b.expert_action(0, k), 0.003f);
    EXPECT_EQ(b.expert_action(1, k), -0.5f);
    EXPECT_EQ(b.slot[static_cast<std::size_t>(k)], 0u);
  }
  ReplayBuffer rb2(kS, kA, 8);
  add_numbered(rb2, 4);  // not terminal: a time-limit cut-off is stored like this
  rb2.sample(rng, 2, b);
  EXPECT_EQ(b.terminal(0, 0), 0.0f);
  EXPECT_EQ(b.has_expert(0, 0), 0.0f);  // no label: flag and label cleared
  EXPECT_EQ(b.expert_action(1, 0), 0.0f);
  EXPECT_EQ(b.size, 2);
}

TEST(ReplayBuffer, SamplingIsUniformOverStoredSlotsAndSeeded) {
  ReplayBuffer rb(kS, kA, 20);
  for (int i = 0; i < 7; ++i) add_numbered(rb, i);  // only slots 0..6 are filled
  Batch b(kS, kA, 100);
  nn::Rng rng(42);
  std::vector<long> counts(20, 0);
  const int draws = 1000;
  for (int d = 0; d < draws; ++d) {
    rb.sample(rng, 100, b);
    for (int k = 0; k < 100; ++k) ++counts[b.slot[static_cast<std::size_t>(k)]];
  }
  double chi2 = 0;
  const double expected = draws * 100.0 / 7;
  for (int s = 0; s < 20; ++s) {
    if (s < 7) {
      chi2 += (counts[s] - expected) * (counts[s] - expected) / expected;
    } else {
      EXPECT_EQ(counts[s], 0) << "slot " << s << " was never written";
    }
  }
  EXPECT_LT(chi2, 22.46);  // chi-square, 6 degrees of freedom, p = 0.001

  nn::Rng a(5), c(5);
  Batch ba(kS, kA, 16), bc(kS, kA, 16);
  rb.sample(a, 16, ba);
  rb.sample(c, 16, bc);
  EXPECT_EQ(ba.slot, bc.slot);
}

TEST(ReplayBuffer, BadUseIsRejected) {
  ReplayBuffer rb(kS, kA, 4);
  Batch b(kS, kA, 4);
  nn::Rng rng(1);
  EXPECT_THROW(rb.sample(rng, 2, b), std::logic_error);
  nn::Vector s(kS + 1), a(kA);
  EXPECT_THROW(rb.add(TransitionView{s, a, 0, s, false, {}, {}, 0, 0}), std::invalid_argument);
  add_numbered(rb, 1);
  EXPECT_THROW(rb.sample(rng, 5, b), std::invalid_argument);
  EXPECT_THROW(ReplayBuffer(0, 1, 1), std::invalid_argument);
}

TEST(ReplayBuffer, AddAndSampleAllocateNothing) {
  ReplayBuffer rb(29, 6, 1000);
  Batch b(29, 6, 256);
  nn::Rng rng(3);
  nn::Vector s = nn::Vector::Ones(29), a = nn::Vector::Ones(6);
  test::AllocationCounter counter;
  for (int i = 0; i < 2000; ++i) {
    rb.add(TransitionView{s, a, 1.0f, s, false, Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero(), 0,
                          0});
  }
  rb.sample(rng, 256, b);
  EXPECT_EQ(counter.count(), 0);
}

TEST(ReplayBuffer, SaveRestoreRoundTripIsExact) {
  ReplayBuffer rb(kS, kA, 6);
  for (int i = 0; i < 9; ++i) add_numbered(rb, i);  // wrapped
  std::stringstream ss;
  rb.save(ss);

  ReplayBuffer restored(kS, kA, 6);
  add_numbered(restored, 100);
  restored.restore(ss);
  EXPECT_EQ(restored.size(), rb.size());
  EXPECT_EQ(restored.next_slot(), rb.next_slot());
  EXPECT_EQ(restored.total_added(), rb.total_added());
  for (int i = 3; i < 9; ++i) expect_numbered(restored, static_cast<std::size_t>(i % 6), i);

  // Same draws and the same future: sampling and the next overwrite match.
  nn::Rng r1(8), r2(8);
  Batch b1(kS, kA, 32), b2(kS, kA, 32);
  rb.sample(r1, 32, b1);
  restored.sample(r2, 32, b2);
  EXPECT_EQ(b1.slot, b2.slot);
  EXPECT_EQ(b1.state, b2.state);
  add_numbered(rb, 9);
  add_numbered(restored, 9);
  expect_numbered(restored, 3, 9);

  // A partly filled buffer too.
  ReplayBuffer partial(kS, kA, 6), partial2(kS, kA, 6);
  add_numbered(partial, 1);
  std::stringstream ss2;
  partial.save(ss2);
  partial2.restore(ss2);
  EXPECT_EQ(partial2.size(), 1u);
  expect_numbered(partial2, 0, 1);
}

TEST(ReplayBuffer, DamagedOrMismatchedRecordsAreRejectedAndTheBufferKept) {
  ReplayBuffer rb(kS, kA, 6);
  for (int i = 0; i < 4; ++i) add_numbered(rb, i);
  std::stringstream ss;
  rb.save(ss);
  const std::string good = ss.str();

  ReplayBuffer target(kS, kA, 6);
  add_numbered(target, 50);
  auto restore_from = [&](const std::string& bytes) {
    std::istringstream is(bytes);
    target.restore(is);
  };
  for (std::size_t i = 0; i < good.size(); i += 7) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x40);
    EXPECT_THROW(restore_from(bad), std::runtime_error) << "byte " << i;
  }
  for (std::size_t n : {std::size_t{0}, std::size_t{10}, good.size() / 2, good.size() - 1}) {
    EXPECT_THROW(restore_from(good.substr(0, n)), std::runtime_error) << n;
  }
  EXPECT_EQ(target.size(), 1u);
  expect_numbered(target, 0, 50);

  ReplayBuffer other_dims(kS + 1, kA, 6), other_capacity(kS, kA, 7);
  std::istringstream is1(good), is2(good);
  try {
    other_dims.restore(is1);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("expected state_dim 4"), std::string::npos) << e.what();
  }
  EXPECT_THROW(other_capacity.restore(is2), std::runtime_error);
}

// Checkpoints written before expert labels existed (version 1) still restore, as transitions
// without labels.
TEST(ReplayBuffer, VersionOneRecordsRestoreWithoutLabels) {
  std::stringstream ss;
  {
    nn::OStreamSink sink(ss);
    nn::Writer w(sink);
    const char magic[8] = {'A', 'U', 'V', 'R', 'L', 'R', 'B', '\0'};
    w.bytes(magic, sizeof magic);
    w.u32(1);
    w.u32(kS);
    w.u32(kA);
    w.u64(4);  // capacity
    w.u64(2);  // size
    w.u64(2);  // next slot
    w.u64(2);  // total added
    const float states[2 * kS] = {1, 1.25f, 1.5f, 2, 2.25f, 2.5f};
    const float actions[2 * kA] = {-0.01f, 0.01f, -0.02f, 0.02f};
    const float rewards[2] = {-1, -2};
    const float next_states[2 * kS] = {2, 2.25f, 2.5f, 3, 3.25f, 3.5f};
    const std::uint8_t terminal[2] = {0, 0};
    const float achieved[6] = {1, 2, 3, 2, 4, 6};
    const float goals[6] = {7, 6, 10, 7, 6, 10};
    const std::uint64_t episodes[2] = {0, 0};
    const std::uint32_t steps[2] = {1, 2};
    w.f32_array(states, 2 * kS);
    w.f32_array(actions, 2 * kA);
    w.f32_array(rewards, 2);
    w.f32_array(next_states, 2 * kS);
    w.bytes(terminal, 2);
    w.f32_array(achieved, 6);
    w.f32_array(goals, 6);
    w.u64_array(episodes, 2);
    w.u32_array(steps, 2);
    w.checksum();
  }
  ReplayBuffer rb(kS, kA, 4);
  add_numbered(rb, 7);  // a label in slot 0 that must not survive the restore
  rb.restore(ss);
  ASSERT_EQ(rb.size(), 2u);
  for (std::size_t slot : {std::size_t{0}, std::size_t{1}}) {
    const float i = static_cast<float>(slot) + 1;
    EXPECT_EQ(rb.state(slot)[2], i + 0.5f);
    EXPECT_EQ(rb.action(slot)[1], 0.01f * i);
    EXPECT_EQ(rb.next_state(slot)[1], i + 1.25f);
    EXPECT_EQ(rb.achieved_position_ned_m(slot)[2], 3 * i);
    EXPECT_EQ(rb.step_index(slot), slot + 1);
    EXPECT_FALSE(rb.has_expert(slot));
    EXPECT_EQ(rb.expert_action(slot)[0], 0.0f);
  }
}

}  // namespace
}  // namespace auvrl::learner
