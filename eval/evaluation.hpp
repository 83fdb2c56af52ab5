// Evaluation of a controller (a learned policy or the PID baseline) on the paper's test cases
// and a random suite, in this process: the same run_episode() as the training actor, through
// the dynamics library directly (no transport), without exploration noise, each episode run
// for the full 70 s so that holding station after arriving is measured.
//
// Scenarios (start and way-point NED, m):
//   test1    start [0, 0, 5] facing north (yaw 0), way-point [7, 6, 10] (paper, test 1);
//   test2    the same way-point, starting facing away from it: yaw = bearing to it + pi;
//   fault    test1 with thruster T1 at 10 % efficiency (the paper's 90 % thrust reduction);
//   current  test1 in a constant 0.3 m/s water current perpendicular to the horizontal
//            start->goal line, pointing to its right (bearing of the line + 90 deg);
//   suite    100 way-points drawn by task::sample_goal from the training region with a fixed
//            seed, from the fixed start.
// The robustness suite (starts, far way-points, faults, currents, sensor noise, a wrong
// model; eval/robustness.hpp) runs its episodes through run_evaluation_episode too; `all` is
// the five above.
//
// Files written to DIR:
//   vehicle.csv    the vehicle and its thrusters (write_vehicle_csv)
//   summary.csv    one row per episode: scenario, controller, episode, goal_x, goal_y, goal_z
//                  (NED, m), reached (1 if ever within 0.5 m), time_to_reach_s (first time
//                  within 0.5 m; EMPTY if never), mean_error_after_reach_m (mean distance from
//                  that moment to the end; EMPTY if never), final_error_m, thrust_energy (sum
//                  over the 0.1 s steps of the mean squared normalised command: six thrusters
//                  at full thrust for 70 s give 700), end_reason (time_limit, left_region,
//                  flipped, blow_up, sim_timeout; reached only if the last step was inside),
//                  smoothness (command_smoothness: mean over the steps and thrusters of the
//                  absolute change of the normalised command, the first step's counted from
//                  zero).
//   trajectories/<scenario>_<episode>.csv   one row per control step, the first (t = 0) the
//                  state after the reset: t, x, y, z, phi, theta, psi, u, v, w, p, q, r,
//                  cmd_1..cmd_n (commanded thrust, N), thrust_1..thrust_n (realised thrust, N:
//                  the faulted T1 shows its 10 %), distance_m. All scenarios but the suite
//                  write every episode; the suite writes its first suite_trajectories.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "agent/controller.hpp"
#include "agent/episode.hpp"
#include "agent/vehicle_link.hpp"
#include "common/task/task.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::eval {

/// One evaluation scenario (see the file comment). kRobustness marks the robustness suite's
/// episodes (eval/robustness.hpp), which scenario_episodes and parse_scenarios do not give.
enum class Scenario { kTest1, kTest2, kFault, kCurrent, kSuite, kRobustness };

const char* to_string(Scenario scenario);
/// "test1", "test2", "fault", "current", "suite", or "all" (the five in that order); throws
/// std::invalid_argument naming the accepted names otherwise (`auvrl eval` takes
/// "robustness" before asking).
std::vector<Scenario> parse_scenarios(const std::string& name);

/// Everything that defines an evaluation besides the controller and the vehicle.
struct EvaluationConfig {
  /// State layout and scales, episode length (700 steps of 0.1 s = 70 s), fixed start, and the
  /// training region the suite draws from. num_thrusters and max_thrust_n are taken from the
  /// vehicle model by run_evaluation.
  task::TaskConfig task;
  double reach_radius_m = 0.5;  ///< "reached": within this distance of the way-point
  Eigen::Vector3d test_goal_ned_m{7.0, 6.0, 10.0};
  int fault_thruster = 0;          ///< T1 (0-based index)
  double fault_efficiency = 0.1;   ///< a 90 % thrust reduction
  double current_speed_mps = 0.3;  ///< across the start->goal line
  int suite_episodes = 100;
  std::uint64_t seed = 1;       ///< suite way-points and the vehicle resets
  int suite_trajectories = 10;  ///< trajectory files for the first this many; -1: all
  /// Every episode runs this many control steps (700 = 70 s), whatever task.max_steps the
  /// policy was trained with (shorter training episodes must not shorten the evaluation).
  int episode_steps = 700;
  /// The robustness suite adds the facing_away group (eval/robustness.hpp) after its own: the
  /// pipeline's choice among fine-tuning candidates scores it; the bar's suite does not.
  bool robustness_facing_away = false;
};

