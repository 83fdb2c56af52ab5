// DDPG/TD3 update: targets and losses against a hand computation, terminal handling, which
// networks move when, TD3's delay, the Q-filtered imitation term (gradient against finite
// differences, the filter, its effect), the smoothness terms (CAPS: gradient against finite
// differences, their effect, off changes nothing), allocation-free updates, and exact
// save/restore.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12 false positive in Eigen AVX-512
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "alloc_counter.hpp"
#include "learner/bench.hpp"
#include "learner/ddpg.hpp"

namespace auvrl::learner {
namespace {

DdpgConfig small_config(Algo algo) {
  DdpgConfig c;
  c.algo = algo;
  c.state_dim = 5;
  c.action_dim = 2;
  c.actor_hidden = {16, 12};
  c.critic_hidden = {16, 12};
  c.batch_size = 8;
  c.seed = 3;
  return c;
}

Batch random_batch(nn::Rng& rng, int s, int a, int n, float terminal_fraction) {
  Batch b(s, a, n);
  b.size = n;
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < s; ++i) {
      b.state(i, k) = nn::uniform(rng, -1, 1);
      b.next_state(i, k) = nn::uniform(rng, -1, 1);
    }
    for (int i = 0; i < a; ++i) b.action(i, k) = nn::uniform(rng, -1, 1);
    b.reward(0, k) = nn::uniform(rng, -2, 1);
    b.terminal(0, k) = nn::uniform01(rng) < terminal_fraction ? 1.0f : 0.0f;
  }
  return b;
}

ReplayBuffer random_replay(nn::Rng& rng, int s, int a, int n) {
  ReplayBuffer rb(s, a, static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Batch one = random_batch(rng, s, a, 1, 0.1f);
    rb.add(TransitionView{one.state.col(0), one.action.col(0), one.reward(0, 0),
                          one.next_state.col(0), one.terminal(0, 0) > 0, Eigen::Vector3f::Zero(),
                          Eigen::Vector3f::Zero(), 0, static_cast<std::uint32_t>(i)});
  }
  return rb;
}

// A copy of a network to evaluate on the side without touching the learner's workspaces.
nn::Matrix eval(const nn::Mlp& net, const nn::Matrix& x, const nn::Matrix& u = nn::Matrix()) {
  nn::Mlp copy = net;
  return u.size() ? nn::Matrix(copy.forward(x, u)) : nn::Matrix(copy.forward(x));
}

TEST(DdpgConfig, DefaultsAreLillicrapsAndValidated) {
  const DdpgConfig c;
  EXPECT_EQ(c.algo, Algo::kDdpg);
  EXPECT_FLOAT_EQ(c.actor_lr, 1e-4f);
  EXPECT_FLOAT_EQ(c.critic_lr, 1e-3f);
  EXPECT_FLOAT_EQ(c.critic_weight_decay, 1e-2f);
  EXPECT_FLOAT_EQ(c.gamma, 0.99f);
  EXPECT_FLOAT_EQ(c.tau, 1e-3f);
  EXPECT_EQ(c.batch_size, 64);
  EXPECT_EQ(c.actor_hidden, (std::vector<int>{400, 300}));
  EXPECT_EQ(c.critic_hidden, (std::vector<int>{400, 300}));
  EXPECT_EQ(c.critic_action_layer, 1);
  EXPECT_EQ(c.replay_capacity, 1000000u);
  EXPECT_THROW(c.validate(), std::invalid_argument);  // dims are the task's: not set
  DdpgConfig d = small_config(Algo::kDdpg);
  d.validate();
  d.tau = 0;
  EXPECT_THROW(d.validate(), std::invalid_argument);
  EXPECT_EQ(c.expert_weight, 0.0f);  // imitation is an addition of ours: off by default
  d = small_config(Algo::kDdpg);
  d.expert_weight = -0.1f;
  EXPECT_THROW(d.validate(), std::invalid_argument);
  d.expert_weight = std::nanf("");
  EXPECT_THROW(d.validate(), std::invalid_argument);
  EXPECT_EQ(parse_algo("td3"), Algo::kTd3);
  EXPECT_THROW(parse_algo("sac"), std::invalid_argument);
}

