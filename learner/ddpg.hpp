// DDPG as in the paper's Algorithm 1 (Lillicrap et al. 2016), with TD3 (Fujimoto et al. 2018)
// as an option of the same class.
#pragma once

#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "common/nn/adam.hpp"
#include "common/nn/mlp.hpp"
#include "common/nn/random.hpp"
#include "learner/replay_buffer.hpp"

namespace auvrl::config {
template <class T>
class Table;
}  // namespace auvrl::config

namespace auvrl::learner {

/// Which update rule.
enum class Algo : std::uint8_t {
  kDdpg = 0,  ///< one critic, actor and targets updated every step (the paper)
  kTd3 = 1,   ///< twin critics, target policy smoothing, delayed actor and target updates
};

/// "ddpg" or "td3".
const char* to_string(Algo a);
/// Parses "ddpg" or "td3"; throws std::invalid_argument otherwise.
Algo parse_algo(const std::string& name);

/// Every hyper-parameter of the update, named once, with its paper default: Lillicrap et al.
/// (2016, section 7) for DDPG, as Algorithm 1 uses them; Fujimoto et al. (2018) for the TD3
/// additions, which only act when algo == kTd3. state_dim and action_dim have no default: they
/// are the task's.
struct DdpgConfig {
  Algo algo = Algo::kDdpg;
  int state_dim = 0;
  int action_dim = 0;

  std::vector<int> actor_hidden{400, 300};   ///< hidden units of mu
  std::vector<int> critic_hidden{400, 300};  ///< hidden units of Q
  /// Weight layer of Q that receives the action: 1 = concatenated to the first hidden layer's
  /// output ("actions were not included until the 2nd hidden layer of Q"); 0 = with the state.
  int critic_action_layer = 1;

  float actor_lr = 1e-4f;   ///< Adam learning rate of mu
  float critic_lr = 1e-3f;  ///< Adam learning rate of Q
  /// L2 weight decay of Q, on its weights (every layer), not its biases (see nn::AdamConfig).
  float critic_weight_decay = 1e-2f;
  float actor_weight_decay = 0.0f;
  float actor_grad_clip_norm = 0.0f;   ///< global-norm clipping of mu's gradient; 0: off
  float critic_grad_clip_norm = 0.0f;  ///< global-norm clipping of Q's gradient; 0: off

  float gamma = 0.99f;  ///< discount
  float tau = 1e-3f;    ///< soft target update rate (Eq. 7)
  int batch_size = 64;  ///< minibatch size m (also the largest batch the networks accept)
  /// Capacity of R. Not used by this class (the caller owns the ReplayBuffer) but named here so
  /// that the whole preset lives in one place.
  std::size_t replay_capacity = 1000000;

  float td3_target_noise = 0.2f;       ///< std of the target policy smoothing noise
  float td3_target_noise_clip = 0.5f;  ///< the noise is clipped to +-this
  int td3_policy_delay = 2;            ///< critic updates per actor and target update

  /// Q-filtered imitation of an expert (Nair et al. 2018, "Overcoming exploration in RL with
  /// demonstrations"): the actor's loss gains
  ///   expert_weight * mean|Q| * 1/N sum_i m_i * mean_j (mu_j(x_i) - a^E_ij)^2,
  /// where a^E is the expert's label stored with the transition and m_i = 1 only where the
  /// transition has a label and the critic rates the expert's action above the policy's
  /// (Q(x_i, a^E_i) > Q(x_i, mu(x_i))), so the policy copies the expert only where the expert is
  /// better and is free to surpass it elsewhere. mean|Q| (not differentiated) makes the weight
  /// independent of the reward's scale, as in TD3+BC (Fujimoto and Gu 2021; its alpha = 2.5
  /// is a weight of 0.4 here). 0: off.
  float expert_weight = 0.0f;
  /// The weight halves every this many updates (a guide early, RL alone later); 0: constant.
  double expert_weight_half_life_updates = 0.0;
  /// Apply the imitation term only where the critic prefers the expert's action (the Q
  /// filter); false: wherever there is a label.
  bool expert_q_filter = true;

