// Perceptron: architecture, initialisation, forward pass against a double reference,
// finite-difference gradient checks, allocation-free passes, and fitting a small regression.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12 false positive in Eigen AVX-512
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "common/nn/adam.hpp"
#include "common/nn/mlp.hpp"
#include "reference_mlp.hpp"

namespace auvrl::nn {
namespace {

Matrix random_matrix(Rng& rng, int rows, int cols, float lo = -1.0f, float hi = 1.0f) {
  Matrix m(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j) {
    for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = uniform(rng, lo, hi);
  }
  return m;
}

// Parameters large enough that tanh saturates a little and ReLUs switch off: a stronger check
// than Lillicrap's near-zero output layer.
void randomise(Mlp& net, Rng& rng) {
  for (Eigen::Index i = 0; i < net.num_params(); ++i) net.params()[i] = uniform(rng, -0.6f, 0.6f);
}

struct GradCase {
  std::string name;
  MlpSpec spec;
};

std::vector<GradCase> grad_cases() {
  MlpSpec no_hidden = MlpSpec::critic(5, 2, {}, 0);
  MlpSpec actor_identity = MlpSpec::actor(4, {6}, 2);
  actor_identity.output_activation = Activation::kIdentity;
  return {
      {"actor_tanh_2_hidden", MlpSpec::actor(5, {7, 6}, 3)},
      {"actor_identity_1_hidden", actor_identity},
      {"critic_action_at_layer0", MlpSpec::critic(5, 2, {7, 6}, 0)},
      {"critic_action_at_layer1", MlpSpec::critic(5, 2, {7, 6}, 1)},
      {"critic_action_at_layer2", MlpSpec::critic(5, 2, {7, 6}, 2)},
      {"critic_no_hidden", no_hidden},
  };
}

void PrintTo(const GradCase& c, std::ostream* os) { *os << c.name << ": " << c.spec.describe(); }

class GradientCheck : public ::testing::TestWithParam<GradCase> {};

TEST_P(GradientCheck, MatchesFiniteDifferencesOfDoubleReference) {
  const MlpSpec& spec = GetParam().spec;
  Rng rng(7);
  const int batch = 5;
  Mlp net(spec, 8);
  randomise(net, rng);
  const Matrix x = random_matrix(rng, spec.input_dim, batch);
  const Matrix e = random_matrix(rng, spec.extra_input_dim, batch);
  const Matrix c = random_matrix(rng, spec.output_dim, batch);  // L = sum(c .* y)

  const Matrix y = spec.extra_input_dim > 0 ? Matrix(net.forward(x, e)) : Matrix(net.forward(x));
  net.backward(c, GradRequest{true, true, spec.extra_input_dim > 0});

  const Eigen::VectorXd p = net.params().cast<double>();
  const Eigen::MatrixXd xd = x.cast<double>();
  const Eigen::MatrixXd ed = e.cast<double>();
  const Eigen::MatrixXd cd = c.cast<double>();
  auto loss = [&](const Eigen::VectorXd& pp, const Eigen::MatrixXd& xx, const Eigen::MatrixXd& ee) {
    return (cd.array() * test::reference_forward(spec, pp, xx, ee).array()).sum();
  };
  // The float forward pass agrees with the double reference.
  EXPECT_LT((y.cast<double>() - test::reference_forward(spec, p, xd, ed)).cwiseAbs().maxCoeff(),
            2e-6);

  const double h = 1e-6;
  auto check = [&](double analytic, double numeric, const std::string& what) {
    EXPECT_NEAR(analytic, numeric, 2e-5 + 1e-4 * std::abs(numeric)) << what;
  };
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    Eigen::VectorXd pp = p, pm = p;
    pp[i] += h;
    pm[i] -= h;
    check(net.grads()[i], (loss(pp, xd, ed) - loss(pm, xd, ed)) / (2 * h),
          "parameter " + std::to_string(i));
  }
  for (Eigen::Index k = 0; k < xd.size(); ++k) {
    Eigen::MatrixXd xp = xd, xm = xd;
    xp.data()[k] += h;
    xm.data()[k] -= h;
    check(net.input_grad()(k % spec.input_dim, k / spec.input_dim),
          (loss(p, xp, ed) - loss(p, xm, ed)) / (2 * h), "input " + std::to_string(k));
  }
  for (Eigen::Index k = 0; k < ed.size(); ++k) {
    Eigen::MatrixXd ep = ed, em = ed;
    ep.data()[k] += h;
    em.data()[k] -= h;
    check(net.extra_input_grad()(k % spec.extra_input_dim, k / spec.extra_input_dim),
          (loss(p, xd, ep) - loss(p, xd, em)) / (2 * h), "extra input " + std::to_string(k));
  }
}

TEST_P(GradientCheck, PartialRequestsGiveTheSameValuesAndLeaveTheRestAlone) {
  const MlpSpec& spec = GetParam().spec;
  const bool critic = spec.extra_input_dim > 0;
  Rng rng(11);
  Mlp net(spec, 8);
  randomise(net, rng);
  const Matrix x = random_matrix(rng, spec.input_dim, 6);
  const Matrix e = random_matrix(rng, spec.extra_input_dim, 6);
  const Matrix c = random_matrix(rng, spec.output_dim, 6);
  auto forward = [&] { critic ? net.forward(x, e) : net.forward(x); };
  forward();
  net.backward(c, GradRequest{true, true, critic});
  const Vector full_grads = net.grads();
  const Matrix full_input = net.input_grad();
  const Matrix full_extra = critic ? Matrix(net.extra_input_grad()) : Matrix();

  // An input gradient alone (for a critic: dQ/da, the actor update's request): same values,
  // parameter gradients untouched.
  net.grads().setZero();
  forward();
  net.backward(c, GradRequest{false, !critic, critic});
  EXPECT_TRUE(net.grads().isZero());
  const Matrix partial = critic ? Matrix(net.extra_input_grad()) : Matrix(net.input_grad());
  EXPECT_LT((partial - (critic ? full_extra : full_input)).cwiseAbs().maxCoeff(), 1e-6f);

  // Parameters alone (the critic update's request).
  net.backward(c, GradRequest{true, false, false});
  EXPECT_LT((net.grads() - full_grads).cwiseAbs().maxCoeff(), 1e-6f);
}

INSTANTIATE_TEST_SUITE_P(Architectures, GradientCheck, ::testing::ValuesIn(grad_cases()),
                         [](const auto& info) { return info.param.name; });

TEST(MlpSpec, LayerSizesAndParameterLayout) {
  const MlpSpec critic = MlpSpec::critic(29, 6, {400, 300}, 1);
  EXPECT_EQ(critic.num_layers(), 3);
  EXPECT_EQ(critic.layer_in(0), 29);
  EXPECT_EQ(critic.layer_in(1), 406);
  EXPECT_EQ(critic.layer_in(2), 300);
  EXPECT_EQ(critic.describe(), "in=29 hidden=400-300 out=1 (identity) extra=6 at layer 1");
  Mlp net(critic, 4);
  EXPECT_EQ(net.num_weights(), 29 * 400 + 406 * 300 + 300);
  EXPECT_EQ(net.num_params(), net.num_weights() + 400 + 300 + 1);
  // Views alias the flat vector: weights first, then biases.
  net.weight(1)(2, 3) = 5.0f;
  EXPECT_EQ(net.params()[29 * 400 + 3 * 300 + 2], 5.0f);
  net.bias(0)[1] = 7.0f;
  EXPECT_EQ(net.params()[net.num_weights() + 1], 7.0f);

  EXPECT_EQ(MlpSpec::actor(29, {64, 64}, 6).describe(), "in=29 hidden=64-64 out=6 (tanh)");
  EXPECT_NE(MlpSpec::critic(29, 6, {64}, 0), MlpSpec::critic(29, 6, {64}, 1));
}

TEST(MlpSpec, InvalidSpecsAreRejected) {
  EXPECT_THROW(Mlp(MlpSpec::actor(0, {8}, 2), 4), std::invalid_argument);
  EXPECT_THROW(Mlp(MlpSpec::actor(3, {8, 0}, 2), 4), std::invalid_argument);
  EXPECT_THROW(Mlp(MlpSpec::critic(3, 2, {8}, 2), 4), std::invalid_argument);
  EXPECT_THROW(Mlp(MlpSpec::actor(3, {8}, 2), 0), std::invalid_argument);
}

TEST(Mlp, LillicrapInitialisationBoundsAndSeeding) {
  Mlp net(MlpSpec::critic(29, 6, {400, 300}, 1), 4);
  Rng rng(42);
  net.init_lillicrap(rng);
  EXPECT_LE(net.weight(0).cwiseAbs().maxCoeff(), 1.0f / std::sqrt(29.0f));
  EXPECT_GT(net.weight(0).cwiseAbs().maxCoeff(), 0.9f / std::sqrt(29.0f));
  EXPECT_LE(net.bias(0).cwiseAbs().maxCoeff(), 1.0f / std::sqrt(29.0f));
  EXPECT_LE(net.weight(1).cwiseAbs().maxCoeff(), 1.0f / std::sqrt(406.0f));  // fan-in with action
  EXPECT_GT(net.weight(1).cwiseAbs().maxCoeff(), 0.9f / std::sqrt(406.0f));
  EXPECT_LE(net.weight(2).cwiseAbs().maxCoeff(), 3e-3f);
  EXPECT_LE(net.bias(2).cwiseAbs().maxCoeff(), 3e-3f);
  EXPECT_GT(net.weight(2).cwiseAbs().maxCoeff(), 2.5e-3f);
  // Roughly uniform: mean near 0, variance near bound^2 / 3.
  const float b0 = 1.0f / std::sqrt(29.0f);
  EXPECT_NEAR(net.weight(0).mean(), 0.0f, 0.01f * b0 * 10);
  EXPECT_NEAR(net.weight(0).array().square().mean(), b0 * b0 / 3, 0.05f * b0 * b0);

  Mlp same(net.spec(), 4), other(net.spec(), 4);
  Rng rng_same(42), rng_other(43);
  same.init_lillicrap(rng_same);
  other.init_lillicrap(rng_other);
  EXPECT_EQ(same.params(), net.params());
  EXPECT_NE(other.params(), net.params());
}

TEST(Mlp, BatchedForwardEqualsOneSampleAtATime) {
  Rng rng(3);
  Mlp net(MlpSpec::critic(29, 6, {64, 48}, 1), 100);
  randomise(net, rng);
  const Matrix x = random_matrix(rng, 29, 100);
  const Matrix a = random_matrix(rng, 6, 100);
  const Matrix batched = net.forward(x, a);
  for (int n = 0; n < 100; n += 9) {
    const Matrix one = net.forward(x.col(n), a.col(n));
    EXPECT_NEAR(one(0, 0), batched(0, n), 1e-5f * (1 + std::abs(batched(0, n))));
  }
}

// The fine-tuning runs its episodes in lockstep through one batched pass (agent::
// run_policy_episodes) and must give the bytes of one episode at a time: an actor's columns do
// not depend on the batch around them (each entry sums its products in the same order, and the
// output's tanh is the same function on every entry).
TEST(Mlp, ActorColumnsOfABatchHaveTheBytesOfOneSampleAtATime) {
  Rng rng(5);
  Mlp batched(MlpSpec::actor(23, {64, 64}, 6), 42);
  batched.init_lillicrap(rng);
  batched.weight(2) *= 200.0f;  // outputs spread over (-1, 1), not all near 0 or saturated
  Mlp single(batched.spec(), 1);
  single.copy_params_from(batched);
  const Matrix x = 3.0f * random_matrix(rng, 23, 42);
  for (const int n : {42, 41, 7, 6, 5, 1}) {
    const Matrix out = batched.forward(x.leftCols(n));
    EXPECT_GT(out.cwiseAbs().maxCoeff(), 0.5f);
    EXPECT_LT(out.cwiseAbs().maxCoeff(), 0.9999f);
    for (int j = 0; j < n; ++j) {
      const Matrix one = single.forward(x.col(j));
      for (int i = 0; i < 6; ++i) {
        ASSERT_EQ(one(i, 0), out(i, j)) << "batch " << n << ", column " << j << ", output " << i;
      }
    }
  }
}

TEST(Mlp, WrongShapesAreRejected) {
  Mlp actor(MlpSpec::actor(3, {8}, 2), 4);
  EXPECT_THROW(actor.forward(Matrix::Zero(4, 2)), std::invalid_argument);
  EXPECT_THROW(actor.forward(Matrix::Zero(3, 5)), std::invalid_argument);
  EXPECT_THROW(actor.backward(Matrix::Zero(2, 1), {}), std::invalid_argument);  // no forward yet
  actor.forward(Matrix::Zero(3, 2));
  EXPECT_THROW(actor.backward(Matrix::Zero(2, 3), {}), std::invalid_argument);
  Mlp critic(MlpSpec::critic(3, 2, {8}, 1), 4);
  EXPECT_THROW(critic.forward(Matrix::Zero(3, 2)), std::invalid_argument);  // needs the action
  EXPECT_THROW(critic.forward(Matrix::Zero(3, 2), Matrix::Zero(2, 3)), std::invalid_argument);
}

TEST(Mlp, MeanOfNetworksIsTheMeanOfEachParameter) {
  Rng rng(6);
  Mlp a(MlpSpec::actor(3, {8}, 2), 4), b(MlpSpec::actor(3, {8}, 2), 1), c(a);
  a.init_lillicrap(rng);
  b.init_lillicrap(rng);
  c.init_lillicrap(rng);
  const Mlp mean = mean_of({&a, &b, &c});
  EXPECT_EQ(mean.spec(), a.spec());
  EXPECT_EQ(mean.max_batch(), 4);  // the first one's
  EXPECT_LT((mean.params() - (a.params() + b.params() + c.params()) / 3.0f).cwiseAbs().maxCoeff(),
            1e-7f);
  // Two networks: exactly halfway, the same bits as 0.5 a + 0.5 b.
  EXPECT_EQ(mean_of({&a, &b}).params(), (0.5f * a.params() + 0.5f * b.params()).eval());
  EXPECT_EQ(mean_of({&a}).params(), a.params());
  const Mlp other(MlpSpec::actor(3, {9}, 2), 4);
  try {
    mean_of({&a, &other});
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("network 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(mean_of({}), std::invalid_argument);
}

TEST(Mlp, SoftUpdateAndCopy) {
  Rng rng(5);
  Mlp a(MlpSpec::actor(3, {8}, 2), 4), b(MlpSpec::actor(3, {8}, 2), 4);
  a.init_lillicrap(rng);
  b.init_lillicrap(rng);
  const Vector before = b.params();
  soft_update(b, a, 0.25f);
  EXPECT_LT((b.params() - (0.25f * a.params() + 0.75f * before)).cwiseAbs().maxCoeff(), 1e-7f);
  soft_update(b, a, 1.0f);
  EXPECT_EQ(b.params(), a.params());
  Mlp c(MlpSpec::actor(3, {9}, 2), 4);
  EXPECT_THROW(soft_update(c, a, 0.5f), std::invalid_argument);
  Mlp copy = a;  // deep copy: independent parameters
  copy.params()[0] += 1.0f;
  EXPECT_NE(copy.params()[0], a.params()[0]);
}

// The update loop's passes allocate nothing once the networks exist, at the sizes used here
// (400-300 at batch 256 is the largest product), for both critic variants.
TEST(Mlp, ForwardBackwardAdamAndSoftUpdateAllocateNothing) {
  for (int action_layer : {0, 1}) {
    Rng rng(9);
    Mlp actor(MlpSpec::actor(29, {400, 300}, 6), 256);
    Mlp critic(MlpSpec::critic(29, 6, {400, 300}, action_layer), 256);
    actor.init_lillicrap(rng);
    critic.init_lillicrap(rng);
    Mlp critic_target = critic;
    AdamConfig config;
    config.weight_decay = 1e-2f;
    config.grad_clip_norm = 1.0f;
    Adam critic_opt(config, critic), actor_opt(AdamConfig{}, actor);
    const Matrix x = random_matrix(rng, 29, 256);
    const Matrix a = random_matrix(rng, 6, 256);
    const Matrix dq = Matrix::Constant(1, 256, 1.0f / 256);
    const Matrix dq_small = Matrix::Constant(1, 64, 1.0f / 64);

    test::AllocationCounter counter;
    for (int round = 0; round < 2; ++round) {
      critic.forward(x, a);
      critic.backward(dq, GradRequest{true, false, false});
      critic_opt.step(critic);
      actor.forward(x);
      critic.forward(x, actor.output());
      critic.backward(dq, GradRequest{false, false, true});
      actor.backward(critic.extra_input_grad(), GradRequest{true, false, false});
      actor_opt.step(actor);
      soft_update(critic_target, critic, 1e-3f);
      critic.forward(x.leftCols(64), a.leftCols(64));  // a smaller batch too
      critic.backward(dq_small, GradRequest{true, true, true});
    }
    EXPECT_EQ(counter.count(), 0) << "action at layer " << action_layer;
  }
}

// A 3-input function fitted by a 64-64 network with Adam on mean squared error.
TEST(Mlp, FitsASmallRegressionProblem) {
  Rng rng(1);
  const int n = 256;
  auto target = [](float a, float b, float c) {
    return std::sin(2.0f * a) * std::cos(b) + 0.5f * c * c - 0.25f;
  };
  auto make_set = [&](Matrix& x, Matrix& y) {
    x = random_matrix(rng, 3, n);
    y.resize(1, n);
    for (int j = 0; j < n; ++j) y(0, j) = target(x(0, j), x(1, j), x(2, j));
  };
  Matrix x, y, x_test, y_test;
  make_set(x, y);
  make_set(x_test, y_test);
  MlpSpec spec = MlpSpec::actor(3, {64, 64}, 1);
  spec.output_activation = Activation::kIdentity;
  Mlp net(spec, n);
  net.init_lillicrap(rng);
  AdamConfig config;
  config.learning_rate = 3e-3f;
  Adam opt(config, net);
  const float baseline = (y_test.array() - y_test.mean()).square().mean();
  Matrix d(1, n);
  for (int step = 0; step < 2000; ++step) {
    d = (2.0f / n) * (net.forward(x) - y);
    net.backward(d, GradRequest{});
    opt.step(net);
  }
  const float train_mse = (net.forward(x) - y).array().square().mean();
  const float test_mse = (net.forward(x_test) - y_test).array().square().mean();
  EXPECT_LT(train_mse, 1e-3f);
  EXPECT_LT(test_mse, 0.02f * baseline) << "baseline (predict the mean) " << baseline;
}

}  // namespace
}  // namespace auvrl::nn