TEST(Ddpg, TargetsStartAsCopiesAndSeedsAreReproducible) {
  Ddpg a(small_config(Algo::kTd3)), b(small_config(Algo::kTd3));
  EXPECT_EQ(a.num_critics(), 2);
  EXPECT_EQ(a.actor().params(), a.actor_target().params());
  EXPECT_EQ(a.critic(1).params(), a.critic_target(1).params());
  EXPECT_NE(a.critic(0).params(), a.critic(1).params());
  EXPECT_EQ(a.actor().params(), b.actor().params());
  DdpgConfig other = small_config(Algo::kTd3);
  other.seed = 4;
  EXPECT_NE(Ddpg(other).actor().params(), a.actor().params());
  EXPECT_EQ(Ddpg(small_config(Algo::kDdpg)).num_critics(), 1);
}

// Lines 14-17 by hand: y = r + gamma (1 - terminal) Q'(x', mu'(x')), loss = mean (Q - y)^2.
TEST(Ddpg, CriticLossAndMeanQMatchAHandComputation) {
  for (Algo algo : {Algo::kDdpg, Algo::kTd3}) {
    DdpgConfig config = small_config(algo);
    config.td3_target_noise = 0.0f;  // so the TD3 target is deterministic
    Ddpg learner(config);
    nn::Rng rng(17);
    const Batch b = random_batch(rng, 5, 2, 8, 0.5f);
    const nn::Matrix u_next = eval(learner.actor_target(), b.next_state);
    nn::Matrix q_next = eval(learner.critic_target(0), b.next_state, u_next);
    if (algo == Algo::kTd3) {
      q_next = q_next.cwiseMin(eval(learner.critic_target(1), b.next_state, u_next));
    }
    const nn::Matrix y =
        (b.reward.array() + 0.99f * (1.0f - b.terminal.array()) * q_next.array()).matrix();
    float expected_loss = 0;
    for (int k = 0; k < learner.num_critics(); ++k) {
      expected_loss += (eval(learner.critic(k), b.state, b.action) - y).squaredNorm() / 8;
    }
    const float expected_mean_q = eval(learner.critic(0), b.state, b.action).mean();

    const UpdateStats stats = learner.update(b);
    EXPECT_NEAR(stats.critic_loss, expected_loss, 1e-5f * (1 + expected_loss)) << to_string(algo);
    EXPECT_NEAR(stats.mean_q, expected_mean_q, 1e-6f) << to_string(algo);
    EXPECT_GT(stats.critic_grad_norm, 0.0f);
  }
}

// A terminal transition's target is its reward alone, whatever Q' says.
TEST(Ddpg, TerminalTransitionsDoNotBootstrap) {
  DdpgConfig config = small_config(Algo::kDdpg);
  config.gamma = 1.0f;
  Ddpg learner(config);
  nn::Rng rng(2);
  Batch b = random_batch(rng, 5, 2, 8, 0.0f);
  b.terminal.setOnes();
  const nn::Matrix q = eval(learner.critic(0), b.state, b.action);
  const float expected = (q - b.reward).squaredNorm() / 8;
  EXPECT_NEAR(learner.update(b).critic_loss, expected, 1e-5f * (1 + expected));
}

// One DDPG update moves the critic, the actor, and both targets by tau of the way.
TEST(Ddpg, UpdateMovesNetworksAndTargetsSoftly) {
  DdpgConfig config = small_config(Algo::kDdpg);
  config.tau = 0.1f;
  Ddpg learner(config);
  const nn::Vector actor0 = learner.actor().params();
  const nn::Vector critic0 = learner.critic().params();
  const nn::Vector actor_target0 = learner.actor_target().params();
  nn::Rng rng(4);
  const UpdateStats stats = learner.update(random_batch(rng, 5, 2, 8, 0.2f));
  EXPECT_TRUE(stats.actor_updated);
  EXPECT_NE(learner.actor().params(), actor0);
  EXPECT_NE(learner.critic().params(), critic0);
  const nn::Vector expected_target = 0.1f * learner.actor().params() + 0.9f * actor_target0;
  EXPECT_LT((learner.actor_target().params() - expected_target).cwiseAbs().maxCoeff(), 1e-7f);
  EXPECT_EQ(learner.updates(), 1);
  EXPECT_EQ(learner.actor_updates(), 1);
  // The actor loss is -mean Q(x, mu(x)) under the updated critic.
  EXPECT_TRUE(std::isfinite(stats.actor_loss));
}