  /// Smooth control, CAPS (Mysore et al. 2021, "Regularizing Action Policies for Smooth Control
  /// with Reinforcement Learning"): the actor's loss gains a temporal term
  ///   smooth_temporal_weight * mean|Q| * 1/N sum_i mean_j (mu_j(x_i) - mu_j(x'_i))^2,
  /// x'_i the transition's next state (one step later, commands alike), and a spatial term
  ///   smooth_spatial_weight * mean|Q| * 1/N sum_i mean_j (mu_j(x_i) - mu_j(x_i + e_i))^2,
  /// e_i ~ N(0, smooth_spatial_sigma^2 I) on the network's input (similar states, similar
  /// commands), with gradients through both policy outputs of each term. mean|Q| (not
  /// differentiated), as for expert_weight, makes the weights independent of the reward's scale
  /// (CAPS weighs its terms against raw Q). 0: off.
  float smooth_temporal_weight = 0.0f;
  float smooth_spatial_weight = 0.0f;
  /// Standard deviation of the spatial term's perturbation, in the network's input units (the
  /// task's scaled observation).
  float smooth_spatial_sigma = 0.05f;

  std::uint64_t seed = 1;  ///< initial weights, minibatch sampling and TD3 noise

  /// Throws std::invalid_argument naming the first unusable value.
  void validate() const;
};

/// The keys of DdpgConfig in a `learner:` section (learner/learner_config.cpp).
const config::Table<DdpgConfig>& ddpg_table();

/// What one update reports.
struct UpdateStats {
  float critic_loss = 0;  ///< mean squared TD error before the step (TD3: sum over both critics)
  float actor_loss = 0;   ///< -mean Q(x, mu(x)) of the actor step (last one if none this update)
  float mean_q = 0;       ///< mean Q(x, u) over the minibatch (first critic), before the step
  bool actor_updated = false;  ///< false on TD3's delayed steps
  float critic_grad_norm = 0;  ///< global norm of the (first) critic's loss gradient
  float actor_grad_norm = 0;   ///< global norm of the actor's loss gradient (if updated)
  /// Share of the actor step's minibatch the imitation term applied to (labelled and, with
  /// the Q filter, rated better than the policy); 0 without expert_weight.
  float expert_share = 0;
  /// The actor step's 1/N sum_i mean_j (mu_j(x_i) - mu_j(x'_i))^2 and the same for the
  /// perturbed states, before the step; 0 where the term is off.
  float smooth_temporal = 0;
  float smooth_spatial = 0;
};

/// The learner's networks, optimisers and update rule. Construction is Algorithm 1's lines 1-2
/// (networks initialised from config.seed, targets copied from them); update() is lines 12-20.
/// Nothing is allocated per update. Not thread-safe.
class Ddpg {
 public:
  explicit Ddpg(const DdpgConfig& config);

  /// Lines 12-20: samples a minibatch of config.batch_size from `replay` and learns from it.
  UpdateStats update(const ReplayBuffer& replay);
  /// Lines 13-20 on a given minibatch (1 <= batch.size <= config.batch_size).
  UpdateStats update(const Batch& batch);

  /// Deterministic policy mu(x) for a batch of states (state_dim x n, n <= batch_size); valid
  /// until the next call or update.
  Eigen::Block<const nn::Matrix> act(const nn::ConstMatrixRef& states);