/// One episode of a scenario: where it starts, where it goes, what is broken.
struct EvaluationEpisode {
  Scenario scenario = Scenario::kTest1;
  int index = 0;  ///< episode number within the scenario, from 0
  Eigen::Vector3d goal_ned_m = Eigen::Vector3d::Zero();
  agent::EpisodeStart start;
  /// The robustness group (eval/robustness.hpp) that names the episode's row in place of the
  /// scenario; empty for the scenarios.
  std::string group;
  /// Radius of the safety sphere around the way-point (the task's beta_max_m), m; 0: the
  /// task's. Way-points farther than it from the start need a larger one.
  double safety_radius_m = 0.0;
};

/// The episodes of a scenario (one for the paper's tests, suite_episodes for the suite).
/// Throws std::invalid_argument if the fault thruster is not one of the task's thrusters, or
/// for kRobustness (robustness_episodes draws those).
std::vector<EvaluationEpisode> scenario_episodes(const EvaluationConfig& config, Scenario scenario);

/// One row of summary.csv (see the file comment for units and empty cells).
struct SummaryRow {
  std::string scenario;
  std::string controller;
  int episode = 0;
  Eigen::Vector3d goal_ned_m = Eigen::Vector3d::Zero();
  bool reached = false;
  double time_to_reach_s = -1.0;           ///< negative if never reached
  double mean_error_after_reach_m = -1.0;  ///< negative if never reached
  double final_error_m = 0.0;
  double thrust_energy = 0.0;
  task::EndReason end_reason = task::EndReason::kNone;
  double smoothness = 0.0;  ///< command_smoothness of the episode's commands
};

/// Mean over the steps and the thrusters of |u_t,i - u_t-1,i|, the change of the normalised
/// command (commanded thrust / maximum thrust, in [-1, 1]) from one 0.1 s step to the next;
/// the first step's change is counted from zero (the thrusters are off at the reset). One row
/// per step; 0 for no steps. Bang-bang between full ahead and astern every step gives 2.
double command_smoothness(const std::vector<std::vector<double>>& commands_normalised);
/// command_smoothness of the rows' commanded thrusts from rows[first] on, each normalised by
/// max_thrust_n.
double trajectory_smoothness(const std::vector<agent::TrajectoryRow>& rows, std::size_t first,
                             double max_thrust_n);

/// Name of an end reason as written in summary.csv.
const char* end_reason_name(task::EndReason reason);

/// Runs one episode in process; fills `trajectory` (when given) with the reset state first,
/// then one row per control step. The row's scenario is the episode's group when it has one.
SummaryRow run_evaluation_episode(const sim::VehicleModel& model, const EvaluationConfig& config,
                                  agent::Controller& controller, const EvaluationEpisode& episode,
                                  std::vector<agent::TrajectoryRow>* trajectory);

/// Runs the scenarios in order and returns one row per episode. With a non-empty out_dir it
/// creates it (and out_dir/trajectories) and writes summary.csv and the trajectory files;
/// throws std::runtime_error naming the path if it cannot. The config's task gets the model's
/// thruster count and maximum thrust.
std::vector<SummaryRow> run_evaluation(const sim::VehicleModel& model, EvaluationConfig config,
                                       agent::Controller& controller,
                                       const std::vector<Scenario>& scenarios,
                                       const std::string& out_dir);

/// How a candidate policy did on validation way-points, against a reference controller (the
/// PID baseline) on the same way-points: what `auvrl train` keeps its best policy by
/// (eval/ranking.hpp ranks two of them).
struct ValidationScore {
  /// What a figure holds when nothing was reached (ranks below any real one).
  static constexpr double kNone = 1e9;

