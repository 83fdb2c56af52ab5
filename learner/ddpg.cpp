// GCC 12 with -march=native on AVX-512 reports false (maybe-)uninitialized reads inside Eigen's
// vectorised kernels (its own _mm512_undefined_ps idiom, GCC bug 105593); not in our code. Before
// the includes, because the warnings are located in the headers.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include "learner/ddpg.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/nn/serialize.hpp"
#include "common/unrecoverable.hpp"

namespace auvrl::learner {
namespace {

constexpr char kMagic[8] = {'A', 'U', 'V', 'R', 'L', 'D', 'G', '\0'};
constexpr std::uint32_t kVersion = 1;

const DdpgConfig& validated(const DdpgConfig& c) {
  c.validate();
  return c;
}

nn::MlpSpec actor_spec(const DdpgConfig& c) {
  return nn::MlpSpec::actor(c.state_dim, c.actor_hidden, c.action_dim);
}

nn::MlpSpec critic_spec(const DdpgConfig& c) {
  return nn::MlpSpec::critic(c.state_dim, c.action_dim, c.critic_hidden, c.critic_action_layer);
}

/// Columns of the actor's forward pass per minibatch sample: the state, and the next state and
/// a perturbed state where the smoothness terms ask for them.
int actor_columns(const DdpgConfig& c) {
  return 1 + (c.smooth_temporal_weight > 0.0f ? 1 : 0) + (c.smooth_spatial_weight > 0.0f ? 1 : 0);
}

nn::AdamConfig adam_config(float lr, float weight_decay, float clip) {
  nn::AdamConfig a;
  a.learning_rate = lr;
  a.weight_decay = weight_decay;
  a.grad_clip_norm = clip;
  return a;
}

}  // namespace

const char* to_string(Algo a) { return a == Algo::kTd3 ? "td3" : "ddpg"; }

Algo parse_algo(const std::string& name) {
  if (name == "ddpg") return Algo::kDdpg;
  if (name == "td3") return Algo::kTd3;
  throw std::invalid_argument("unknown algorithm '" + name + "', expected ddpg or td3");
}

void DdpgConfig::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("DdpgConfig: " + what); };
  if (algo != Algo::kDdpg && algo != Algo::kTd3) bad("unknown algo");
  if (state_dim < 1 || action_dim < 1) bad("state_dim and action_dim must be set (>= 1)");
  if (batch_size < 1) bad("batch_size must be >= 1");
  if (!(gamma >= 0.0f && gamma <= 1.0f)) bad("gamma must be in [0, 1]");
  if (!(tau > 0.0f && tau <= 1.0f)) bad("tau must be in (0, 1]");
  if (actor_lr < 0.0f || critic_lr < 0.0f) bad("learning rates must be >= 0");
  if (td3_policy_delay < 1) bad("td3_policy_delay must be >= 1");
  if (td3_target_noise < 0.0f || td3_target_noise_clip < 0.0f) bad("TD3 noise must be >= 0");
  if (!(expert_weight >= 0.0f) || !std::isfinite(expert_weight)) {
    bad("expert_weight must be finite and >= 0");
  }
  if (!(expert_weight_half_life_updates >= 0.0) ||
      !std::isfinite(expert_weight_half_life_updates)) {
    bad("expert_weight_half_life_updates must be finite and >= 0");
  }
  const std::pair<float, const char*> non_negative[] = {
      {smooth_temporal_weight, "smooth_temporal_weight"},
      {smooth_spatial_weight, "smooth_spatial_weight"},
      {smooth_spatial_sigma, "smooth_spatial_sigma"}};
  for (const auto& [value, key] : non_negative) {
    if (!(value >= 0.0f) || !std::isfinite(value)) {
      bad(std::string(key) + " must be finite and >= 0");
    }
  }
  actor_spec(*this).validate();
  critic_spec(*this).validate();
}

