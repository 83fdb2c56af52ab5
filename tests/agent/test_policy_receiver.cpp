// The actor's handling of policy_weights_t messages with a valid LCM encoding but hostile
// content: a damaged checksum, the wrong architecture or output, NaN/inf parameters under a
// valid checksum, a size field that disagrees, bad schedule fields: each is rejected and
// counted, and the policy the actor holds stays exactly as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "agent/policy_receiver.hpp"
#include "common/nn/serialize.hpp"
#include "common/task/task.hpp"

namespace {

using namespace auvrl;

nn::Mlp network(int in, int out, nn::Activation output = nn::Activation::kTanh,
                float value = 0.01f) {
  nn::MlpSpec spec;
  spec.input_dim = in;
  spec.hidden = {8, 8};
  spec.output_dim = out;
  spec.output_activation = output;
  nn::Mlp net(spec, 1);
  net.params().setConstant(value);
  return net;
}

auvrl_lcm::policy_weights_t weights(const nn::Mlp& net, std::int64_t version) {
  auvrl_lcm::policy_weights_t m{};
  m.version = version;
  m.beta_m = 1.0;
  m.updates_owed = 3.0;
  const auto bytes = nn::network_to_bytes(net);
  m.num_bytes = static_cast<std::int32_t>(bytes.size());
  m.network.assign(bytes.begin(), bytes.end());
  return m;
}

class PolicyReceiverTest : public ::testing::Test {
 protected:
  PolicyReceiverTest() : receiver_(task_.state_dim(), task_.num_thrusters, 1.5) {
    std::string error;
    EXPECT_EQ(receiver_.apply(good(1), error), agent::WeightsOutcome::kApplied) << error;
    held_ = receiver_.policy()->network().params();
  }
  auvrl_lcm::policy_weights_t good(std::int64_t version) {
    return weights(network(task_.state_dim(), task_.num_thrusters), version);
  }
  /// Applies msg, expects a rejection, and that nothing changed.
  void expect_rejected(const auvrl_lcm::policy_weights_t& msg, const std::string& why,
                       agent::WeightsOutcome outcome = agent::WeightsOutcome::kRejected) {
    std::string error;
    const std::int64_t rejected = receiver_.rejected();
    EXPECT_EQ(receiver_.apply(msg, error), outcome) << why;
    EXPECT_FALSE(error.empty()) << why;
    EXPECT_EQ(receiver_.rejected(), rejected + 1) << why;
    EXPECT_EQ(receiver_.version(), 1) << why;
    EXPECT_DOUBLE_EQ(receiver_.beta_m(), 1.0) << why;
    EXPECT_DOUBLE_EQ(receiver_.learner_backlog(), 3.0) << why;
    EXPECT_FALSE(receiver_.training_done()) << why;
    ASSERT_NE(receiver_.policy(), nullptr);
    EXPECT_EQ(receiver_.policy()->network().params(), held_) << why;
  }

  task::TaskConfig task_;
  agent::PolicyReceiver receiver_;
  nn::Vector held_;
};

TEST_F(PolicyReceiverTest, DamagedChecksumIsRejected) {
  auto msg = good(2);
  msg.network[msg.network.size() / 2] ^= 0x40;  // a parameter byte: the CRC no longer matches
  msg.training_done = true;
  expect_rejected(msg, "crc");
  msg = good(2);
  msg.network.back() ^= 1;  // the CRC itself
  expect_rejected(msg, "crc field");
}

TEST_F(PolicyReceiverTest, WrongShapesAreRejected) {
  // A sound network of other sizes: another vehicle's or layout's (the actor stops on it).
  expect_rejected(weights(network(task_.state_dim() + 1, task_.num_thrusters), 2), "inputs",
                  agent::WeightsOutcome::kWrongSizes);
  expect_rejected(weights(network(task_.state_dim(), task_.num_thrusters - 1), 2), "outputs",
                  agent::WeightsOutcome::kWrongSizes);
  expect_rejected(
      weights(network(task_.state_dim(), task_.num_thrusters, nn::Activation::kIdentity), 2),
      "no tanh output");
  auto truncated = good(2);
  truncated.network.resize(truncated.network.size() - 10);
  truncated.num_bytes -= 10;
  expect_rejected(truncated, "truncated");
  auto size_lies = good(2);
  size_lies.num_bytes += 1;  // the size field disagrees with the network it came with
  expect_rejected(size_lies, "num_bytes");
  auto empty = good(2);
  empty.network.clear();
  empty.num_bytes = 0;
  expect_rejected(empty, "empty");
}

TEST_F(PolicyReceiverTest, NonFiniteParametersUnderAValidChecksumAreRejected) {
  // The checksum catches damage, not a sender: NaN weights can carry a correct CRC.
  expect_rejected(
      weights(network(task_.state_dim(), task_.num_thrusters, nn::Activation::kTanh, std::nanf("")),
              2),
      "nan");
  expect_rejected(weights(network(task_.state_dim(), task_.num_thrusters, nn::Activation::kTanh,
                                  std::numeric_limits<float>::infinity()),
                          2),
                  "inf");
}

TEST_F(PolicyReceiverTest, BadScheduleFieldsAreRejected) {
  auto msg = good(2);
  msg.beta_m = std::nan("");
  expect_rejected(msg, "beta nan");
  msg.beta_m = -1.0;
  expect_rejected(msg, "beta negative");
  msg.beta_m = 0.0;
  expect_rejected(msg, "beta zero");
  msg = good(2);
  msg.updates_owed = std::numeric_limits<double>::infinity();
  expect_rejected(msg, "backlog inf");
  msg.updates_owed = -5.0;
  expect_rejected(msg, "backlog negative");
  msg = good(-3);
  expect_rejected(msg, "negative version");
  // The same version with bad fields is rejected too (nothing of it is taken).
  msg = good(1);
  msg.beta_m = std::nan("");
  expect_rejected(msg, "same version, beta nan");
}

TEST_F(PolicyReceiverTest, GoodWeightsAfterRejectionsAreApplied) {
  auto bad = good(2);
  bad.network[40] ^= 1;
  expect_rejected(bad, "crc");
  auto next =
      weights(network(task_.state_dim(), task_.num_thrusters, nn::Activation::kTanh, 0.02f), 2);
  next.beta_m = 0.5;
  std::string error;
  EXPECT_EQ(receiver_.apply(next, error), agent::WeightsOutcome::kApplied) << error;
  EXPECT_EQ(receiver_.version(), 2);
  EXPECT_DOUBLE_EQ(receiver_.beta_m(), 0.5);
  EXPECT_FLOAT_EQ(receiver_.policy()->network().params()[0], 0.02f);
  // The same version again only refreshes the schedule fields.
  next.beta_m = 0.25;
  EXPECT_EQ(receiver_.apply(next, error), agent::WeightsOutcome::kRefreshed);
  EXPECT_DOUBLE_EQ(receiver_.beta_m(), 0.25);
  EXPECT_EQ(receiver_.applied(), 2);
}

}  // namespace