// The actor step follows dQ/da: after a step with a large learning rate on a fixed critic,
// Q(x, mu(x)) is higher.
TEST(Ddpg, ActorStepIncreasesQ) {
  DdpgConfig config = small_config(Algo::kDdpg);
  config.critic_lr = 0.0f;  // freeze Q so that only the actor moves
  config.actor_lr = 1e-2f;
  Ddpg learner(config);
  nn::Rng rng(6);
  const Batch b = random_batch(rng, 5, 2, 8, 0.0f);
  const UpdateStats first = learner.update(b);
  UpdateStats last = first;
  for (int i = 0; i < 20; ++i) last = learner.update(b);
  EXPECT_LT(last.actor_loss, first.actor_loss);
}

TEST(Ddpg, ZeroLearningRatesFreezeTheirNetworks) {
  DdpgConfig config = small_config(Algo::kDdpg);
  config.actor_lr = 0.0f;
  Ddpg frozen_actor(config);
  const nn::Vector a0 = frozen_actor.actor().params();
  nn::Rng rng(8);
  frozen_actor.update(random_batch(rng, 5, 2, 8, 0.1f));
  EXPECT_EQ(frozen_actor.actor().params(), a0);
  config.actor_lr = 1e-4f;
  config.critic_lr = 0.0f;
  Ddpg frozen_critic(config);
  const nn::Vector c0 = frozen_critic.critic().params();
  frozen_critic.update(random_batch(rng, 5, 2, 8, 0.1f));
  EXPECT_EQ(frozen_critic.critic().params(), c0);
}

// TD3: the actor and all targets move only every td3_policy_delay-th update.
TEST(Ddpg, Td3DelaysActorAndTargetUpdates) {
  DdpgConfig config = small_config(Algo::kTd3);
  config.td3_policy_delay = 3;
  Ddpg learner(config);
  nn::Rng rng(10);
  const nn::Vector actor0 = learner.actor().params();
  const nn::Vector target0 = learner.critic_target(1).params();
  const nn::Vector critic1 = learner.critic(1).params();
  for (int i = 1; i <= 2; ++i) {
    EXPECT_FALSE(learner.update(random_batch(rng, 5, 2, 8, 0.1f)).actor_updated);
  }
  EXPECT_EQ(learner.actor().params(), actor0);
  EXPECT_EQ(learner.critic_target(1).params(), target0);
  EXPECT_NE(learner.critic(1).params(), critic1);  // both critics learn every update
  EXPECT_TRUE(learner.update(random_batch(rng, 5, 2, 8, 0.1f)).actor_updated);
  EXPECT_NE(learner.actor().params(), actor0);
  EXPECT_NE(learner.critic_target(1).params(), target0);
  EXPECT_EQ(learner.updates(), 3);
  EXPECT_EQ(learner.actor_updates(), 1);
}

// Expert labels on every column of b (action_dim x n), with has_expert where `labelled`.
void label(Batch& b, nn::Rng& rng, float labelled_fraction) {
  for (int k = 0; k < b.size; ++k) {
    b.has_expert(0, k) = nn::uniform01(rng) < labelled_fraction ? 1.0f : 0.0f;
    for (int i = 0; i < b.expert_action.rows(); ++i)
      b.expert_action(i, k) = nn::uniform(rng, -1, 1);
  }
}

// The actor's loss with the imitation term, as DdpgConfig documents it, evaluated on the side:
// -mean Q(x, mu(x)) + weight * q_scale * 1/N sum_i m_i mean_j (mu_ij - a^E_ij)^2, with the scale
// and the mask held fixed (they are not differentiated).
double imitation_loss(const nn::Mlp& actor, const nn::Mlp& critic, const Batch& b,
                      const std::vector<bool>& mask, double weight, double q_scale) {
  const int n = b.size;
  const nn::Matrix x = b.state.leftCols(n);
  const nn::Matrix mu = eval(actor, x);
  const nn::Matrix q = eval(critic, x, mu);
  double loss = -static_cast<double>(q.mean());
  for (int i = 0; i < n; ++i) {
    if (!mask[static_cast<std::size_t>(i)]) continue;
    const double sq = (mu.col(i) - b.expert_action.col(i)).cast<double>().squaredNorm();
    loss += weight * q_scale * sq / (n * mu.rows());
  }
  return loss;
}