Ddpg::Ddpg(const DdpgConfig& config)
    : config_(validated(config)),
      rng_(config.seed),
      actor_(actor_spec(config), config.batch_size * actor_columns(config)),
      actor_target_(actor_spec(config), config.batch_size),
      actor_opt_(
          adam_config(config.actor_lr, config.actor_weight_decay, config.actor_grad_clip_norm),
          actor_),
      batch_(config.state_dim, config.action_dim, config.batch_size),
      next_action_(nn::Matrix::Zero(config.action_dim, config.batch_size)),
      noise_(nn::Matrix::Zero(config.action_dim, config.batch_size)),
      target_q_(nn::Matrix::Zero(1, config.batch_size)),
      y_(nn::Matrix::Zero(1, config.batch_size)),
      dq_(nn::Matrix::Zero(1, config.batch_size)),
      q_expert_(nn::Matrix::Zero(1, config.batch_size)),
      dmu_(nn::Matrix::Zero(config.action_dim, config.batch_size * actor_columns(config))),
      actor_input_(nn::Matrix::Zero(
          config.state_dim,
          actor_columns(config) > 1 ? config.batch_size * actor_columns(config) : 0)) {
  // Line 1: initialise mu and Q (Lillicrap's scheme), from the seed.
  actor_.init_lillicrap(rng_);
  const int num_critics = config_.algo == Algo::kTd3 ? 2 : 1;
  for (int k = 0; k < num_critics; ++k) {
    critics_.emplace_back(critic_spec(config_), config_.batch_size);
    critics_.back().init_lillicrap(rng_);
    critic_opts_.emplace_back(
        adam_config(config_.critic_lr, config_.critic_weight_decay, config_.critic_grad_clip_norm),
        critics_.back());
  }
  // Line 2: Q' <- Q, mu' <- mu.
  actor_target_.copy_params_from(actor_);
  critic_targets_ = critics_;
}

UpdateStats Ddpg::update(const ReplayBuffer& replay) {
  if (replay.state_dim() != config_.state_dim || replay.action_dim() != config_.action_dim) {
    throw std::invalid_argument("Ddpg::update: replay buffer dims differ from the learner's");
  }
  // Line 12: sample a random minibatch of m transitions from R.
  replay.sample(rng_, config_.batch_size, batch_);
  return update(batch_);
}

UpdateStats Ddpg::update(const Batch& b) {
  const int n = b.size;
  if (n < 1 || n > config_.batch_size || b.state.rows() != config_.state_dim ||
      b.action.rows() != config_.action_dim) {
    throw std::invalid_argument("Ddpg::update: minibatch of the wrong size or dims");
  }
  const auto x = b.state.leftCols(n);
  const auto u = b.action.leftCols(n);
  const auto r = b.reward.leftCols(n);
  const auto x_next = b.next_state.leftCols(n);
  const auto terminal = b.terminal.leftCols(n);
  const bool td3 = config_.algo == Algo::kTd3;
  UpdateStats stats;

  // Line 14: u'_{i+1} = mu'(x_{i+1} | theta'). TD3 smooths the target policy with clipped noise.
  auto u_next = next_action_.leftCols(n);
  u_next = actor_target_.forward(x_next);
  if (td3) {
    auto eps = noise_.leftCols(n);
    nn::fill_standard_normal(rng_, eps);
    const float c = config_.td3_target_noise_clip;
    u_next = (u_next + (config_.td3_target_noise * eps).cwiseMax(-c).cwiseMin(c))
                 .cwiseMax(-1.0f)
                 .cwiseMin(1.0f);
  }

  // Line 15: y_i = r_i + gamma (1 - terminal_i) Q'(x_{i+1}, u'_{i+1} | w'). A terminal
  // transition has no future; a time-limit cut-off is not terminal and bootstraps.
  // TD3 takes the smaller of its twin targets.
  auto q_next = target_q_.leftCols(n);
  q_next = critic_targets_[0].forward(x_next, u_next);
  if (td3) q_next = q_next.cwiseMin(critic_targets_[1].forward(x_next, u_next));
  auto y = y_.leftCols(n);
  y.array() = r.array() + config_.gamma * (1.0f - terminal.array()) * q_next.array();

  // Line 17: critic step on L(w) = 1/N sum (y_i - Q(x_i, u_i | w))^2 (Eq. 8), whose gradient
  // w.r.t. each Q(x_i, u_i) is 2/N (Q - y) (Eq. 11). TD3 steps both critics toward the same y.
  auto dq = dq_.leftCols(n);
  for (std::size_t k = 0; k < critics_.size(); ++k) {
    const auto q = critics_[k].forward(x, u);
    dq = (2.0f / static_cast<float>(n)) * (q - y);
    stats.critic_loss += (q - y).squaredNorm() / static_cast<float>(n);
    if (k == 0) stats.mean_q = q.mean();
    critics_[k].backward(dq, nn::GradRequest{true, false, false});
    const float norm = critic_opts_[k].step(critics_[k]);
    if (k == 0) stats.critic_grad_norm = norm;
  }
  ++updates_;

  // Lines 18-20, every update for DDPG, every td3_policy_delay-th for TD3.
  if (!td3 || updates_ % config_.td3_policy_delay == 0) {
    actor_step(b, stats);
    // Lines 19-20: theta' <- tau theta + (1 - tau) theta', w' <- tau w + (1 - tau) w' (Eq. 7).
    nn::soft_update(actor_target_, actor_, config_.tau);
    for (std::size_t k = 0; k < critics_.size(); ++k) {
      nn::soft_update(critic_targets_[k], critics_[k], config_.tau);
    }
  }
  stats.actor_loss = last_actor_loss_;
  stats.expert_share = last_expert_share_;
  stats.smooth_temporal = last_smooth_temporal_;
  stats.smooth_spatial = last_smooth_spatial_;
  return stats;
}

