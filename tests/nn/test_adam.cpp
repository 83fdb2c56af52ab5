// Adam against hand-computed steps, weight decay on weights only, gradient clipping, state I/O.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12 false positive in Eigen AVX-512
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/nn/adam.hpp"
#include "common/nn/byte_io.hpp"

namespace auvrl::nn {
namespace {

Vector vec(std::initializer_list<float> v) {
  Vector out(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (float x : v) out[i++] = x;
  return out;
}

// Step 1 with lr 0.1 and default betas: m = 0.1 g, v = 0.001 g^2, m_hat = g, v_hat = g^2, so
// each parameter moves by 0.1 * g / (|g| + 1e-8), i.e. by -0.1 * sign(g).
// Step 2 with g2: m = 0.09 g1 + 0.1 g2, v = 0.000999 g1^2 + 0.001 g2^2,
// m_hat = m / 0.19, v_hat = v / 0.001999.
TEST(Adam, MatchesHandComputedSteps) {
  AdamConfig config;
  config.learning_rate = 0.1f;
  Adam adam(config, 3, 0);
  Vector p = vec({1.0f, -2.0f, 0.5f});
  Vector g1 = vec({0.1f, -0.3f, 2.0f});
  adam.step(p, g1);
  EXPECT_NEAR(p[0], 0.9f, 1e-6f);
  EXPECT_NEAR(p[1], -1.9f, 1e-6f);
  EXPECT_NEAR(p[2], 0.4f, 1e-6f);
  EXPECT_EQ(adam.steps(), 1);

  Vector g2 = vec({-0.2f, -0.1f, 1.0f});
  adam.step(p, g2);
  const double g1d[3] = {0.1, -0.3, 2.0}, g2d[3] = {-0.2, -0.1, 1.0}, p1[3] = {0.9, -1.9, 0.4};
  for (int i = 0; i < 3; ++i) {
    const double m = 0.09 * g1d[i] + 0.1 * g2d[i];
    const double v = 0.000999 * g1d[i] * g1d[i] + 0.001 * g2d[i] * g2d[i];
    const double expected = p1[i] - 0.1 * (m / 0.19) / (std::sqrt(v / 0.001999) + 1e-8);
    EXPECT_NEAR(p[i], expected, 2e-6) << i;
  }
  // The first parameter's step: m_hat = (0.009 - 0.02) / 0.19 = -0.05789...,
  // v_hat = (9.99e-6 + 4e-5) / 0.001999 = 0.025008..., step = -0.1 * m_hat / sqrt(v_hat).
  EXPECT_NEAR(p[0], 0.9 + 0.1 * 0.0578947 / 0.1581387, 2e-6);
}

// L2 decay adds weight_decay * w to the gradient of the first num_decayed entries (weights) and
// leaves the rest (biases) alone.
// The fine-tuning climbs along a direction: a step on its negative is Adam's ascent
// theta += lr m_hat / (sqrt(v_hat) + eps), moments of the direction itself.
TEST(Adam, StepOnTheNegatedDirectionAscends) {
  AdamConfig config;
  config.learning_rate = 0.01f;
  const int n = 37;  // chunks of 16 and a tail
  Adam adam(config, n, 0);
  Vector theta = Vector::LinSpaced(n, -1.0f, 1.0f);
  Vector expected = theta;
  Vector m = Vector::Zero(n), v = Vector::Zero(n);
  for (int t = 1; t <= 5; ++t) {
    Vector direction(n);
    for (int i = 0; i < n; ++i) direction[i] = std::sin(0.7f * static_cast<float>(i * t)) + 0.1f;
    m = 0.9f * m + 0.1f * direction;
    v = 0.999f * v + 0.001f * direction.cwiseProduct(direction);
    const float m_scale = 1.0f / (1.0f - std::pow(0.9f, static_cast<float>(t)));
    const float v_scale = 1.0f / (1.0f - std::pow(0.999f, static_cast<float>(t)));
    expected += 0.01f * ((m.array() * m_scale) / ((v.array() * v_scale).sqrt() + 1e-8f)).matrix();
    Vector descent = -direction;
    adam.step(theta, descent);
    for (int i = 0; i < n; ++i) EXPECT_NEAR(theta[i], expected[i], 1e-6f) << t << " " << i;
  }
}

TEST(Adam, WeightDecayAppliesToWeightsOnly) {
  AdamConfig config;
  config.learning_rate = 0.01f;
  config.weight_decay = 0.5f;
  Adam adam(config, 4, 2);
  Vector p = vec({2.0f, -1.0f, 3.0f, -4.0f});
  Vector g = vec({0.5f, 1.0f, 0.0f, 0.0f});
  adam.step(p, g);
  // Effective gradients: 0.5 + 0.5*2 = 1.5, 1 + 0.5*(-1) = 0.5, 0, 0 -> step -0.01*sign.
  EXPECT_NEAR(p[0], 1.99f, 1e-6f);
  EXPECT_NEAR(p[1], -1.01f, 1e-6f);
  EXPECT_EQ(p[2], 3.0f);  // bias: zero gradient, no decay, no move
  EXPECT_EQ(p[3], -4.0f);
  EXPECT_NEAR(adam.first_moment()[0], 0.15f, 1e-7f);
  // 1 - 0.999f is 0.00099998713 in float: relative tolerance.
  EXPECT_NEAR(adam.second_moment()[0], 0.001f * 1.5f * 1.5f, 1e-4f * 0.00225f);
  // The caller's gradient is not modified by the decay.
  EXPECT_EQ(g[0], 0.5f);

  // Second step with zero loss gradient: the decay alone pulls weights toward zero.
  Vector zero = Vector::Zero(4);
  const float w0 = p[0];
  adam.step(p, zero);
  EXPECT_LT(p[0], w0);
  EXPECT_EQ(p[2], 3.0f);
}

TEST(Adam, ClipByGlobalNorm) {
  Vector g = vec({3.0f, 4.0f});
  EXPECT_FLOAT_EQ(clip_by_global_norm(g, 10.0f), 5.0f);
  EXPECT_EQ(g, vec({3.0f, 4.0f}));  // below the limit: unchanged
  EXPECT_FLOAT_EQ(clip_by_global_norm(g, 1.0f), 5.0f);
  EXPECT_NEAR(g[0], 0.6f, 1e-7f);
  EXPECT_NEAR(g[1], 0.8f, 1e-7f);
  EXPECT_NEAR(g.norm(), 1.0f, 1e-6f);
  Vector h = vec({3.0f, 4.0f});
  clip_by_global_norm(h, 0.0f);  // off
  EXPECT_EQ(h, vec({3.0f, 4.0f}));
}

// With clipping the moments see the clipped gradient: first moment = 0.1 * clipped g.
TEST(Adam, StepUsesTheClippedGradient) {
  AdamConfig config;
  config.grad_clip_norm = 1.0f;
  Adam adam(config, 2, 2);
  Vector p = vec({0.0f, 0.0f});
  Vector g = vec({30.0f, 40.0f});
  EXPECT_FLOAT_EQ(adam.step(p, g), 50.0f);
  EXPECT_NEAR(adam.first_moment()[0], 0.1f * 0.6f, 1e-7f);
  EXPECT_NEAR(adam.first_moment()[1], 0.1f * 0.8f, 1e-7f);
  EXPECT_NEAR(adam.second_moment()[1], 0.001f * 0.64f, 1e-4f * 0.00064f);
}

TEST(Adam, LongRunBiasCorrectionStaysFinite) {
  Adam adam(AdamConfig{}, 1, 0);
  Vector p = vec({1.0f});
  Vector g = vec({1e-3f});
  for (int i = 0; i < 100000; ++i) adam.step(p, g);
  EXPECT_TRUE(std::isfinite(p[0]));
  EXPECT_NEAR(p[0], 1.0f - 100000 * 1e-3f, 0.5f);  // ~lr per step for a constant gradient
}

TEST(Adam, StateRoundTripAndSizeCheck) {
  Adam a(AdamConfig{}, 3, 1);
  Vector p = vec({1, 2, 3});
  Vector g = vec({0.1f, -0.2f, 0.3f});
  a.step(p, g);
  a.step(p, g);
  std::vector<std::uint8_t> bytes;
  VectorSink sink(bytes);
  Writer w(sink);
  a.save(w);
  w.checksum();

  Adam b(AdamConfig{}, 3, 1);
  SpanSource src(bytes);
  Reader r(src, "adam");
  b.load(r);
  r.verify_checksum();
  EXPECT_EQ(b.steps(), 2);
  EXPECT_EQ(b.first_moment(), a.first_moment());
  EXPECT_EQ(b.second_moment(), a.second_moment());
  Vector pa = p, pb = p, ga = g, gb = g;
  a.step(pa, ga);
  b.step(pb, gb);
  EXPECT_EQ(pa, pb);

  Adam c(AdamConfig{}, 4, 1);
  SpanSource src2(bytes);
  Reader r2(src2, "adam");
  EXPECT_THROW(c.load(r2), std::runtime_error);
  EXPECT_EQ(c.steps(), 0);
}

}  // namespace
}  // namespace auvrl::nn
