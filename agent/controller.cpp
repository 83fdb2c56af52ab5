#include "agent/controller.hpp"

#include <stdexcept>

#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"

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

PolicyController::PolicyController(nn::Mlp network, const task::TaskConfig& task)
    : PolicyController(std::move(network), task.state_dim(), task.num_thrusters) {
  use_driving_aids(task);
}

void PolicyController::set_network(nn::Mlp network) {
  check_sizes(network, state_dim_, num_thrusters_);
  network_ = std::move(network);
}

void PolicyController::use_driving_aids(const task::TaskConfig& task) {
  driving_task_.reset();
  position_filter_.reset();
  if (task.position_filter.enabled()) {
    position_filter_.emplace(task.position_filter, task.control_step_s);
  }
  if (task.integral.enabled() || position_filter_) driving_task_ = task;
  goal_offset_ned_m_.setZero();
  fault_accommodation_.reset();
  if (task::has_fault_accommodation(task)) fault_accommodation_.emplace(task);
}

void PolicyController::act(const task::Observation& observation, const Eigen::Vector3d& goal_ned_m,
                           const task::StateVector& state, task::ActionVector& action) {
  action = network_.forward(network_input(observation, goal_ned_m, state));
  finish_action(state, action);
}

const task::StateVector& PolicyController::network_input(const task::Observation& observation,
                                                         const Eigen::Vector3d& goal_ned_m,
                                                         const task::StateVector& state) {
  if (!driving_task_) return state;
  const task::TaskConfig& task = *driving_task_;
  const Eigen::Vector3d position_ned_m =
      position_filter_ ? position_filter_->update(observation) : observation.position_ned_m;
  const Eigen::Vector3d shown_goal_ned_m =
      task.integral.enabled()
          ? task::advance_goal_integral(task, goal_ned_m, position_ned_m, goal_offset_ned_m_)
          : goal_ned_m;
  moved_state_ = state;
  // Zero shift without the filter: the state's position entries stay the measured ones.
  task::relabel_state(task, goal_ned_m, shown_goal_ned_m,
                      position_ned_m - observation.position_ned_m, moved_state_);
  return moved_state_;
}

void PolicyController::finish_action(const task::StateVector& state, task::ActionVector& action) {
  if (fault_accommodation_) fault_accommodation_->apply(state, action);
}

namespace {

nn::Mlp read_policy_network(const std::string& path) {
  std::vector<std::uint8_t> bytes;
  try {
    bytes = nn::read_file(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("policy file (--policy): ") + e.what());
  }
  try {
    return nn::network_from_bytes(bytes, 1);
  } catch (const std::exception& e) {
    throw std::runtime_error("policy file " + path + ": not a usable network file: " + e.what());
  }
}

}  // namespace

std::unique_ptr<PolicyController> load_policy(const std::string& path,
                                              const std::string& vehicle_name, int num_thrusters,
                                              const std::optional<task::StateLayout>& layout,
                                              task::TaskConfig& task) {
  nn::Mlp network = read_policy_network(path);
  const std::string where = "policy file " + path + " (vehicle " + vehicle_name + ")";
  task.num_thrusters = num_thrusters;
  try {
    task.layout = layout ? *layout : task::infer_layout(network.spec().input_dim, num_thrusters);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
  try {
    return std::make_unique<PolicyController>(std::move(network), task);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + " with the " + task::to_string(task.layout) +
                             " layout: " + e.what());
  }
}

}  // namespace auvrl::agent