// Line 18: deterministic policy gradient (Eq. 12). The actor minimises
// J(theta) = -1/N sum Q(x_i, mu(x_i | theta)), so dJ/dtheta = -1/N sum dQ/du * dmu/dtheta:
// dQ/du comes from the (just updated) critic's backward pass to its action input, then runs
// back through the actor. With expert_weight, the Q-filtered imitation term (see DdpgConfig)
// adds c * m_i * (mu(x_i) - a^E_i) to dJ/dmu, c = 2 * weight * mean|Q| / (N * action_dim).
// With the smoothness terms, one forward and one backward pass of the actor take the next and
// the perturbed states as extra columns (add_smoothness_gradients).
void Ddpg::actor_step(const Batch& b, UpdateStats& stats) {
  const Eigen::Index n = b.size;
  const auto x = b.state.leftCols(n);
  const bool imitate = expert_weight() > 0.0f && b.has_expert.leftCols(n).sum() > 0.0f;
  auto q_expert = q_expert_.leftCols(n);
  if (imitate && config_.expert_q_filter) {
    // Before the policy's own forward pass: the backward pass needs that one's activations.
    q_expert = critics_[0].forward(x, b.expert_action.leftCols(n));
  }
  const Eigen::Index columns = smoothing() ? stack_actor_inputs(b) : n;
  const auto mu_all =
      smoothing() ? actor_.forward(actor_input_.leftCols(columns)) : actor_.forward(x);
  const auto mu = mu_all.leftCols(n);
  const auto q = critics_[0].forward(x, mu);
  last_actor_loss_ = -q.mean();
  auto dq = dq_.leftCols(n);
  dq.setConstant(-1.0f / static_cast<float>(n));
  critics_[0].backward(dq, nn::GradRequest{false, false, true});
  auto dmu = dmu_.leftCols(columns);
  dmu.leftCols(n) = critics_[0].extra_input_grad();
  const float q_scale = q.cwiseAbs().mean();
  if (smoothing()) add_smoothness_gradients(n, q_scale);
  last_expert_share_ = 0.0f;
  if (imitate) {
    const float c = 2.0f * expert_weight() * q_scale / static_cast<float>(n * config_.action_dim);
    int applied = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const bool use =
          b.has_expert(0, i) > 0.5f && (!config_.expert_q_filter || q_expert(0, i) > q(0, i));
      if (!use) continue;
      dmu.col(i) += c * (mu.col(i) - b.expert_action.col(i));
      ++applied;
    }
    last_expert_share_ = static_cast<float>(applied) / static_cast<float>(n);
  }
  actor_.backward(dmu, nn::GradRequest{true, false, false});
  stats.actor_grad_norm = actor_opt_.step(actor_);
  stats.actor_updated = true;
  ++actor_updates_;
}

