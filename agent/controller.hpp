// What decides the thrust: a learned policy (the paper's end-to-end agent) or the classical
// PID baseline. Both see the same inputs and return normalised commands in [-1, 1].
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "common/nn/mlp.hpp"
#include "common/task/fault_accommodation.hpp"
#include "common/task/task.hpp"

namespace auvrl::agent {

/// A controller for one vehicle. act() is called once per control step.
class Controller {
 public:
  virtual ~Controller() = default;
  /// Called at the start of every episode.
  virtual void reset() {}
  /// Fills action (size num_thrusters, each in [-1, 1]) from the observation, the goal and the
  /// task's observation vector built from them.
  virtual void act(const task::Observation& observation, const Eigen::Vector3d& goal_ned_m,
                   const task::StateVector& state, task::ActionVector& action) = 0;
  virtual std::string name() const = 0;
};

/// The learned policy mu(x | theta): the actor network on the task's observation vector. When
/// it drives (use_driving_aids), it is shown the goal moved by the task's goal integrator
/// (task::GoalIntegralSettings) instead of the goal itself, and the position estimated by the
/// task's position filter (task::PositionFilterSettings) instead of the measured one, and its
/// commands pass the task's thruster fault accommodation (task::ThrusterFaultAccommodation).
class PolicyController final : public Controller {
 public:
  /// Throws std::invalid_argument if the network's input/output sizes do not match.
  PolicyController(nn::Mlp network, int state_dim, int num_thrusters);
  /// A policy that drives: sizes from the task, its driving aids as use_driving_aids says.
  PolicyController(nn::Mlp network, const task::TaskConfig& task);
  /// Integral action as task.integral says (off when its gain is 0), the position filter as
  /// task.position_filter says (off when its time constant is 0) and fault accommodation as
  /// task.fault_accommodation says (extended_thrust layout only). The actors' exploring policy
  /// never uses them; a policy that drives does.
  void use_driving_aids(const task::TaskConfig& task);
  /// Clears the integrator, the position filter and the thrusters found weak or dead (the start of
  /// an episode or mission).
  void reset() override {
    goal_offset_ned_m_.setZero();
    if (position_filter_) position_filter_->reset();
    if (fault_accommodation_) fault_accommodation_->reset();
  }
  void act(const task::Observation& observation, const Eigen::Vector3d& goal_ned_m,
           const task::StateVector& state, task::ActionVector& action) override;
  /// act() in two halves around the network, for a network run elsewhere (batched over
  /// episodes: run_policy_episodes): what the network is shown this step (the state, or with the
  /// driving aids the state with the filter's position and the integrator's goal; it advances
  /// them, so once per step), and the network's output made the command (the fault
  /// accommodation, where on). act() is network_input, the network, finish_action.
  const task::StateVector& network_input(const task::Observation& observation,
                                         const Eigen::Vector3d& goal_ned_m,
                                         const task::StateVector& state);
  void finish_action(const task::StateVector& state, task::ActionVector& action);
  /// The integrator's goal offset now, NED, m.
  const Eigen::Vector3d& goal_offset_ned_m() const { return goal_offset_ned_m_; }
  std::string name() const override { return "policy"; }
  /// Replaces the network (new weights from the learner); same size checks.
  void set_network(nn::Mlp network);
  const nn::Mlp& network() const { return network_; }

 private:
  nn::Mlp network_;
  int state_dim_;
  int num_thrusters_;

  std::optional<task::TaskConfig> driving_task_;  ///< set when integral action or filter is on
  std::optional<task::PositionFilter> position_filter_;
  std::optional<task::ThrusterFaultAccommodation> fault_accommodation_;
  Eigen::Vector3d goal_offset_ned_m_ = Eigen::Vector3d::Zero();
  task::StateVector moved_state_;
};

/// The policy in a network file, for a vehicle with num_thrusters thrusters: reads the file
/// (its CRC-32 checked), takes `layout` or infers it from the network's input size
/// (task::infer_layout), checks the sizes and sets task.layout; integral action as
/// task.integral says (it drives). Throws std::runtime_error
/// naming the file, the vehicle and what was expected.
std::unique_ptr<PolicyController> load_policy(const std::string& path,
                                              const std::string& vehicle_name, int num_thrusters,
                                              const std::optional<task::StateLayout>& layout,
                                              task::TaskConfig& task);

}  // namespace auvrl::agent
