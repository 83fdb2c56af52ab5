// The paper's goal-driven task (section IV-A, Eq. 13-14), in one place for actors, learner
// (hindsight relabelling) and evaluation: what the agent observes, what it is rewarded, when
// an episode ends, and where the way-points come from.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "common/task/randomisation.hpp"
#include "common/vehicle_facts.hpp"

namespace auvrl::config {
template <class T>
class Table;
}  // namespace auvrl::config

namespace auvrl::task {

/// Which observation vector the networks see.
enum class StateLayout {
  /// The paper: x_t = [x_pos, x_e, v_t, u_t-1] with x_e = x_ref - x_pos (NED, scaled), v_t the
  /// six body velocities, u_t-1 the previous action: 3 + 3 + 6 + n values. It has no attitude,
  /// so a goal behind the vehicle (test 2) is only partially observable.
  kPaper,
  /// What a vehicle needs to act on a goal it may face away from: goal error in the body
  /// frame, distance, sin/cos of roll, pitch and yaw, body velocities, previous action, depth:
  /// 3 + 1 + 6 + 6 + n + 1 values.
  kExtended,
  /// The extended layout followed by the thrust each thruster produces now (as the vehicle
  /// reports it, normalised by the maximum thrust): 3 + 1 + 6 + 6 + n + 1 + n values. The
  /// thrusters ramp at only 5.5 % of full thrust per step and lag, so the previous command
  /// says little about the force acting; without it the policy cannot tell how hard it is
  /// still pushing (docs/lab-notes/2026-11-21-fast-preset-origins.md).
  kExtendedThrust,
};

StateLayout parse_layout(const std::string& name);  ///< "paper", "extended", "extended_thrust"

/// The state layout a policy network was trained with, from its input size: 12 + n is the
/// paper's layout (18 with six thrusters), 17 + n the extended one (23), 17 + 2n the extended
/// one with the thrusters' realised thrust (29). Throws std::invalid_argument otherwise.
StateLayout infer_layout(int input_dim, int num_thrusters);
const char* to_string(StateLayout layout);

/// Which reward function.
enum class RewardKind {
  /// Eq. 14: +goal_reward when d <= beta; -step_penalty - thrust_weight f(u) otherwise;
  /// failure_reward when d > beta_max (or the vehicle flips).
  kPaper,
  /// Dense: progress_weight (d_before - d_after) - step_penalty - thrust_weight f(u)
  /// - distance_weight d_after + precision_reward exp(-d_after / precision_scale_m), the same
  /// goal and failure rewards. Learns much faster (shared/reference/learning_notes.md).
  kShaped,
};

RewardKind parse_reward_kind(const std::string& name);  ///< "paper" or "shaped"
const char* to_string(RewardKind kind);

/// Fixed scales that bring every input to roughly [-1, 1] (docs/configuration.md, task.scales).
struct ObservationScales {
  double position_m = 10.0;  ///< positions and goal errors
  double linear_velocity_mps = 1.0;
  double angular_rate_rad_s = 1.0;
  double depth_m = 10.0;
};

/// Integral action for a policy that drives (evaluation, fine-tuning, missions, deployment;
/// never the actors' training episodes): the goal the policy is shown is moved by the integral
/// of the position error, so that a steady push (a current, extra buoyancy, a weak thruster)
/// that the policy answers with a steady offset is driven out, as a PID's integral term does.
/// Each control step within radius_m of the goal: offset += gain_per_s * control_step_s *
/// (goal - position), NED, its length clamped to max_offset_m (anti-windup).
struct GoalIntegralSettings {
  /// The largest gain accepted, 1/s (a 0.1 s time constant: faster than any vehicle's loop).
  static constexpr double kMaxGainPerS = 10.0;
  /// How fast the goal moves per metre of error, 1/s (0: off). Against a constant push the
  /// offset settles with time constant 1 / gain_per_s.
  double gain_per_s = 0.1;
  /// The integrator runs only this close to the goal, m: it corrects the hold, not the transit.
  double radius_m = 1.0;
  double max_offset_m = 1.0;  ///< m
  bool enabled() const { return gain_per_s > 0.0; }
};

/// The position a driving policy is shown (evaluation, fine-tuning, missions, deployment; never
/// the actors' training episodes): a complementary filter (task::PositionFilter) that
/// dead-reckons from the measured velocity and attitude and pulls the estimate toward each
/// position fix with this time constant. White position noise reaches the policy several times
/// weaker; noise-free, the estimate follows the vehicle.
struct PositionFilterSettings {
  /// The longest time constant accepted, s (the estimate then rides on the velocity alone).
  static constexpr double kMaxTimeConstantS = 10.0;
  double time_constant_s = 0.5;  ///< s, 0: off (the measured position itself)
  bool enabled() const { return time_constant_s > 0.0; }
};

/// Thruster fault accommodation for a driving policy (evaluation, missions, deployment; not
/// the fine-tuning's own episodes nor the actors'; task::ThrusterFaultAccommodation): each
/// thruster's efficiency is estimated from its realised thrust against a healthy thruster's
/// response to the same commands. Once it falls below weak_below the thruster is weak until the
/// next reset: it keeps the policy's commands and the healthy thrusters make up the wrench it
/// fails to deliver; below dead_below it is dead: it is no longer commanded and its whole share
/// of the policy's body wrench goes to the healthy ones, in damped least squares either way.
/// Needs the extended_thrust layout (the realised thrust); the other layouts drive without it.
struct FaultAccommodationSettings {
  bool enabled = true;
  /// Estimated efficiency (realised over a healthy thruster's thrust) below which a thruster
  /// counts as dead.
  double dead_below = 0.05;
  /// Estimated efficiency below which a thruster counts as weak (at least dead_below; equal to
  /// it: dead thrusters only).
  double weak_below = 0.3;
  /// Time constant of the efficiency estimate, s.
  double estimate_time_constant_s = 2.0;
  /// Damping of the redistribution, relative to the mean squared column of the thrusters'
  /// wrench matrix: small values rebuild the whole wrench with the healthy thrusters, large
  /// ones leave their commands alone (a dead thruster still gets none).
  double damping = 1.0;
  /// Throws std::invalid_argument naming the first unusable value (task.fault_accommodation.*).
  void validate() const;
};

/// Every constant of the task. Defaults are the paper's where it gives one.
struct TaskConfig {
  StateLayout layout = StateLayout::kPaper;
  ObservationScales scales;
  // The vehicle's facts (apply_vehicle; never set by a configuration file: the vehicle file
  // is the one place they are written).
  int num_thrusters = 6;
  double max_thrust_n = 39.24;  ///< action +-1 maps to +-this, N
  double control_step_s = 0.1;
  ThrusterDynamics thruster_dynamics;           ///< the thrusters' response
  std::vector<ThrusterWrench> thruster_wrench;  ///< per thruster; empty until apply_vehicle