// The actor's gradient with the Q-filtered imitation term against central differences of the
// loss above along the gradient and along a random direction, and the filter's mask against
// the critic evaluated on the side. The critic first learns from large rewards so that
// mean|Q| (the term's scale) is far from its near-zero initial value; the actor's learning
// rate is 0, so the gradient is taken at the actor's initial parameters.
TEST(Ddpg, ImitationTermGradientMatchesFiniteDifferences) {
  for (bool q_filter : {false, true}) {
    DdpgConfig config = small_config(Algo::kDdpg);
    config.actor_lr = 0.0f;
    config.critic_lr = 1e-2f;
    config.critic_weight_decay = 0.0f;
    config.expert_weight = 0.5f;
    config.expert_q_filter = q_filter;
    Ddpg learner(config);
    nn::Rng rng(21);
    Batch b = random_batch(rng, 5, 2, 8, 0.0f);
    b.reward.leftCols(b.size).array() += 20.0f;
    label(b, rng, 0.75f);
    for (int i = 0; i < 200; ++i) learner.update(b);
    const nn::Mlp actor0 = learner.actor();

    const UpdateStats stats = learner.update(b);
    ASSERT_TRUE(stats.actor_updated);
    const nn::Vector grad = learner.actor().grads();
    const nn::Mlp& critic = learner.critic();  // the actor step used the just-updated critic

    const nn::Matrix x = b.state.leftCols(b.size);
    const nn::Matrix mu0 = eval(actor0, x);
    const nn::Matrix q_mu = eval(critic, x, mu0);
    const nn::Matrix q_expert = eval(critic, x, b.expert_action.leftCols(b.size));
    std::vector<bool> mask, none(static_cast<std::size_t>(b.size), false);
    int applied = 0;
    for (int i = 0; i < b.size; ++i) {
      mask.push_back(b.has_expert(0, i) > 0.5f && (!q_filter || q_expert(0, i) > q_mu(0, i)));
      applied += mask.back() ? 1 : 0;
    }
    EXPECT_FLOAT_EQ(stats.expert_share, static_cast<float>(applied) / b.size);
    const double q_scale = q_mu.cwiseAbs().mean();
    ASSERT_GT(q_scale, 10.0);
    ASSERT_GT(applied, 0);

    nn::Vector random_dir(grad.size());
    for (Eigen::Index i = 0; i < random_dir.size(); ++i) random_dir[i] = nn::uniform(rng, -1, 1);
    for (const nn::Vector& dir :
         {nn::Vector(grad.normalized()), nn::Vector(random_dir.normalized())}) {
      const float eps = 1e-3f;
      nn::Mlp plus = actor0, minus = actor0;
      plus.params() += eps * dir;
      minus.params() -= eps * dir;
      auto slope = [&](const std::vector<bool>& m) {
        return (imitation_loss(plus, critic, b, m, 0.5, q_scale) -
                imitation_loss(minus, critic, b, m, 0.5, q_scale)) /
               (2.0 * eps);
      };
      const double numeric = slope(mask);
      const double analytic = grad.dot(dir);
      const double tolerance = 0.02 * grad.norm();
      EXPECT_NEAR(analytic, numeric, tolerance) << "q_filter " << q_filter;
      // The imitation term is a real part of the gradient: leaving it out misses it.
      if (dir.dot(grad) > 0.99f * grad.norm()) {
        EXPECT_GT(std::abs(slope(none) - numeric), 5 * tolerance) << "q_filter " << q_filter;
      }
    }
  }
}

// Without labels (or with a weight of 0) the imitation term changes nothing; with labels and
// no Q filter, a frozen critic and a large weight, the policy moves onto the expert's actions.
TEST(Ddpg, ImitationNeedsLabelsAndPullsThePolicyToTheExpert) {
  DdpgConfig config = small_config(Algo::kDdpg);
  config.critic_lr = 0.0f;
  config.actor_lr = 1e-2f;
  nn::Rng rng(22);
  Batch b = random_batch(rng, 5, 2, 8, 0.0f);
  label(b, rng, 1.0f);
  b.expert_action.leftCols(b.size) *= 0.8f;  // inside tanh's range
  Batch unlabelled = b;
  unlabelled.has_expert.setZero();

  DdpgConfig plain_config = config;
  Ddpg plain(plain_config);
  config.expert_weight = 50.0f;
  config.expert_q_filter = false;
  Ddpg no_labels(config), imitating(config);
  for (int i = 0; i < 5; ++i) {
    plain.update(b);
    EXPECT_EQ(no_labels.update(unlabelled).expert_share, 0.0f);
  }
  EXPECT_EQ(no_labels.actor().params(), plain.actor().params());

  const nn::Matrix x = b.state.leftCols(b.size);
  const nn::Matrix target = b.expert_action.leftCols(b.size);
  const double before = (eval(imitating.actor(), x) - target).norm();
  for (int i = 0; i < 300; ++i) EXPECT_EQ(imitating.update(b).expert_share, 1.0f);
  const double after = (eval(imitating.actor(), x) - target).norm();
  EXPECT_LT(after, 0.2 * before) << before << " -> " << after;
}