Eigen::Index Ddpg::stack_actor_inputs(const Batch& b) {
  const Eigen::Index n = b.size;
  Eigen::Index columns = n;
  actor_input_.leftCols(n) = b.state.leftCols(n);
  if (config_.smooth_temporal_weight > 0.0f) {
    actor_input_.middleCols(columns, n) = b.next_state.leftCols(n);
    columns += n;
  }
  perturbed_count_ = 0;
  if (config_.smooth_spatial_weight > 0.0f) {
    auto perturbed = actor_input_.middleCols(columns, n);
    nn::fill_standard_normal(rng_, perturbed);
    perturbed = b.state.leftCols(n) + config_.smooth_spatial_sigma * perturbed;
    perturbed_begin_ = columns;
    perturbed_count_ = n;
    columns += n;
  }
  return columns;
}

// CAPS: a term w * q_scale * 1/N sum_i mean_j (mu_j(x_i) - mu_j(z_i))^2, z_i the next or the
// perturbed state, adds c * (mu(x_i) - mu(z_i)) to dJ/dmu(x_i) and its negative to dJ/dmu(z_i),
// c = 2 * w * q_scale / (N * action_dim).
void Ddpg::add_smoothness_gradients(Eigen::Index n, float q_scale) {
  const auto mu_all = actor_.output();
  const auto mu = mu_all.leftCols(n);
  const float per_entry = 1.0f / static_cast<float>(n * config_.action_dim);
  Eigen::Index column = n;
  const auto term = [&](float weight, float& value) {
    const auto other = mu_all.middleCols(column, n);
    value = (mu - other).squaredNorm() * per_entry;
    const float c = 2.0f * weight * q_scale * per_entry;
    dmu_.leftCols(n) += c * (mu - other);
    dmu_.middleCols(column, n) = -c * (mu - other);
    column += n;
  };
  last_smooth_temporal_ = last_smooth_spatial_ = 0.0f;
  if (config_.smooth_temporal_weight > 0.0f) {
    term(config_.smooth_temporal_weight, last_smooth_temporal_);
  }
  if (config_.smooth_spatial_weight > 0.0f) {
    term(config_.smooth_spatial_weight, last_smooth_spatial_);
  }
}

Eigen::Block<const nn::Matrix> Ddpg::last_perturbed_states() const {
  return Eigen::Block<const nn::Matrix>(actor_input_, 0, perturbed_begin_, actor_input_.rows(),
                                        perturbed_count_);
}

float Ddpg::expert_weight() const {
  if (config_.expert_weight_half_life_updates <= 0.0) return config_.expert_weight;
  return config_.expert_weight *
         static_cast<float>(
             std::exp2(-static_cast<double>(updates_) / config_.expert_weight_half_life_updates));
}

Eigen::Block<const nn::Matrix> Ddpg::act(const nn::ConstMatrixRef& states) {
  return actor_.forward(states);
}

void Ddpg::save(std::ostream& os) const {
  nn::OStreamSink sink(os);
  nn::Writer w(sink);
  save(w);
}

void Ddpg::save(nn::Writer& w) const {
  w.bytes(kMagic, sizeof kMagic);
  w.u32(kVersion);
  w.u8(static_cast<std::uint8_t>(config_.algo));
  w.u32(static_cast<std::uint32_t>(config_.state_dim));
  w.u32(static_cast<std::uint32_t>(config_.action_dim));
  w.u32(static_cast<std::uint32_t>(critics_.size()));
  w.u64(static_cast<std::uint64_t>(updates_));
  w.u64(static_cast<std::uint64_t>(actor_updates_));
  w.f32(last_actor_loss_);
  auto net = [&](const nn::Mlp& m) {
    const std::vector<std::uint8_t> bytes = nn::network_to_bytes(m);
    w.u64(bytes.size());
    w.bytes(bytes.data(), bytes.size());
  };
  net(actor_);
  net(actor_target_);
  for (std::size_t k = 0; k < critics_.size(); ++k) {
    net(critics_[k]);
    net(critic_targets_[k]);
  }
  actor_opt_.save(w);
  for (const nn::Adam& opt : critic_opts_) opt.save(w);
  nn::write_rng(w, rng_);
  w.checksum();
}

