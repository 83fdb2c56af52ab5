// Exploration noise: Ornstein-Uhlenbeck statistics (mean reversion), Gaussian, seeding, clipping.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "agent/episode.hpp"
#include "common/random.hpp"

namespace auvrl::agent {
namespace {

/// Noise values for one dimension: applied to a zero action, step by step.
std::vector<double> draw(ExplorationNoise& noise, int steps) {
  std::vector<double> out;
  task::ActionVector a(1);
  for (int i = 0; i < steps; ++i) {
    a.setZero();
    noise.apply(a);
    out.push_back(a[0]);
  }
  return out;
}

struct Moments {
  double mean = 0, variance = 0, lag1 = 0;
};

Moments moments(const std::vector<double>& x) {
  Moments m;
  for (double v : x) m.mean += v;
  m.mean /= static_cast<double>(x.size());
  double cov = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    m.variance += (x[i] - m.mean) * (x[i] - m.mean);
    if (i > 0) cov += (x[i] - m.mean) * (x[i - 1] - m.mean);
  }
  m.lag1 = cov / m.variance;
  m.variance /= static_cast<double>(x.size());
  return m;
}

TEST(ExplorationNoise, OrnsteinUhlenbeckRevertsToZeroWithTheRightStatistics) {
  // x += -theta x + sigma N(0, 1): lag-1 autocorrelation 1 - theta, stationary variance
  // sigma^2 / (1 - (1 - theta)^2), mean 0. Small sigma so that clipping never acts.
  const double sigma = 0.05, theta = 0.15;
  ExplorationNoise noise(ExplorationNoise::Kind::kOrnsteinUhlenbeck, 1, sigma, theta, 9);
  const Moments m = moments(draw(noise, 200000));
  EXPECT_NEAR(m.lag1, 1.0 - theta, 0.01);
  const double variance = sigma * sigma / (1.0 - (1.0 - theta) * (1.0 - theta));
  EXPECT_NEAR(m.variance, variance, 0.05 * variance);
  EXPECT_NEAR(m.mean, 0.0, 0.1 * std::sqrt(variance));
}

TEST(ExplorationNoise, OrnsteinUhlenbeckDecaysGeometricallyWithoutNoise) {
  // With theta = 1 every step forgets the last; with theta = 0 it is a random walk whose
  // variance grows linearly: the mean reversion is what keeps OU bounded.
  ExplorationNoise walk(ExplorationNoise::Kind::kOrnsteinUhlenbeck, 1, 0.001, 0.0, 4);
  const std::vector<double> w = draw(walk, 40000);
  double early = 0, late = 0;
  for (int i = 0; i < 1000; ++i)
    early += w[static_cast<std::size_t>(i)] * w[static_cast<std::size_t>(i)];
  for (int i = 39000; i < 40000; ++i)
    late += w[static_cast<std::size_t>(i)] * w[static_cast<std::size_t>(i)];
  EXPECT_GT(late, 5.0 * early);
  ExplorationNoise white(ExplorationNoise::Kind::kOrnsteinUhlenbeck, 1, 0.05, 1.0, 4);
  EXPECT_NEAR(moments(draw(white, 100000)).lag1, 0.0, 0.02);
}

TEST(ExplorationNoise, GaussianIsWhiteWithSigma) {
  ExplorationNoise noise(ExplorationNoise::Kind::kGaussian, 1, 0.1, 0.15, 2);
  const Moments m = moments(draw(noise, 100000));
  EXPECT_NEAR(m.lag1, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(m.variance), 0.1, 0.003);
  EXPECT_NEAR(m.mean, 0.0, 0.003);
}

TEST(ExplorationNoise, SameSeedSameNoiseOtherSeedOther) {
  for (auto kind :
       {ExplorationNoise::Kind::kOrnsteinUhlenbeck, ExplorationNoise::Kind::kGaussian}) {
    ExplorationNoise a(kind, 6, 0.2, 0.15, 77), b(kind, 6, 0.2, 0.15, 77),
        c(kind, 6, 0.2, 0.15, 78);
    bool differs = false;
    for (int i = 0; i < 50; ++i) {
      task::ActionVector xa = task::ActionVector::Constant(6, 0.1f), xb = xa, xc = xa;
      a.apply(xa);
      b.apply(xb);
      c.apply(xc);
      EXPECT_EQ(xa, xb);
      differs |= xa != xc;
    }
    EXPECT_TRUE(differs);
  }
}

TEST(ExplorationNoise, GaussianDrawsThePortableStandardNormal) {
  // The same numbers with any standard library: sigma times draw::standard_normal of the seed.
  ExplorationNoise noise(ExplorationNoise::Kind::kGaussian, 1, 0.1, 0.15, 2024);
  draw::Engine rng(2024);
  for (double v : draw(noise, 20)) {
    EXPECT_FLOAT_EQ(static_cast<float>(v), static_cast<float>(0.1 * draw::standard_normal(rng)));
  }
}

TEST(ExplorationNoise, ResetClearsTheOrnsteinUhlenbeckState) {
  // theta = 0: the state is the running sum of the draws; after reset it starts from zero, so
  // the first value after reset is one draw only (small), not the accumulated walk.
  ExplorationNoise noise(ExplorationNoise::Kind::kOrnsteinUhlenbeck, 1, 0.01, 0.0, 5);
  const std::vector<double> walk = draw(noise, 10000);
  ASSERT_GT(std::abs(walk.back()), 0.1);  // 0.01 * sqrt(10000) = 1 typical: clipped or large
  noise.reset();
  EXPECT_LT(std::abs(draw(noise, 1)[0]), 0.05);  // one draw: 5 sigma
}

TEST(ExplorationNoise, OutputIsClippedToTheActionRange) {
  ExplorationNoise noise(ExplorationNoise::Kind::kGaussian, 6, 2.0, 0.15, 3);
  bool hit_upper = false, hit_lower = false;
  for (int i = 0; i < 1000; ++i) {
    task::ActionVector a = task::ActionVector::Constant(6, 0.9f);
    noise.apply(a);
    for (int k = 0; k < 6; ++k) {
      ASSERT_GE(a[k], -1.0f);
      ASSERT_LE(a[k], 1.0f);
      hit_upper |= a[k] == 1.0f;
      hit_lower |= a[k] == -1.0f;
    }
  }
  EXPECT_TRUE(hit_upper);
  EXPECT_TRUE(hit_lower);
}

TEST(ExplorationNoise, NoneLeavesTheActionAlone) {
  ExplorationNoise noise(ExplorationNoise::Kind::kNone, 6, 0.2, 0.15, 1);
  task::ActionVector a = task::ActionVector::Constant(6, 0.3f);
  noise.apply(a);
  EXPECT_EQ(a, task::ActionVector::Constant(6, 0.3f));
}

TEST(ExplorationNoise, BadSettingsRejected) {
  EXPECT_THROW(ExplorationNoise(ExplorationNoise::Kind::kGaussian, 6, -0.1, 0.15, 1),
               std::invalid_argument);
  EXPECT_THROW(ExplorationNoise(ExplorationNoise::Kind::kOrnsteinUhlenbeck, 6, 0.2, -1.0, 1),
               std::invalid_argument);
  EXPECT_EQ(parse_noise_kind("ou"), ExplorationNoise::Kind::kOrnsteinUhlenbeck);
  EXPECT_EQ(parse_noise_kind("gaussian"), ExplorationNoise::Kind::kGaussian);
  EXPECT_EQ(parse_noise_kind("none"), ExplorationNoise::Kind::kNone);
  EXPECT_THROW(parse_noise_kind("pink"), std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::agent
