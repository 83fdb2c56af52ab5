#include "agent/policy_receiver.hpp"

#include <cmath>
#include <stdexcept>

#include "common/nn/serialize.hpp"

namespace auvrl::agent {

PolicyReceiver::PolicyReceiver(int state_dim, int num_thrusters, double initial_beta_m)
    : state_dim_(state_dim), num_thrusters_(num_thrusters), beta_m_(initial_beta_m) {}

WeightsOutcome PolicyReceiver::apply(const auvrl_lcm::policy_weights_t& msg, std::string& error) {
  const auto reject = [&](std::string why) {
    error = std::move(why);
    ++rejected_;
    return WeightsOutcome::kRejected;
  };
  if (!std::isfinite(msg.beta_m) || msg.beta_m <= 0.0) {
    return reject("beta_m " + std::to_string(msg.beta_m) + " is not a positive finite radius");
  }
  if (!std::isfinite(msg.updates_owed) || msg.updates_owed < 0.0) {
    return reject("updates_owed " + std::to_string(msg.updates_owed) + " is not finite and >= 0");
  }
  if (msg.version < 0) return reject("negative version " + std::to_string(msg.version));
  if (msg.num_bytes < 0 || static_cast<std::size_t>(msg.num_bytes) != msg.network.size()) {
    return reject("num_bytes " + std::to_string(msg.num_bytes) + " but " +
                  std::to_string(msg.network.size()) + " network bytes");
  }
  if (msg.version == version_ && policy_) {
    beta_m_ = msg.beta_m;
    training_done_ = msg.training_done;
    learner_backlog_ = msg.updates_owed;
    return WeightsOutcome::kRefreshed;
  }
  try {
    nn::Mlp network = nn::network_from_bytes(
        reinterpret_cast<const std::uint8_t*>(msg.network.data()), msg.network.size(), 1);
    if (network.spec().output_activation != nn::Activation::kTanh) {
      return reject("policy network " + network.spec().describe() + " has no tanh output");
    }
    if (!network.params().allFinite()) return reject("non-finite parameters in the network");
    const nn::MlpSpec& spec = network.spec();
    if (spec.input_dim != state_dim_ || spec.output_dim != num_thrusters_ ||
        spec.extra_input_dim != 0) {
      reject("weights version " + std::to_string(msg.version) + " hold a policy network " +
             spec.describe() + "; this actor's task needs in=" + std::to_string(state_dim_) +
             " out=" + std::to_string(num_thrusters_));
      return WeightsOutcome::kWrongSizes;
    }
    auto policy =
        std::make_unique<PolicyController>(std::move(network), state_dim_, num_thrusters_);
    policy_ = std::move(policy);
  } catch (const std::exception& e) {
    return reject(e.what());
  }
  version_ = msg.version;
  beta_m_ = msg.beta_m;
  training_done_ = msg.training_done;
  learner_backlog_ = msg.updates_owed;
  ++applied_;
  return WeightsOutcome::kApplied;
}

}  // namespace auvrl::agent