  const DdpgConfig& config() const { return config_; }
  const nn::Mlp& actor() const { return actor_; }
  const nn::Mlp& actor_target() const { return actor_target_; }
  /// Critic i (0, or 0 and 1 for TD3) and its target.
  const nn::Mlp& critic(int i = 0) const { return critics_[static_cast<std::size_t>(i)]; }
  const nn::Mlp& critic_target(int i = 0) const {
    return critic_targets_[static_cast<std::size_t>(i)];
  }
  int num_critics() const { return static_cast<int>(critics_.size()); }
  /// The imitation weight now: expert_weight, halved every expert_weight_half_life_updates.
  float expert_weight() const;
  /// Updates done (critic steps).
  std::int64_t updates() const { return updates_; }
  /// Actor steps done (fewer than updates() with TD3's delay).
  std::int64_t actor_updates() const { return actor_updates_; }
  /// The perturbed states x_i + e_i of the last actor step's spatial smoothness term
  /// (state_dim x N; empty when the term is off), for tests.
  Eigen::Block<const nn::Matrix> last_perturbed_states() const;

  /// Writes the full learning state (networks, targets, Adam moments, step counters, random
  /// generator) as one self-checking record:
  ///   char[8] "AUVRLDG\0", u32 version (1), u8 algo, u32 state_dim, u32 action_dim,
  ///   u32 number of critics, u64 updates, u64 actor updates, f32 last actor loss,
  ///   then each network as u64 length + its nn format (actor, actor target, then each critic
  ///   and its target), the Adam states (actor, then each critic), the generator state, and
  ///   the CRC-32 of all of it. The hyper-parameters are not in it: they come from the
  ///   configuration.
  void save(std::ostream& os) const;
  void save(nn::Writer& w) const;
  /// Restores a record written by save() from a learner of the same algorithm and network
  /// architectures. Throws std::runtime_error saying what differs or what is damaged; the
  /// learner is unchanged then. After restore, updates continue exactly as they would have.
  void restore(std::istream& is);
  void restore(nn::Reader& r);

 private:
  void actor_step(const Batch& b, UpdateStats& stats);
  /// The columns of the actor's forward pass: the minibatch's states, then the next states
  /// (temporal term), then the perturbed states (spatial term); returns how many.
  Eigen::Index stack_actor_inputs(const Batch& b);
  /// Adds the smoothness terms' gradients (CAPS) to dmu_ (all stacked columns), scaled by
  /// q_scale = mean|Q|, and records the terms' values.
  void add_smoothness_gradients(Eigen::Index n, float q_scale);
  bool smoothing() const {
    return config_.smooth_temporal_weight > 0.0f || config_.smooth_spatial_weight > 0.0f;
  }

  DdpgConfig config_;
  nn::Rng rng_;
  nn::Mlp actor_;
  nn::Mlp actor_target_;
  std::vector<nn::Mlp> critics_;
  std::vector<nn::Mlp> critic_targets_;
  nn::Adam actor_opt_;
  std::vector<nn::Adam> critic_opts_;
  std::int64_t updates_ = 0;
  std::int64_t actor_updates_ = 0;
  float last_actor_loss_ = 0;
  // Workspaces, sized for batch_size.
  Batch batch_;
  nn::Matrix next_action_;  // u'_{i+1} (action_dim x m)
  nn::Matrix noise_;        // TD3 target smoothing noise (action_dim x m)
  nn::Matrix target_q_;     // Q'(x_{i+1}, u'_{i+1}) (1 x m)
  nn::Matrix y_;            // targets y_i (1 x m)
  nn::Matrix dq_;           // dL/dQ (1 x m)
  nn::Matrix q_expert_;     // Q(x_i, a^E_i) (1 x m)
  nn::Matrix dmu_;          // dL/dmu (action_dim x m, or x up to 3m with smoothness terms)
  nn::Matrix actor_input_;  // smoothness: [x_i | x'_i | x_i + e_i] (state_dim x up to 3m)
  Eigen::Index perturbed_begin_ = 0, perturbed_count_ = 0;  // columns of x_i + e_i in it
  float last_expert_share_ = 0;
  float last_smooth_temporal_ = 0, last_smooth_spatial_ = 0;
};

}  // namespace auvrl::learner