  RewardKind reward = RewardKind::kPaper;
  double goal_reward = 10.0;  ///< on reaching the goal radius beta
  double step_penalty = 1.0;  ///< the "-1" of Eq. 14, per step
  /// f(Tr) = thrust_weight * mean(u_i^2) with u the normalised command in [-1, 1]: the paper
  /// weights thruster usage without giving f; a quadratic cost is the usual energy proxy.
  double thrust_weight = 0.1;
  /// Reward when the episode fails (d > beta_max or flipped). The paper's -10 makes ending the
  /// episode early optimal while success is rare; -1/(1 - gamma) = -100 removes that.
  double failure_reward = -10.0;
  double progress_weight = 10.0;  ///< shaped reward: per metre of progress toward the goal
  double beta_max_m = 20.0;       ///< safety sphere around the goal, m
  double flip_angle_rad = 1.2;    ///< |roll| or |pitch| beyond this ends the episode
  /// Hold mode: reaching does not end the episode; every step inside beta earns
  /// hold_reward_per_step instead, so the agent learns to stay (evaluation demands holding).
  bool hold_mode = false;
  double hold_reward_per_step = 1.0;
  /// Shaped reward only (the paper's Eq. 14 ignores both): terms that pay for being close,
  /// not only for getting closer, so that holding station is precise (the progress term sums
  /// to zero while the vehicle holds, and the hold reward is flat inside beta).
  /// -distance_weight * d per step (d in m) ...
  double distance_weight = 0.0;
  /// ... and +precision_reward * exp(-d / precision_scale_m) per step.
  double precision_reward = 0.0;
  double precision_scale_m = 0.5;
  /// The price of command changes, per step (both rewards, like the thrust cost):
  /// -command_change_weight * mean_i (u_i,t - u_i,t-1)^2, u normalised to [-1, 1]. Every layout
  /// carries the previous command u_t-1, so the reward stays a function of state and action.
  double command_change_weight = 0.0;

  int max_steps = 700;  ///< 70 s of 0.1 s steps: a cut-off, not a terminal state

  Eigen::Vector3d start_position_ned_m{0.0, 0.0, 5.0};
  double start_yaw_rad = 0.0;
  /// Way-points are drawn uniformly in this box (NED, absolute), m.
  Eigen::Vector3d goal_min_ned_m{-10.0, -10.0, 1.0};
  Eigen::Vector3d goal_max_ned_m{10.0, 10.0, 15.0};

