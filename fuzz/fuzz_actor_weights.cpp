// auv_actor's input: POLICY_WEIGHTS messages as raw bytes, published on the in-process
// transport, received the way ActorNode receives them (transport::Latest, newest kept) and
// applied by PolicyReceiver (the code ActorNode runs); an accepted policy then acts once.
#include <auvrl_lcm/policy_weights_t.hpp>

#include "agent/policy_receiver.hpp"
#include "common/channels.hpp"
#include "common/task/task.hpp"
#include "fuzz/fuzz_util.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const task::TaskConfig task_config;
  transport::Transport& t = fuzz::in_process_transport();
  transport::Latest<auvrl_lcm::policy_weights_t> weights(t, channels::kPolicyWeights, 8);
  agent::PolicyReceiver receiver(task_config.state_dim(), task_config.num_thrusters, 1.5);
  const task::StateVector state = task::StateVector::Zero(task_config.state_dim());
  const task::Observation observation{};
  task::ActionVector action;
  for (const fuzz::Record& r : fuzz::read_records(data, size)) {
    const auto bytes = fuzz::message_bytes<auvrl_lcm::policy_weights_t>(r);
    t.publish(channels::kPolicyWeights, bytes.data(), bytes.size());
    t.drain();
    if (auto msg = weights.take()) {
      std::string error;
      receiver.apply(*msg, error);
    }
    if (agent::PolicyController* policy = receiver.policy()) {
      policy->act(observation, Eigen::Vector3d::Zero(), state, action);
    }
  }
  return 0;
}