  int reached = 0;
  int episodes = 0;
  double mean_time_s = kNone;  ///< mean time to reach over the reached way-points
  double mean_hold_m = kNone;  ///< mean hold error over the reached way-points
  /// Worst ratio of the candidate's time to reach to the reference's, over the way-points both
  /// reached (kNone: none): below 1, it reached every way-point sooner than the reference.
  double max_time_ratio = kNone;
  /// Means over every way-point (reached or not) of the episode's thrust energy and command
  /// smoothness (SummaryRow::thrust_energy, smoothness).
  double mean_energy = 0.0;
  double mean_smoothness = 0.0;
};

/// Scores `rows` (the candidate's) against `reference` (the same episodes, in the same order,
/// run by the reference controller); throws std::invalid_argument if they do not match.
ValidationScore score_against_reference(const std::vector<SummaryRow>& rows,
                                        const std::vector<SummaryRow>& reference);

/// Writes vehicle.csv: the vehicle evaluated (name, file) and its thrusters (number from 1,
/// name, maximum thrust in N), one row per thruster, for the plots' labels.
void write_vehicle_csv(const std::string& path, const VehicleFacts& vehicle);

/// Header line of summary.csv (no newline).
std::string summary_csv_header();
/// Writes summary.csv; throws std::runtime_error naming the path on failure.
void write_summary_csv(const std::string& path, const std::vector<SummaryRow>& rows);
/// Header line of a trajectory file for n thrusters (no newline).
std::string trajectory_csv_header(int num_thrusters);
/// Writes a trajectory file; throws std::runtime_error naming the path on failure. With
/// waypoint_index (one per row: the mission's way-point the vehicle was driving to, from 0) a
/// last column `waypoint` holds it.
void write_trajectory_csv(const std::string& path, const std::vector<agent::TrajectoryRow>& rows,
                          int num_thrusters, const std::vector<int>* waypoint_index = nullptr);

/// One screen of text: per scenario, episodes, reached count, mean time to reach and mean
/// hold error over the reached episodes, mean final error, thrust energy and smoothness.
std::string format_summary_table(const std::vector<SummaryRow>& rows);

/// The state layout of a policy network (task::infer_layout).
using task::infer_layout;

/// What `auvrl eval` was asked to do.
struct EvalRequest {
  std::string policy_path;            ///< nn network file; empty when controller is "pid"
  std::string controller = "policy";  ///< or "pid"; "policy" needs policy_path
  std::string scenario = "all";
  std::string out_dir;       ///< required
  std::string vehicle_path;  ///< vehicle file (the default unless vehicle_given)
  /// --vehicle was given: with a mission it overrides the mission's vehicle:.
  bool vehicle_given = false;
  /// A mission file (config/missions/*.yaml): run it (eval/mission_run.hpp) instead of the
  /// scenarios.
  std::string mission_path;
  std::string layout;  ///< "paper", "extended", "extended_thrust" or empty: from the policy
  /// The policy's integral action, position filter and fault accommodation.
  task::DrivingAidOptions driving = {};
  std::uint64_t seed = 1;
  int suite_episodes = 100;
  int suite_trajectories = 10;
  /// scenario "robustness" (eval/robustness.hpp): episodes per group, and whether a policy is
  /// also compared with the PID baseline on the same episodes.
  int robustness_episodes = 20;
  bool robustness_with_pid = false;
  /// and whether the suite adds the facing_away group (EvaluationConfig::robustness_facing_away).
  bool robustness_facing_away = false;
};

/// Builds the controller for a request: loads and checks the policy file (errors name the
/// file and what was expected) or builds the PID from the model; applies the vehicle to
/// config.task and sets its layout.
std::unique_ptr<agent::Controller> make_eval_controller(const EvalRequest& request,
                                                        const sim::VehicleModel& model,
                                                        EvaluationConfig& config);

/// The whole `auvrl eval`: loads the vehicle, builds the controller, runs the scenarios,
/// writes DIR, prints the table to `out`, returns the rows. Throws std::invalid_argument for a
/// bad request and std::runtime_error for unreadable or unusable files.
std::vector<SummaryRow> run_eval_request(const EvalRequest& request, std::ostream& out);

}  // namespace auvrl::eval