  /// Exploring starts (training only: the evaluation always starts at rest at the start
  /// pose). This share of training episodes starts in a random state: attitude uniform in
  /// start attitude +- start_attitude_spread_rad, body velocities uniform in
  /// +-start_velocity_max_body_mps and +-start_rate_max_body_rad_s. A policy that only ever
  /// starts at rest never tries a second way of getting somewhere (every policy learnt to turn
  /// round and reverse to the way-point, even one straight ahead).
  double random_start_fraction = 0.0;
  Eigen::Vector3d start_attitude_spread_rad = Eigen::Vector3d::Zero();    ///< roll, pitch, yaw
  Eigen::Vector3d start_velocity_max_body_mps = Eigen::Vector3d::Zero();  ///< u, v, w
  Eigen::Vector3d start_rate_max_body_rad_s = Eigen::Vector3d::Zero();    ///< p, q, r

  /// Randomised training episodes (training only, like the exploring starts): faults, currents,
  /// sensor noise and model variation drawn per episode by the actors (randomisation.hpp).
  EpisodeRandomisation randomise;

  /// The driving policy's integral action (not the paper's: its preset turns it off).
  GoalIntegralSettings integral;
  /// The driving policy's position estimate (not the paper's: its preset turns it off).
  PositionFilterSettings position_filter;
  /// The driving policy's answer to a weak or dead thruster (not the paper's: its preset turns it
  /// off).
  FaultAccommodationSettings fault_accommodation;

  /// Size of the observation vector.
  int state_dim() const;
  /// Throws std::invalid_argument naming the first unusable value.
  void validate() const;
};

/// What a policy that drives adds to its network (task.integral, task.position_filter,
/// task.fault_accommodation), as the programs that drive a policy from a file (`auvrl eval`,
/// `auvrl export`, `auv_controller`) take it from their command line.
struct DrivingAidOptions {
  double integral_gain_per_s = GoalIntegralSettings{}.gain_per_s;       ///< 1/s, 0: off
  double position_filter_s = PositionFilterSettings{}.time_constant_s;  ///< s, 0: off
  bool fault_accommodation = FaultAccommodationSettings{}.enabled;
  /// Sets task.integral.gain_per_s, task.position_filter.time_constant_s and
  /// task.fault_accommodation.enabled.
  void apply(TaskConfig& task) const;
};

/// Sets the fields the vehicle decides: thruster count, maximum thrust, control step, the
/// thrusters' response and wrenches.
void apply_vehicle(const VehicleFacts& vehicle, TaskConfig& task);

/// The keys of a `task:` section (common/task/task_yaml.cpp).
const config::Table<TaskConfig>& task_table();
/// The keys of a `randomise:` section (task.randomise, finetune.randomise).
const config::Table<EpisodeRandomisation>& randomise_table();

/// What the vehicle reports, as the task uses it.
struct Observation {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d euler_rpy_rad = Eigen::Vector3d::Zero();  ///< roll, pitch, yaw (ZYX)
  Eigen::Vector3d velocity_body_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rate_body_rad_s = Eigen::Vector3d::Zero();
};

using StateVector = Eigen::VectorXf;
using ActionVector = Eigen::VectorXf;  ///< normalised commands in [-1, 1]

/// Rotation from body to NED for ZYX Euler angles (Fossen's R(Theta)).
Eigen::Matrix3d body_to_ned(const Eigen::Vector3d& euler_rpy_rad);

/// The heading (yaw, rad, in (-pi, pi]) that faces straight away from goal_ned_m at
/// position_ned_m, in the horizontal plane: the way-point lies exactly behind (the paper's test2,
/// the fine-tuning's facing-away starts).
double yaw_facing_away_rad(const Eigen::Vector3d& position_ned_m,
                           const Eigen::Vector3d& goal_ned_m);

/// The observation vector for the layout (size config.state_dim()). thrust_realised_n (N, one
/// per thruster) is read by the extended_thrust layout only, which requires it.
void build_state(const TaskConfig& config, const Observation& obs,
                 const Eigen::Vector3d& goal_ned_m, const ActionVector& previous_action,
                 StateVector& out, const std::vector<double>& thrust_realised_n = {});

/// One control step of the goal integrator (GoalIntegralSettings): moves offset_ned_m by the
/// error from position_ned_m to goal_ned_m when within the radius, and returns goal + offset.
Eigen::Vector3d advance_goal_integral(const TaskConfig& config, const Eigen::Vector3d& goal_ned_m,
                                      const Eigen::Vector3d& position_ned_m,
                                      Eigen::Vector3d& offset_ned_m);

/// Rewrites a stored observation vector for another goal (hindsight relabelling): only the
/// goal-dependent entries change (x_e; or body-frame error and distance).
void relabel_state(const TaskConfig& config, const Eigen::Vector3d& old_goal_ned_m,
                   const Eigen::Vector3d& new_goal_ned_m, Eigen::Ref<StateVector> state);

/// Rewrites an observation vector built for old_goal_ned_m as if built for new_goal_ned_m with
/// the vehicle shift_ned_m further along: the goal error and distance, and the position (paper
/// layout) or depth entries (the position filter's estimate in place of the measurement).
void relabel_state(const TaskConfig& config, const Eigen::Vector3d& old_goal_ned_m,
                   const Eigen::Vector3d& new_goal_ned_m, const Eigen::Vector3d& shift_ned_m,
                   Eigen::Ref<StateVector> state);

/// The complementary filter of PositionFilterSettings for one vehicle. Each control step the
/// estimate moves by the measured velocity rotated into NED by the measured attitude
/// (trapezoidal, over control_step_s), then by 1 - exp(-step / time_constant_s) of its distance
/// to the measured position. The first step after reset() takes the measurement as it is.
class PositionFilter {
 public:
  /// Throws std::invalid_argument unless the filter is on and the control step positive.
  PositionFilter(const PositionFilterSettings& settings, double control_step_s);
  void reset() { started_ = false; }
  /// One control step with this measurement; returns the estimate, NED, m.
  const Eigen::Vector3d& update(const Observation& measured);
  /// The share of the distance to the measurement closed each step.
  double gain() const { return gain_; }