// The imitation weight halves every expert_weight_half_life_updates updates (0: constant).
TEST(Ddpg, ImitationWeightHalvesEveryHalfLife) {
  DdpgConfig config = small_config(Algo::kTd3);
  config.expert_weight = 0.8f;
  Ddpg constant(config);
  config.expert_weight_half_life_updates = 4;
  Ddpg halving(config);
  nn::Rng rng(23);
  const Batch b = random_batch(rng, 5, 2, 8, 0.1f);
  EXPECT_FLOAT_EQ(halving.expert_weight(), 0.8f);
  for (int i = 0; i < 8; ++i) {
    halving.update(b);
    constant.update(b);
  }
  EXPECT_FLOAT_EQ(halving.expert_weight(), 0.2f);
  halving.update(b);
  EXPECT_FLOAT_EQ(halving.expert_weight(), 0.8f * std::exp2(-9.0f / 4.0f));
  EXPECT_FLOAT_EQ(constant.expert_weight(), 0.8f);
  config.expert_weight_half_life_updates = -1;
  EXPECT_THROW(config.validate(), std::invalid_argument);
}

TEST(DdpgConfig, SmoothnessIsOffByDefaultAndNegativeWeightsAreRefusedNamingTheKey) {
  const DdpgConfig c;
  EXPECT_EQ(c.smooth_temporal_weight, 0.0f);
  EXPECT_EQ(c.smooth_spatial_weight, 0.0f);
  for (const char* key :
       {"smooth_temporal_weight", "smooth_spatial_weight", "smooth_spatial_sigma"}) {
    for (float bad : {-0.1f, std::nanf(""), INFINITY}) {
      DdpgConfig d = small_config(Algo::kTd3);
      float& value = std::string(key) == "smooth_temporal_weight"  ? d.smooth_temporal_weight
                     : std::string(key) == "smooth_spatial_weight" ? d.smooth_spatial_weight
                                                                   : d.smooth_spatial_sigma;
      value = bad;
      try {
        d.validate();
        ADD_FAILURE() << key << " = " << bad << " was accepted";
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      }
    }
  }
}

// The actor's loss with the smoothness terms, as DdpgConfig documents it, evaluated on the side:
// -mean Q(x, mu(x)) + q_scale * (w_T D(x, x') + w_S D(x, z)), D(a, b) = 1/N sum_i mean_j
// (mu_j(a_i) - mu_j(b_i))^2, z the perturbed states the learner drew; q_scale held fixed.
double smoothness_loss(const nn::Mlp& actor, const nn::Mlp& critic, const Batch& b,
                       const nn::Matrix& perturbed, double w_t, double w_s, double q_scale) {
  const int n = b.size;
  const nn::Matrix x = b.state.leftCols(n);
  const nn::Matrix mu = eval(actor, x);
  const double entries = static_cast<double>(n) * static_cast<double>(mu.rows());
  double loss = -static_cast<double>(eval(critic, x, mu).mean());
  if (w_t > 0) {
    const nn::Matrix next = eval(actor, nn::Matrix(b.next_state.leftCols(n)));
    loss += w_t * q_scale * (mu - next).cast<double>().squaredNorm() / entries;
  }
  if (w_s > 0) {
    const nn::Matrix other = eval(actor, perturbed);
    loss += w_s * q_scale * (mu - other).cast<double>().squaredNorm() / entries;
  }
  return loss;
}

