// Adam (Kingma & Ba 2015) with bias correction, optional L2 weight decay on the weights and
// optional gradient clipping by global norm, on a flat parameter vector.
#pragma once

#include <cstdint>

#include "common/nn/byte_io.hpp"
#include "common/nn/mlp.hpp"
#include "common/nn/types.hpp"

namespace auvrl::nn {

/// Adam's settings. Defaults are Kingma & Ba's, with no decay and no clipping.
struct AdamConfig {
  float learning_rate = 1e-3f;
  float beta1 = 0.9f;
  float beta2 = 0.999f;
  float epsilon = 1e-8f;
  /// L2 regularisation as in DDPG's critic (Lillicrap et al.: 1e-2): the loss gains
  /// (weight_decay / 2) * |W|^2 over the weights (not the biases), i.e. the gradient gains
  /// weight_decay * W before Adam's moments (coupled L2, not AdamW's decoupled decay).
  float weight_decay = 0.0f;
  /// If > 0, the loss gradient is scaled by max_norm / max(norm, max_norm) (global L2 norm over
  /// all parameters, as tf.clip_by_global_norm), before the weight decay term is added.
  float grad_clip_norm = 0.0f;
};

/// Adam state (first and second moments, step count) for one parameter vector.
class Adam {
 public:
  /// For `num_params` parameters of which the first `num_decayed` are weights subject to
  /// weight decay (Mlp's layout: weights first).
  Adam(AdamConfig config, Eigen::Index num_params, Eigen::Index num_decayed);
  /// For a network: every weight decayed, no bias.
  Adam(AdamConfig config, const Mlp& net) : Adam(config, net.num_params(), net.num_weights()) {}

  /// One step: params -= lr * m_hat / (sqrt(v_hat) + eps), with m_hat = m / (1 - beta1^t) and
  /// v_hat = v / (1 - beta2^t). Clipping (if on) scales `grads` in place. Returns the global
  /// norm of `grads` before clipping. Allocates nothing.
  float step(VectorRef params, VectorRef grads);
  /// Step on a network's parameters with its gradients from the last backward().
  float step(Mlp& net) { return step(net.params(), net.grads()); }

  const AdamConfig& config() const { return config_; }
  /// Changes the learning rate (schedules); the moments are kept.
  void set_learning_rate(float lr) { config_.learning_rate = lr; }
  /// Steps taken so far (t in the bias correction).
  std::int64_t steps() const { return t_; }
  const Vector& first_moment() const { return m_; }
  const Vector& second_moment() const { return v_; }

  /// Writes the moments and step count (not the config, which comes from the configuration).
  void save(Writer& w) const;
  /// Reads what save() wrote; the sizes must match this optimiser's. Leaves this optimiser
  /// unchanged if reading fails.
  void load(Reader& r);

 private:
  AdamConfig config_;
  Eigen::Index num_decayed_;
  Vector m_;
  Vector v_;
  std::int64_t t_ = 0;
};

/// Scales `grads` so that its L2 norm is at most max_norm (no-op if max_norm <= 0 or already
/// smaller); returns the norm before scaling.
float clip_by_global_norm(VectorRef grads, float max_norm);

}  // namespace auvrl::nn
