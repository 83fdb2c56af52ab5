// One episode of the goal-driven task against a vehicle link: reset, then per control step
// build the state, ask the controller, add exploration noise, command the thrusters, observe,
// reward. The training actor and the evaluation run this same code.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "agent/controller.hpp"
#include "agent/vehicle_link.hpp"
#include "common/task/task.hpp"

namespace auvrl::agent {

/// Exploration noise added to the controller's action (Algorithm 1, line 5 and 9).
class ExplorationNoise {
 public:
  enum class Kind { kNone, kOrnsteinUhlenbeck, kGaussian };
  /// OU as in Lillicrap et al.: theta 0.15, sigma 0.2, dt 1 per step; Gaussian: N(0, sigma).
  ExplorationNoise(Kind kind, int dim, double sigma, double theta, std::uint64_t seed);
  void reset();  ///< start of an episode (OU state to zero)
  /// Restarts the random stream from `seed` (and the OU state at zero).
  void reseed(std::uint64_t seed);
  /// Adds noise to action in place and clips to [-1, 1].
  void apply(task::ActionVector& action);
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
  double sigma_;
  double theta_;
  Eigen::VectorXd state_;
  std::mt19937_64 rng_;  ///< draws N(0, 1) with draw::standard_normal (portable)
};

ExplorationNoise::Kind parse_noise_kind(const std::string& name);  ///< none | ou | gaussian

/// One transition as the learner stores it.
struct Transition {
  task::StateVector state;
  task::ActionVector action;
  double reward = 0.0;
  task::StateVector next_state;
  bool terminal = false;
  Eigen::Vector3d achieved_position_ned_m = Eigen::Vector3d::Zero();
  int step_index = 0;
  /// What EpisodeOptions::expert would have commanded in `state` (empty without an expert).
  task::ActionVector expert_action;
};

/// One control step as recorded for trajectories and plots.
struct TrajectoryRow {
  double time_s = 0.0;
  task::Observation observation;
  std::vector<double> thrust_command_n;
  std::vector<double> thrust_realised_n;
  double distance_m = 0.0;  ///< from the true position where the link knows it (VehicleReport)
};

/// What an episode did.
struct EpisodeSummary {
  double episode_return = 0.0;
  int length_steps = 0;
  bool success = false;  ///< ended inside beta (or, in hold mode, was ever inside)
  /// The distances below and the time to reach use the true position where the link knows it
  /// (VehicleReport::true_position_ned_m), else the reported one.
  double final_distance_m = 0.0;
  double min_distance_m = 0.0;
  double thrust_energy = 0.0;  ///< sum of mean squared normalised commands
  task::EndReason end_reason = task::EndReason::kNone;
  /// First time inside `reach_radius_m` (see EpisodeOptions), s; negative if never.
  double time_to_reach_s = -1.0;
  /// Mean distance to the goal from that moment to the end, m (0 if never reached).
  double mean_error_after_reach_m = 0.0;
};

/// How to run an episode.
struct EpisodeOptions {
  Eigen::Vector3d goal_ned_m = Eigen::Vector3d::Zero();
  double beta_m = 0.5;
  EpisodeStart start;
  /// Radius for time_to_reach_s / mean_error_after_reach_m (evaluation: 0.5 m).
  double reach_radius_m = 0.5;
  /// Keep running after the task would end by reaching (evaluation: the full 70 s to see the
  /// vehicle hold station). Failures still end the episode.
  bool run_full_time = false;
  /// With run_full_time: end the episode this many steps after first coming within
  /// reach_radius_m (negative: run to max_steps). The fine-tuning's objective looks no further.
  int steps_after_reach = -1;
  ExplorationNoise* noise = nullptr;  ///< none: the controller alone
  /// Labels every transition with what this controller would have commanded (it is reset with
  /// the episode and asked every step, but never drives). None: no labels.
  Controller* expert = nullptr;
  /// Called with every transition (not for a blown-up step).
  std::function<void(const Transition&)> on_transition;
  std::vector<TrajectoryRow>* trajectory = nullptr;  ///< recorded when given
};

/// Runs one episode. If the vehicle stops answering, the summary ends with kSimTimeout (and
/// with kBlowUp for a numerical blow-up); no transition after that point is reported.
EpisodeSummary run_episode(const task::TaskConfig& task, VehicleLink& link, Controller& controller,
                           const EpisodeOptions& options);

class EpisodeFigures;

/// One episode stepped by its caller: run_episode's loop with the controller's turn left out,
/// so that several episodes can share one batched pass of a network (run_policy_episodes). The
/// constructor resets the controller, the expert, the noise and the vehicle; then, while
/// running(), the controller fills action() from observation() and state(), and step() carries
/// it out; finish() gives the summary. run_episode is exactly that loop.
class EpisodeStepper {
 public:
  /// Throws std::invalid_argument if the vehicle's thruster count is not the task's.
  EpisodeStepper(const task::TaskConfig& task, VehicleLink& link, Controller& controller,
                 const EpisodeOptions& options);
  ~EpisodeStepper();
  EpisodeStepper(const EpisodeStepper&) = delete;
  EpisodeStepper& operator=(const EpisodeStepper&) = delete;

  /// Whether the episode wants another action.
  bool running() const { return running_; }
  const task::Observation& observation() const { return report_->observation; }
  /// The task's observation vector of this step.
  const task::StateVector& state() const { return state_; }
  /// This step's command, for the controller to fill.
  task::ActionVector& action() { return action_; }
  /// Commands action(), observes and rewards (the expert's label and the noise first).
  void step();
  /// The summary, once the episode is over (or to end it early).
  EpisodeSummary finish();

 private:
  double true_distance_m(const VehicleReport& r, double reported_m) const;

  const task::TaskConfig& task_;
  VehicleLink& link_;
  const EpisodeOptions& options_;
  EpisodeSummary summary_;
  std::unique_ptr<EpisodeFigures> figures_;
  std::optional<VehicleReport> report_;
  task::ActionVector previous_action_, action_, expert_action_;
  task::StateVector state_, next_state_;
  std::vector<double> thrust_n_;
  double distance_m_ = 0.0;
  int step_ = 0;
  bool task_ended_ = false;  ///< reached (when running the full time anyway)
  bool running_ = false;
};

/// One of the episodes run_policy_episodes runs together: its task, vehicle, options, and the
/// policy controller whose driving aids (integrator, position filter, fault accommodation) it
/// uses; that controller's own network is not used.
struct PolicyEpisode {
  const task::TaskConfig* task = nullptr;
  VehicleLink* link = nullptr;
  PolicyController* controller = nullptr;
  const EpisodeOptions* options = nullptr;
};

/// Runs the episodes in lockstep, each step's commands from one batched pass of `network` over
/// the episodes still running: the summaries (and trajectories and transitions) run_episode
/// gives each with its controller driving `network`, to the bit where the network's columns
/// are computed as one sample is (nn::Mlp on AVX-512). Throws std::invalid_argument for more
/// episodes than network.max_batch(), or a network whose sizes are not the controllers'.
std::vector<EpisodeSummary> run_policy_episodes(nn::Mlp& network,
                                                const std::vector<PolicyEpisode>& episodes);

}  // namespace auvrl::agent