void Ddpg::restore(std::istream& is) {
  nn::IStreamSource source(is);
  nn::Reader r(source, "learner state");
  restore(r);
}

void Ddpg::restore(nn::Reader& r) {
  r.expect_magic(kMagic);
  const std::uint32_t version = r.u32();
  if (version != kVersion) {
    r.fail("unsupported format version " + std::to_string(version) + ", expected " +
           std::to_string(kVersion));
  }
  const std::uint8_t algo = r.u8();
  const std::uint32_t state_dim = r.u32();
  const std::uint32_t action_dim = r.u32();
  const std::uint32_t num_critics = r.u32();
  if (algo != static_cast<std::uint8_t>(config_.algo) ||
      state_dim != static_cast<std::uint32_t>(config_.state_dim) ||
      action_dim != static_cast<std::uint32_t>(config_.action_dim) ||
      num_critics != critics_.size()) {
    // Sound bytes of another learner (another vehicle, layout or algorithm): no restart
    // mends that, unlike damage.
    throw UnrecoverableFault(r.context() + ": saved by a learner with algo " +
                             (algo == 1   ? "td3"
                              : algo == 0 ? "ddpg"
                                          : "?") +
                             ", state_dim " + std::to_string(state_dim) + ", action_dim " +
                             std::to_string(action_dim) + ", " + std::to_string(num_critics) +
                             " critic(s); this learner has algo " + to_string(config_.algo) +
                             ", state_dim " + std::to_string(config_.state_dim) + ", action_dim " +
                             std::to_string(config_.action_dim) + ", " +
                             std::to_string(critics_.size()) + " critic(s)");
  }
  const std::uint64_t updates = r.u64();
  const std::uint64_t actor_updates = r.u64();
  const float last_actor_loss = r.f32();

  // Everything goes into copies first, so that a failure leaves this learner as it was.
  auto net = [&](nn::Mlp& m, const char* name) {
    const std::uint64_t size = r.u64();
    if (size > (std::uint64_t{1} << 32)) r.fail(std::string(name) + ": implausible size");
    // Grown as the bytes arrive, so a damaged size field costs at most what the file holds
    // (allocating it up front took ~4 GB for a short file; found by fuzz_checkpoint).
    std::vector<std::uint8_t> bytes;
    constexpr std::uint64_t kChunk = 1 << 16;
    while (bytes.size() < size) {
      const std::size_t have = bytes.size();
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, size - have));
      bytes.resize(have + n);
      r.bytes(bytes.data() + have, n);
    }
    try {
      nn::load_network(m, bytes);
    } catch (const std::runtime_error& e) {
      r.fail(std::string(name) + ": " + e.what());
    }
  };
  nn::Mlp actor = actor_;
  nn::Mlp actor_target = actor_target_;
  std::vector<nn::Mlp> critics = critics_;
  std::vector<nn::Mlp> critic_targets = critic_targets_;
  net(actor, "actor");
  net(actor_target, "actor target");
  for (std::size_t k = 0; k < critics.size(); ++k) {
    net(critics[k], "critic");
    net(critic_targets[k], "critic target");
  }
  nn::Adam actor_opt = actor_opt_;
  std::vector<nn::Adam> critic_opts = critic_opts_;
  actor_opt.load(r);
  for (nn::Adam& opt : critic_opts) opt.load(r);
  nn::Rng rng;
  nn::read_rng(r, rng);
  r.verify_checksum();

  actor_ = std::move(actor);
  actor_target_ = std::move(actor_target);
  critics_ = std::move(critics);
  critic_targets_ = std::move(critic_targets);
  actor_opt_ = std::move(actor_opt);
  critic_opts_ = std::move(critic_opts);
  rng_ = rng;
  updates_ = static_cast<std::int64_t>(updates);
  actor_updates_ = static_cast<std::int64_t>(actor_updates);
  last_actor_loss_ = last_actor_loss;
}

}  // namespace auvrl::learner