// The actor's gradient with the temporal term, the spatial term and both, against central
// differences of the loss above along the gradient and a random direction. As for imitation, the
// critic first learns from large rewards (mean|Q| far from 0); the actor learns too, without
// the terms (its initial commands are all near 0, so the terms would be near 0); then a learner
// with the terms and an actor's rate of 0 takes over that state for the step checked.
TEST(Ddpg, SmoothnessTermsGradientMatchesFiniteDifferences) {
  for (const auto& [w_t, w_s] : {std::pair{20.0f, 0.0f}, {0.0f, 20.0f}, {10.0f, 20.0f}}) {
    DdpgConfig config = small_config(Algo::kDdpg);
    config.actor_lr = 1e-3f;
    config.critic_lr = 1e-2f;
    config.critic_weight_decay = 0.0f;
    Ddpg trained(config);
    nn::Rng rng(31);
    Batch b = random_batch(rng, 5, 2, 8, 0.0f);
    b.reward.leftCols(b.size).array() += 20.0f;
    for (int i = 0; i < 200; ++i) trained.update(b);
    std::stringstream saved;
    trained.save(saved);
    config.actor_lr = 0.0f;
    config.smooth_temporal_weight = w_t;
    config.smooth_spatial_weight = w_s;
    config.smooth_spatial_sigma = 0.3f;
    Ddpg learner(config);
    learner.restore(saved);
    const nn::Mlp actor0 = learner.actor();

    const UpdateStats stats = learner.update(b);
    ASSERT_TRUE(stats.actor_updated);
    const nn::Vector grad = learner.actor().grads();
    const nn::Mlp& critic = learner.critic();
    const nn::Matrix perturbed = learner.last_perturbed_states();
    ASSERT_EQ(perturbed.cols(), w_s > 0 ? b.size : 0);
    const nn::Matrix x = b.state.leftCols(b.size);
    const double q_scale = eval(critic, x, eval(actor0, x)).cwiseAbs().mean();
    ASSERT_GT(q_scale, 10.0);
    // The terms' values as reported.
    const auto term = [&](const nn::Matrix& z) {
      return (eval(actor0, x) - eval(actor0, z)).squaredNorm() / (b.size * 2.0);
    };
    if (w_t > 0) {
      EXPECT_NEAR(stats.smooth_temporal, term(b.next_state.leftCols(b.size)), 1e-6);
    }
    if (w_s > 0) {
      EXPECT_NEAR(stats.smooth_spatial, term(perturbed), 1e-6);
      EXPECT_GT(stats.smooth_spatial, 0.0f);
      const double spread = std::sqrt((perturbed - x).squaredNorm() / (5.0 * b.size));
      EXPECT_NEAR(spread, 0.3, 0.12);  // the perturbation's standard deviation
    }

    nn::Vector random_dir(grad.size());
    for (Eigen::Index i = 0; i < random_dir.size(); ++i) random_dir[i] = nn::uniform(rng, -1, 1);
    for (const nn::Vector& dir :
         {nn::Vector(grad.normalized()), nn::Vector(random_dir.normalized())}) {
      const float eps = 1e-3f;
      nn::Mlp plus = actor0, minus = actor0;
      plus.params() += eps * dir;
      minus.params() -= eps * dir;
      const auto slope = [&](double t, double sp) {
        return (smoothness_loss(plus, critic, b, perturbed, t, sp, q_scale) -
                smoothness_loss(minus, critic, b, perturbed, t, sp, q_scale)) /
               (2.0 * eps);
      };
      const double numeric = slope(w_t, w_s);
      const double tolerance = 0.02 * grad.norm();
      EXPECT_NEAR(grad.dot(dir), numeric, tolerance) << w_t << " " << w_s;
      // The terms are a real part of the gradient: leaving them out misses it.
      if (dir.dot(grad) > 0.99f * grad.norm()) {
        EXPECT_GT(std::abs(slope(0, 0) - numeric), 5 * tolerance) << w_t << " " << w_s;
      }
    }
  }
}