 private:
  double control_step_s_;
  double gain_;
  bool started_ = false;
  Eigen::Vector3d position_ned_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_ned_mps_ = Eigen::Vector3d::Zero();  ///< at the last update
};

/// The previous action (normalised commands) an observation vector carries, any layout.
void previous_action_from_state(const TaskConfig& config,
                                const Eigen::Ref<const StateVector>& state,
                                Eigen::VectorXd& previous_action);
/// The realised thrust (N per thruster) an extended_thrust observation vector carries. Throws
/// std::invalid_argument for the other layouts (they do not carry it).
void realised_thrust_from_state(const TaskConfig& config,
                                const Eigen::Ref<const StateVector>& state,
                                Eigen::VectorXd& thrust_realised_n);

/// Vehicle position encoded in an observation vector built for goal_ned_m.
Eigen::Vector3d position_from_state(const TaskConfig& config, const Eigen::Vector3d& goal_ned_m,
                                    const Eigen::Ref<const StateVector>& state);

/// Why an episode ended (values of episode_report_t.end_reason).
enum class EndReason : int {
  kNone = -1,
  kReached = 0,
  kTimeLimit = 1,
  kLeftRegion = 2,
  kFlipped = 3,
  kBlowUp = 4,
  kSimTimeout = 5,
};

/// The outcome of one step.
struct StepOutcome {
  double reward = 0.0;
  bool terminal = false;  ///< the task ended: do not bootstrap from the next state
  bool done = false;      ///< the episode ends (terminal, or the time limit cut it off)
  bool inside_goal = false;
  double distance_m = 0.0;
  EndReason reason = EndReason::kNone;
};

/// f(Tr): the thrust cost of one step's normalised action.
double thrust_cost(const TaskConfig& config, const ActionVector& action);

/// The price of changing the command from previous_action (u_t-1) to action (u_t):
/// command_change_weight * mean((u_t - u_t-1)^2); 0 when previous_action is empty.
double command_change_cost(const TaskConfig& config, const ActionVector& action,
                           const ActionVector& previous_action);

/// The previous action u_t-1 that an observation vector of the layout carries, into out (which
/// allocates only when it is not already of the thruster count's size).
void previous_action_from_state(const TaskConfig& config,
                                const Eigen::Ref<const StateVector>& state, ActionVector& out);

/// True when roll or pitch is beyond the flip angle (Euler angles are singular at 90 deg).
bool is_flipped(const TaskConfig& config, const Eigen::Vector3d& euler_rpy_rad);

/// Reward and termination of one transition, from the distances to the goal before and after
/// it, whether the vehicle flipped, the action, the goal radius and the previous action (for the
/// command change price; empty: none). steps_taken counts this step (the time limit cuts the
/// episode off at config.max_steps).
StepOutcome evaluate_step(const TaskConfig& config, double distance_before_m,
                          double distance_after_m, bool flipped, const ActionVector& action,
                          double beta_m, int steps_taken,
                          const ActionVector& previous_action = ActionVector());

/// Draws a way-point uniformly in the configured box.
Eigen::Vector3d sample_goal(const TaskConfig& config, std::mt19937_64& rng);

/// Where and how a training episode starts (NED pose, body velocities).
struct StartState {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d euler_rpy_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_body_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rate_body_rad_s = Eigen::Vector3d::Zero();
};

/// The start of a training episode: at rest at the start pose, or, with probability
/// random_start_fraction, a random state around it (see TaskConfig). Takes the same number of
/// draws from rng either way.
StartState sample_start(const TaskConfig& config, std::mt19937_64& rng);

}  // namespace auvrl::task
