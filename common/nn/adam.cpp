// GCC 12 with -march=native on AVX-512 reports false (maybe-)uninitialized reads inside Eigen's
// vectorised kernels (its own _mm512_undefined_ps idiom, GCC bug 105593); not in our code. Before
// the includes, because the warnings are located in the headers.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include "common/nn/adam.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/nn/denormals.hpp"

namespace auvrl::nn {

Adam::Adam(AdamConfig config, Eigen::Index num_params, Eigen::Index num_decayed)
    : config_(config),
      num_decayed_(num_decayed),
      m_(Vector::Zero(num_params)),
      v_(Vector::Zero(num_params)) {
  if (num_decayed < 0 || num_decayed > num_params) {
    throw std::invalid_argument("Adam: num_decayed must be in 0..num_params");
  }
}

float clip_by_global_norm(VectorRef grads, float max_norm) {
  const float norm = grads.norm();
  if (max_norm > 0.0f && norm > max_norm) grads *= max_norm / norm;
  return norm;
}

float Adam::step(VectorRef params, VectorRef grads) {
  if (params.size() != m_.size() || grads.size() != m_.size()) {
    throw std::invalid_argument("Adam::step: " + std::to_string(params.size()) +
                                " parameters and " + std::to_string(grads.size()) +
                                " gradients, expected " + std::to_string(m_.size()));
  }
  const ScopedFlushDenormals flush;
  // The gradient's norm (returned for statistics) costs a pass of its own only when clipping
  // needs it before the step; otherwise the step's single pass accumulates it.
  const bool clip = config_.grad_clip_norm > 0.0f;
  float norm = 0.0f;
  float scale = 1.0f;
  if (clip) {
    norm = grads.norm();
    if (norm > config_.grad_clip_norm) {
      scale = config_.grad_clip_norm / norm;
      grads *= scale;
    }
  }
  ++t_;
  // Bias corrections in double: beta2^t stays accurate over millions of steps.
  const double bc1 = 1.0 - std::pow(static_cast<double>(config_.beta1), static_cast<double>(t_));
  const double bc2 = 1.0 - std::pow(static_cast<double>(config_.beta2), static_cast<double>(t_));
  const float inv_bc1 = static_cast<float>(1.0 / bc1);
  const float inv_bc2 = static_cast<float>(1.0 / bc2);
  const float lr = config_.learning_rate;
  const float b1 = config_.beta1;
  const float b2 = config_.beta2;
  const float eps = config_.epsilon;

  // One fused pass (the state of large networks does not fit in cache, so the pass is
  // memory-bound): weights with decay, then biases without.
  float* __restrict p = params.data();
  const float* __restrict g = grads.data();
  float* __restrict m = m_.data();
  float* __restrict v = v_.data();
  // Chunks of 16 as fixed-size Eigen arrays: one vectorised pass, with the sum of squares kept
  // in 16 partial sums.
  using Chunk = Eigen::Array<float, 16, 1>;
  Chunk sum_sq = Chunk::Zero();
  float tail_sq = 0.0f;
  auto run = [&](Eigen::Index begin, Eigen::Index end, float decay) {
    Eigen::Index i = begin;
    for (; i + 16 <= end; i += 16) {
      Eigen::Map<Chunk> pc(p + i), mc(m + i), vc(v + i);
      const Eigen::Map<const Chunk> gc(g + i);
      sum_sq += gc.square();
      const Chunk gi = gc + decay * pc;
      mc = b1 * mc + (1.0f - b1) * gi;
      vc = b2 * vc + (1.0f - b2) * gi.square();
      pc -= lr * (mc * inv_bc1) / ((vc * inv_bc2).sqrt() + eps);
    }
    for (; i < end; ++i) {
      tail_sq += g[i] * g[i];
      const float gi = g[i] + decay * p[i];
      m[i] = b1 * m[i] + (1.0f - b1) * gi;
      v[i] = b2 * v[i] + (1.0f - b2) * gi * gi;
      p[i] -= lr * (m[i] * inv_bc1) / (std::sqrt(v[i] * inv_bc2) + eps);
    }
  };
  run(0, num_decayed_, config_.weight_decay);
  run(num_decayed_, m_.size(), 0.0f);
  return clip ? norm : std::sqrt(sum_sq.sum() + tail_sq);
}

void Adam::save(Writer& w) const {
  w.u64(static_cast<std::uint64_t>(m_.size()));
  w.u64(static_cast<std::uint64_t>(t_));
  w.f32_array(m_.data(), static_cast<std::size_t>(m_.size()));
  w.f32_array(v_.data(), static_cast<std::size_t>(v_.size()));
}

void Adam::load(Reader& r) {
  const std::uint64_t n = r.u64();
  if (n != static_cast<std::uint64_t>(m_.size())) {
    r.fail("Adam state for " + std::to_string(n) + " parameters, expected " +
           std::to_string(m_.size()));
  }
  const std::uint64_t t = r.u64();
  Vector m(m_.size());
  Vector v(v_.size());
  r.f32_array(m.data(), static_cast<std::size_t>(m.size()));
  r.f32_array(v.data(), static_cast<std::size_t>(v.size()));
  m_.swap(m);
  v_.swap(v);
  t_ = static_cast<std::int64_t>(t);
}

}  // namespace auvrl::nn