// On a fixed batch, the temporal term brings the commands in x and x' together and the spatial
// term those in x and nearby states, compared with the same learner without them; with both
// weights 0 the spatial sigma changes nothing (no draw, the same updates).
TEST(Ddpg, SmoothnessTermsMakeTheCommandsCloser) {
  DdpgConfig config = small_config(Algo::kTd3);
  config.actor_lr = 3e-3f;
  config.critic_weight_decay = 0.0f;
  nn::Rng rng(32);
  Batch b = random_batch(rng, 5, 2, 8, 0.0f);
  b.reward.leftCols(b.size).array() += 20.0f;
  const nn::Matrix x = b.state.leftCols(b.size);
  const nn::Matrix x_next = b.next_state.leftCols(b.size);
  nn::Matrix nearby = x;
  for (Eigen::Index i = 0; i < nearby.size(); ++i) nearby(i) += 0.3f * nn::uniform(rng, -1, 1);
  const auto train = [&](float w_t, float w_s, float sigma) {
    DdpgConfig c = config;
    c.smooth_temporal_weight = w_t;
    c.smooth_spatial_weight = w_s;
    c.smooth_spatial_sigma = sigma;
    Ddpg learner(c);
    for (int i = 0; i < 600; ++i) learner.update(b);
    return learner.actor();
  };
  const auto gap = [&](const nn::Mlp& actor, const nn::Matrix& other) {
    return (eval(actor, x) - eval(actor, other)).norm();
  };
  const nn::Mlp plain = train(0, 0, 0.05f);
  EXPECT_EQ(train(0, 0, 0.7f).params(), plain.params());
  const nn::Mlp temporal = train(2.0f, 0, 0.05f);
  EXPECT_LT(gap(temporal, x_next), 0.5 * gap(plain, x_next))
      << gap(plain, x_next) << " -> " << gap(temporal, x_next);
  const nn::Mlp spatial = train(0, 2.0f, 0.3f);
  EXPECT_LT(gap(spatial, nearby), 0.7 * gap(plain, nearby))
      << gap(plain, nearby) << " -> " << gap(spatial, nearby);
}

TEST(Ddpg, UpdatesAllocateNothing) {
  for (Algo algo : {Algo::kDdpg, Algo::kTd3}) {
    for (bool smooth : {false, true}) {
      DdpgConfig config;
      config.algo = algo;
      config.state_dim = 29;
      config.action_dim = 6;
      config.critic_grad_clip_norm = 10.0f;
      if (smooth) config.smooth_temporal_weight = config.smooth_spatial_weight = 0.1f;
      Ddpg learner(config);  // the paper's 400-300, batch 64
      nn::Rng rng(1);
      const ReplayBuffer replay = random_replay(rng, 29, 6, 500);
      learner.update(replay);
      test::AllocationCounter counter;
      for (int i = 0; i < 4; ++i) learner.update(replay);
      EXPECT_EQ(counter.count(), 0) << to_string(algo) << (smooth ? " smooth" : "");
    }
  }
}

// Save after some updates, carry on; a learner restored from the save (built with another seed)
// makes exactly the same next updates: networks, Adam moments, counters and RNG all restored.
TEST(Ddpg, SaveRestoreGivesIdenticalSubsequentUpdates) {
  for (Algo algo : {Algo::kDdpg, Algo::kTd3}) {
    nn::Rng rng(21);
    const ReplayBuffer replay = random_replay(rng, 5, 2, 200);
    DdpgConfig config = small_config(algo);
    if (algo == Algo::kTd3) config.smooth_spatial_weight = 0.2f;  // draws from the RNG too
    Ddpg original(config);
    for (int i = 0; i < 7; ++i) original.update(replay);
    std::stringstream saved;
    original.save(saved);

    std::vector<UpdateStats> expected;
    for (int i = 0; i < 5; ++i) expected.push_back(original.update(replay));

    DdpgConfig other = config;
    other.seed = 999;
    Ddpg restored(other);
    restored.restore(saved);
    EXPECT_EQ(restored.updates(), 7);
    for (int i = 0; i < 5; ++i) {
      const UpdateStats s = restored.update(replay);
      EXPECT_EQ(s.critic_loss, expected[static_cast<std::size_t>(i)].critic_loss) << i;
      EXPECT_EQ(s.actor_loss, expected[static_cast<std::size_t>(i)].actor_loss) << i;
      EXPECT_EQ(s.mean_q, expected[static_cast<std::size_t>(i)].mean_q) << i;
      EXPECT_EQ(s.actor_updated, expected[static_cast<std::size_t>(i)].actor_updated) << i;
    }
    EXPECT_EQ(restored.actor().params(), original.actor().params()) << to_string(algo);
    EXPECT_EQ(restored.actor_target().params(), original.actor_target().params());
    for (int k = 0; k < original.num_critics(); ++k) {
      EXPECT_EQ(restored.critic(k).params(), original.critic(k).params());
      EXPECT_EQ(restored.critic_target(k).params(), original.critic_target(k).params());
    }
    EXPECT_EQ(restored.actor_updates(), original.actor_updates());
  }
}

