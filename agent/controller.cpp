#include "agent/controller.hpp"

#include <stdexcept>

namespace auvrl::agent {

namespace {
void check_sizes(const nn::Mlp& network, int state_dim, int num_thrusters) {
  const nn::MlpSpec& spec = network.spec();
  if (spec.input_dim != state_dim || spec.output_dim != num_thrusters ||
      spec.extra_input_dim != 0) {
    throw std::invalid_argument("policy network " + spec.describe() + " does not fit the task: " +
                                "expected in=" + std::to_string(state_dim) +
                                " out=" + std::to_string(num_thrusters));
  }
}
}  // namespace

PolicyController::PolicyController(nn::Mlp network, int state_dim, int num_thrusters)
    : network_(std::move(network)), state_dim_(state_dim), num_thrusters_(num_thrusters) {
  check_sizes(network_, state_dim_, num_thrusters_);
}

void PolicyController::set_network(nn::Mlp network) {
  check_sizes(network, state_dim_, num_thrusters_);
  network_ = std::move(network);
}

void PolicyController::act(const task::Observation&, const Eigen::Vector3d&,
                           const task::StateVector& state, task::ActionVector& action) {
  action = network_.forward(state);
}

}  // namespace auvrl::agent
