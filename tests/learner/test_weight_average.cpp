// The mean of the actor's recent weights (learner/weight_average.hpp): the right copies and
// their exact mean, nothing when off, and a checkpoint's round trip that loses nothing and
// refuses what does not fit.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "common/nn/byte_io.hpp"
#include "learner/weight_average.hpp"

namespace auvrl::learner {
namespace {

nn::Mlp actor_of(float value) {
  nn::Mlp net(nn::MlpSpec::actor(3, {4}, 2), 1);
  net.params().setConstant(value);
  return net;
}

TEST(WeightAverage, MeansTheLastWindowOfCopiesTakenEveryNUpdates) {
  WeightAverage average(10, 30);  // three copies
  for (int updates = 1; updates <= 50; ++updates) {
    average.observe(updates, actor_of(static_cast<float>(updates)));
  }
  // Copies at 30, 40 and 50 (10 and 20 dropped); the updates in between are not taken.
  EXPECT_EQ(average.copies(), 3u);
  EXPECT_EQ(average.first_updates(), 30);
  EXPECT_EQ(average.last_updates(), 50);
  const std::optional<nn::Mlp> mean = average.mean(actor_of(0.0f));
  ASSERT_TRUE(mean);
  EXPECT_EQ(mean->spec(), actor_of(0.0f).spec());
  for (Eigen::Index i = 0; i < mean->num_params(); ++i) EXPECT_FLOAT_EQ(mean->params()[i], 40.0f);
  average.observe(50, actor_of(1000.0f));  // the same count again: already taken
  EXPECT_FLOAT_EQ(average.mean(actor_of(0.0f))->params()[0], 40.0f);
}

TEST(WeightAverage, AMixOfDifferentParametersIsTheirElementwiseMean) {
  WeightAverage average(1, 2);
  nn::Mlp a = actor_of(0.0f);
  nn::Mlp b = actor_of(0.0f);
  for (Eigen::Index i = 0; i < a.num_params(); ++i) {
    a.params()[i] = static_cast<float>(i);
    b.params()[i] = -3.0f * static_cast<float>(i) + 1.0f;
  }
  average.observe(1, a);
  average.observe(2, b);
  const nn::Mlp mean = *average.mean(a);
  for (Eigen::Index i = 0; i < a.num_params(); ++i) {
    EXPECT_FLOAT_EQ(mean.params()[i], (a.params()[i] + b.params()[i]) / 2.0f) << i;
  }
}

TEST(WeightAverage, OffOrBeforeTheFirstCopyThereIsNoMean) {
  WeightAverage off(5000, 0);
  EXPECT_FALSE(off.enabled());
  for (int updates = 1; updates <= 20000; updates += 4999) off.observe(updates, actor_of(1.0f));
  EXPECT_EQ(off.copies(), 0u);
  EXPECT_FALSE(off.mean(actor_of(0.0f)));
  WeightAverage early(100, 1000);
  early.observe(99, actor_of(1.0f));
  EXPECT_FALSE(early.mean(actor_of(0.0f)));
}

TEST(WeightAverage, RefusesSettingsItCannotHoldNamingTheKey) {
  EXPECT_THROW(WeightAverage(0, 100), std::invalid_argument);
  EXPECT_THROW(WeightAverage(10, -1), std::invalid_argument);
  try {
    WeightAverage(1, WeightAverage::kMaxCopies + 1);
    FAIL() << "a window of too many copies was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("average_window_updates"), std::string::npos);
  }
  WeightAverage average(1, 1);
  average.observe(1, actor_of(1.0f));
  nn::Mlp other(nn::MlpSpec::actor(3, {5}, 2), 1);
  EXPECT_THROW(average.mean(other), std::invalid_argument);
}

std::vector<std::uint8_t> saved(const WeightAverage& average) {
  std::vector<std::uint8_t> bytes;
  nn::VectorSink sink(bytes);
  nn::Writer w(sink);
  average.save(w);
  return bytes;
}

TEST(WeightAverage, ACheckpointsRoundTripKeepsTheCopiesAndTheirMean) {
  WeightAverage average(2, 6);
  for (int updates = 1; updates <= 11; ++updates) {
    average.observe(updates, actor_of(static_cast<float>(updates) * 0.5f));
  }
  const std::vector<std::uint8_t> bytes = saved(average);
  WeightAverage restored(2, 6);
  nn::SpanSource source(bytes);
  nn::Reader r(source, "test");
  restored.restore(r, actor_of(0.0f).num_params());
  EXPECT_EQ(restored.copies(), 3u);
  EXPECT_EQ(restored.first_updates(), 6);
  EXPECT_EQ(restored.last_updates(), 10);
  EXPECT_EQ(restored.mean(actor_of(0.0f))->params(), average.mean(actor_of(0.0f))->params());
  // A resumed run with a smaller window keeps the newest copies.
  WeightAverage smaller(2, 2);
  nn::SpanSource again(bytes);
  nn::Reader r2(again, "test");
  smaller.restore(r2, actor_of(0.0f).num_params());
  EXPECT_EQ(smaller.copies(), 1u);
  EXPECT_FLOAT_EQ(smaller.mean(actor_of(0.0f))->params()[0], 5.0f);
}

TEST(WeightAverage, RestoreRefusesOtherSizesAndDisorderedCopies) {
  WeightAverage average(1, 2);
  average.observe(1, actor_of(1.0f));
  average.observe(2, actor_of(2.0f));
  std::vector<std::uint8_t> bytes = saved(average);
  {
    WeightAverage restored(1, 2);
    nn::SpanSource source(bytes);
    nn::Reader r(source, "checkpoint x");
    EXPECT_THROW(restored.restore(r, actor_of(0.0f).num_params() + 1), std::runtime_error);
    EXPECT_EQ(restored.copies(), 0u);  // nothing taken from a file that does not fit
  }
  // The second copy's update count (after the count, the size and the first copy) set to 1.
  const std::size_t second = 4 + 8 + 8 + 4 * static_cast<std::size_t>(actor_of(0.0f).num_params());
  bytes[second] = 1;
  WeightAverage restored(1, 2);
  nn::SpanSource source(bytes);
  nn::Reader r(source, "checkpoint x");
  try {
    restored.restore(r, actor_of(0.0f).num_params());
    FAIL() << "copies out of order were accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("out of order"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace auvrl::learner