TEST(Ddpg, DamagedOrMismatchedStateIsRejectedAndTheLearnerKept) {
  nn::Rng rng(5);
  const ReplayBuffer replay = random_replay(rng, 5, 2, 50);
  Ddpg source(small_config(Algo::kDdpg));
  source.update(replay);
  std::stringstream ss;
  source.save(ss);
  const std::string good = ss.str();

  Ddpg target(small_config(Algo::kDdpg));
  const nn::Vector before = target.actor().params();
  for (std::size_t i = 0; i < good.size(); i += 53) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x08);
    std::istringstream is(bad);
    EXPECT_THROW(target.restore(is), std::runtime_error) << "byte " << i;
  }
  std::istringstream truncated(good.substr(0, good.size() - 3));
  EXPECT_THROW(target.restore(truncated), std::runtime_error);
  EXPECT_EQ(target.actor().params(), before);
  EXPECT_EQ(target.updates(), 0);

  auto message = [&](Ddpg& learner) {
    std::istringstream is(good);
    try {
      learner.restore(is);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("<no exception>");
  };
  Ddpg td3(small_config(Algo::kTd3));
  EXPECT_NE(message(td3).find("this learner has algo td3"), std::string::npos) << message(td3);
  DdpgConfig wider = small_config(Algo::kDdpg);
  wider.actor_hidden = {32, 12};
  Ddpg wide(wider);
  const std::string m = message(wide);
  EXPECT_NE(m.find("actor: network: architecture mismatch: expected in=5 hidden=32-12"),
            std::string::npos)
      << m;
}

TEST(Bench, LineFormatAndParsing) {
  BenchResult r;
  r.config.hidden = {256, 256};
  r.config.batch = 256;
  r.updates_per_s = 1234.4;
  EXPECT_EQ(format_bench_line(r),
            "algo=ddpg hidden=256-256 batch=256 threads=1 updates_per_s=1234");
  r.config.algo = Algo::kTd3;
  r.config.state_dim = 3;
  r.config.action_dim = 1;
  EXPECT_EQ(format_bench_line(r),
            "algo=td3 hidden=256-256 batch=256 threads=1 updates_per_s=1234 state_dim=3 "
            "action_dim=1");
  EXPECT_EQ(parse_hidden("400-300"), (std::vector<int>{400, 300}));
  EXPECT_THROW(parse_hidden("400-x"), std::invalid_argument);
  EXPECT_THROW(parse_hidden(""), std::invalid_argument);
  EXPECT_EQ(standard_bench_cases(Algo::kDdpg).size(), 3u);
  const BenchResult quick = run_update_benchmark(Algo::kTd3, {16, 16}, 8, 1, 5, 2, 0.05);
  EXPECT_GT(quick.updates, 0);
  EXPECT_GT(quick.updates_per_s, 0);
}

TEST(Bench, TheFastPresetCaseWithImitationRunsAndSaysSo) {
  BenchCase c = fast_preset_bench_case(0.4f);
  EXPECT_EQ(c.algo, Algo::kTd3);
  EXPECT_EQ(c.hidden, (std::vector<int>{64, 64}));
  EXPECT_EQ(c.state_dim, 29);
  c.seconds = 0.05;
  const BenchResult r = run_update_benchmark(c);
  EXPECT_GT(r.updates, 0);
  EXPECT_NE(format_bench_line(r).find(" expert_weight=0.4"), std::string::npos)
      << format_bench_line(r);
  BenchCase plain = fast_preset_bench_case(0.0f);
  plain.seconds = 0.05;
  EXPECT_EQ(format_bench_line(run_update_benchmark(plain)).find("expert"), std::string::npos);
  BenchCase smooth = fast_preset_bench_case(0.4f);
  smooth.smooth_temporal_weight = 0.1f;
  smooth.seconds = 0.05;
  const BenchResult s = run_update_benchmark(smooth);
  EXPECT_GT(s.updates, 0);
  EXPECT_NE(format_bench_line(s).find(" smooth_temporal_weight=0.1 smooth_spatial_weight=0"),
            std::string::npos)
      << format_bench_line(s);
}

}  // namespace
}  // namespace auvrl::learner
