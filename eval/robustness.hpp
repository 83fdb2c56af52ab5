// The robustness suite (`auvrl eval --scenario robustness`): a controller on groups of episodes
// that each change one thing from the evaluation's suite (fixed start at rest, a way-point of
// the training region), run in process by run_evaluation_episode for the full 700 steps, and
// summed up per group. docs/usage.md lists the groups with their draws; this file is the
// definition.
//
// Every group draws a random heading (yaw uniform in [-pi, pi)) and, unless it says otherwise,
// starts at rest at the task's start position and goes to a way-point drawn by
// task::sample_goal from the training region (drawn again while within 1 m of the start):
//   rest_start       nothing else changed;
//   any_start        the start drawn uniformly in the training region's box, roll and pitch
//                    in +-0.1 rad, body velocities in +-0.3 m/s, body rates in +-0.1 rad/s;
//                    the safety sphere grows by the start's distance to the way-point (they
//                    may be 31 m apart, the sphere's radius is the task's beta_max_m, 20 m);
//   far_waypoint     a way-point farther than any of the region from the start (its farthest
//                    corner: 17.3 m for the default region) and at most 30 m: the distance
//                    uniform in between, the depth uniform in the region's depth range, the
//                    bearing uniform; the safety sphere grows by that distance;
//   t<i>_10pct       thruster i (1-based, as T1..T6) at 10 % efficiency;
//   t<i>_0pct        thruster i dead (0 %);
//   current          a constant horizontal current, speed uniform in [0.1, 0.5] m/s, direction
//                    uniform;
//   varying_current  a slowly varying current along a uniform direction: 0.2 m/s constant
//                    plus a first-order Gauss-Markov speed (time constant 30 s, sigma 0.03
//                    m/s/sqrt(s), from 0 at the reset): its standard deviation reaches 0.12 m/s
//                    after 70 s (0.03 sqrt(15 (1 - exp(-140 / 30)))), so about 0..0.45 m/s;
//   sensor_noise     Gaussian noise on what the vehicle reports: position 0.1 m, attitude
//                    0.02 rad, velocity 0.05 m/s, rates 0.02 rad/s (every axis);
//   drag_x0.6, drag_x1.5   every quadratic damping coefficient x0.6, x1.5;
//   added_mass_x1.5  every added-mass derivative x1.5;
//   mass_x1.2        mass and inertia x1.2 (ballasted to the file's trim);
//   thrust_x0.7      every thruster at 70 % efficiency;
//   lag_0.6s         the thrusters' first-order lag with a 0.6 s time constant (file: 0.29 s);
//   buoyancy_+2kg    2 kg of extra buoyancy (19.62 N).
// The controllers are built from the vehicle file: they know none of these changes.
//
// Each episode draws from its own stream, std::mt19937_64 seeded with
// splitmix64(splitmix64(seed ^ fnv1a64(group name)) + episode index): adding a group or more
// episodes changes no other episode. Draw order: yaw, (any_start: position, roll, pitch, body
// velocities, body rates), the way-point, (current: speed, direction; varying_current:
// direction), the vehicle's reset seed (sensor noise, varying current).
//
// Metrics per group and controller (group_metrics): reached (ever within 0.5 m), held
// (reached, ran the full 70 s and within 0.5 m at the end), flips and blow-ups (end reasons),
// episodes that left the safety sphere, mean time to reach and mean hold error (mean distance
// after first reaching) over the reached episodes, mean thrust energy and mean smoothness
// (command_smoothness) over all. In the sensor_noise group the distances are those measured,
// as the episode code sees them (0.1 m per axis adds about 0.1 m to a small distance).
//
// Files written to DIR: robustness_episodes.csv (one row per episode: the draw and the
// outcome), robustness.csv (one row per group: the metrics and the description) and
// vehicle.csv.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "agent/controller.hpp"
#include "eval/evaluation.hpp"
#include "sim/dynamics.hpp"
#include "sim/model_variation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::eval {

/// Episodes per group unless asked otherwise.
constexpr int kRobustnessEpisodesPerGroup = 20;
/// A drawn way-point closer than this to the start (m) is drawn again.
constexpr double kRobustnessMinGoalDistanceM = 1.0;
/// The safety sphere of an episode whose start may lie beyond the task's (beta_max_m around the
/// way-point): it grows by the start's distance from the way-point, m.
double grown_safety_radius_m(const task::TaskConfig& task, const Eigen::Vector3d& start_ned_m,
                             const Eigen::Vector3d& goal_ned_m);
/// The farthest way-point of far_waypoint, m.
constexpr double kRobustnessFarMaxM = 30.0;

/// Where a group's episodes start.
enum class StartDraw {
  kRest,      ///< the task's start position, level, at rest
  kAnywhere,  ///< uniform in the training region, small attitude, velocities and rates
};

/// Where a group's way-points are.
enum class GoalDraw {
  kRegion,  ///< task::sample_goal in the training region
  kFar,     ///< farther than the region's farthest corner, at most kRobustnessFarMaxM
};

/// How a group's episodes are drawn and what they change (the defaults change nothing).
struct GroupDraw {
  StartDraw start = StartDraw::kRest;
  GoalDraw goal = GoalDraw::kRegion;
  int thruster = -1;                    ///< the weakened thruster (0-based); -1: none
  double thruster_efficiency = 1;       ///< of that thruster, in [0, 1]
  double all_thrusters_efficiency = 1;  ///< of every thruster (thrust x0.7)
  /// Constant horizontal current: speed uniform in [min, max] m/s, direction uniform; 0: none.
  double current_min_mps = 0, current_max_mps = 0;
  /// Varying current along a uniform direction: constant part (m/s) and a Gauss-Markov speed
  /// (agent::EpisodeStart's current_varying_*); sigma 0: none.
  double varying_mean_mps = 0;
  double varying_sigma_mps = 0;  ///< m/s/sqrt(s)
  double varying_time_constant_s = 30;
  sim::SensorNoise sensor_noise;        ///< on what the vehicle reports
  sim::ModelVariation model_variation;  ///< how the vehicle differs from its file
  /// The start heading turned so that the way-point lies straight behind (horizontally): the
  /// body-frame goal error then says nothing of which way to turn.
  bool facing_away = false;
};

/// One group of the suite: its name (robustness.csv's `group`), what it tests, its draw.
struct RobustnessGroup {
  std::string name;
  std::string description;
  GroupDraw draw;
};

/// The groups in the suite's order (see the file comment) for a vehicle with num_thrusters
/// thrusters; thruster_names (one per thruster, may be empty) only label the descriptions. With
/// with_facing_away, the group facing_away follows them (at rest at the start position, the
/// way-point in the region straight behind): not one of the bar's groups, but scored where the
/// pipeline chooses among fine-tuning candidates, since a search may learn to back towards such
/// a way-point for seconds before it turns.
std::vector<RobustnessGroup> robustness_groups(int num_thrusters,
                                               const std::vector<std::string>& thruster_names = {},
                                               bool with_facing_away = false);

/// The suite's episodes, group after group, episodes_per_group each, drawn from config.task's
/// training region and start position (see the file comment for the streams). Each has
/// scenario kRobustness and its group's name. Throws std::invalid_argument for a negative
/// count, no thrusters, or a region whose farthest corner is kRobustnessFarMaxM or more away.
std::vector<EvaluationEpisode> robustness_episodes(const EvaluationConfig& config,
                                                   int num_thrusters, int episodes_per_group,
                                                   std::uint64_t seed);

/// The per-group figures of one controller (see the file comment). The means over reached
/// episodes are NaN when none was reached.
struct GroupMetrics {
  std::string group;
  std::string controller;
  int episodes = 0;
  int reached = 0;
  int held = 0;
  int flips = 0;
  int blow_ups = 0;
  int left_region = 0;  ///< left the safety sphere around the way-point
  double mean_time_s = std::numeric_limits<double>::quiet_NaN();
  double mean_hold_m = std::numeric_limits<double>::quiet_NaN();
  double mean_energy = 0.0;
  double mean_smoothness = 0.0;
};

/// True when the episode reached, ran its full length (end reason reached or time limit) and
/// ended within reach_radius_m.
bool is_held(const SummaryRow& row, double reach_radius_m = 0.5);

/// The metrics of rows (SummaryRow::scenario is the group), one per group in the order the
/// groups first appear.
std::vector<GroupMetrics> group_metrics(const std::vector<SummaryRow>& rows,
                                        double reach_radius_m = 0.5);

/// The bar a policy must clear against the PID baseline in every group.
struct RobustnessBar {
  double hold_margin_m = 0.05;    ///< hold error at most the PID's plus this
  double smoothness_ratio = 2.0;  ///< smoothness at most this times the PID's
};

/// A policy's group against the reference's (the PID's), criterion by criterion.
struct GroupComparison {
  GroupMetrics policy;
  GroupMetrics reference;
  bool held = false;        ///< held at least as often
  bool no_flip = false;     ///< no flip
  bool time = false;        ///< mean time to reach no later (none reached: only if neither did)
  bool energy = false;      ///< mean thrust energy no more
  bool hold = false;        ///< mean hold error within the margin (none reached: as time)
  bool smoothness = false;  ///< at most smoothness_ratio times the reference's
  bool passes() const { return held && no_flip && time && energy && hold && smoothness; }
};

/// Compares group by group (matched by name; a group the reference lacks throws
/// std::invalid_argument).
std::vector<GroupComparison> compare_robustness(const std::vector<GroupMetrics>& policy,
                                                const std::vector<GroupMetrics>& reference,
                                                const RobustnessBar& bar = {});

/// The mean of paired differences and its 95 % percentile-bootstrap interval; NaN where there
/// is no pair.
struct PairedDifference {
  int pairs = 0;
  double mean = std::numeric_limits<double>::quiet_NaN();
  double low = std::numeric_limits<double>::quiet_NaN();   ///< 2.5th percentile
  double high = std::numeric_limits<double>::quiet_NaN();  ///< 97.5th percentile
};

/// The mean of `differences` and its 95 % interval from `resamples` bootstrap resamples (drawn
/// with replacement from `seed`'s stream: the same inputs give the same interval). Throws
/// std::invalid_argument for fewer than 100 resamples or a non-finite difference.
PairedDifference bootstrap_mean(const std::vector<double>& differences, std::uint64_t seed,
                                int resamples = 2000);

/// One group: how far the policy lies from each threshold of the bar that compares means,
/// episode by episode of the same draw. Negative is on the bar's side.
struct GroupMargins {
  std::string group;
  int held_policy_only = 0;     ///< episodes the policy held and the PID did not
  int held_reference_only = 0;  ///< episodes the PID held and the policy did not
  PairedDifference time_s;      ///< policy - PID, episodes both reached
  PairedDifference energy;      ///< policy - PID
  PairedDifference hold_m;      ///< policy - PID - hold margin, episodes both reached
  PairedDifference smoothness;  ///< policy - ratio x PID
};

/// The margins of every group, in the order the groups first appear in `policy`; rows are
/// paired by group and episode number (the same suite, seed and episode count); held as
/// is_held says at reach_radius_m. Throws std::invalid_argument naming the group and episode of
/// a policy row with no reference row.
std::vector<GroupMargins> paired_margins(const std::vector<SummaryRow>& policy,
                                         const std::vector<SummaryRow>& reference,
                                         std::uint64_t seed, double reach_radius_m = 0.5,
                                         const RobustnessBar& bar = {});

/// A Markdown table of the margins: per group, the episodes only one controller held, then per
/// criterion the mean and its 95 % interval.
std::string robustness_margins_markdown(const std::vector<GroupMargins>& margins,
                                        const RobustnessBar& bar = {});

/// A Markdown table: one row per group, each criterion's two figures and pass/FAIL, then a
/// line counting the groups that pass every criterion.
std::string robustness_comparison_markdown(const std::vector<GroupComparison>& comparisons,
                                           const RobustnessBar& bar = {});

/// Writes dir/robustness_comparison.md (the Markdown table, robustness_comparison_markdown with
/// the default bar, then the margins' table when there are margins) and
/// dir/robustness_comparison.csv (write_robustness_comparison_csv), and returns the Markdown;
/// throws std::runtime_error naming the path it cannot write.
std::string write_robustness_comparison(const std::string& dir,
                                        const std::vector<GroupComparison>& comparisons,
                                        const std::vector<GroupMargins>& margins = {});

/// Writes the comparison as CSV, one row per group: whether it passes, each criterion's pass
/// (1) or fail (0), then the policy's and the PID's figures (columns in docs/usage.md; a mean
/// over no reached episode is empty). The same comparison as the Markdown table, for scripts
/// that read many runs. Throws std::runtime_error naming the path when it cannot write.
void write_robustness_comparison_csv(const std::string& path,
                                     const std::vector<GroupComparison>& comparisons);

/// What run_robustness did.
struct RobustnessResult {
  std::vector<EvaluationEpisode> episodes;
  std::vector<SummaryRow> rows;  ///< one per episode, in the episodes' order
  std::vector<GroupMetrics> groups;
  double elapsed_s = 0.0;  ///< wall-clock time of the episodes
};

/// count episodes of the group facing_away (robustness_groups with with_facing_away), drawn as
/// the suite draws that group at seed (its first episodes are the suite's). Throws
/// std::invalid_argument for a negative count.
std::vector<EvaluationEpisode> facing_away_episodes(const EvaluationConfig& config,
                                                    int num_thrusters, int count,
                                                    std::uint64_t seed);

/// Runs drawn episodes one after another (deterministic), the config's task given the model's
/// thruster count and maximum thrust and config.episode_steps steps each; one row per episode,
/// in their order. Throws std::invalid_argument for a task that does not validate or a reach
/// radius that is not > 0.
std::vector<SummaryRow> run_drawn_episodes(const sim::VehicleModel& model, EvaluationConfig config,
                                           agent::Controller& controller,
                                           const std::vector<EvaluationEpisode>& episodes);

/// Makes a controller for one thread of the episodes (each thread drives with its own).
using ControllerFactory = std::function<std::unique_ptr<agent::Controller>()>;

/// run_drawn_episodes on `threads` threads, each driving with its own controller from
/// make_controller: the same rows as one controller on one thread.
std::vector<SummaryRow> run_drawn_episodes(const sim::VehicleModel& model, EvaluationConfig config,
                                           const ControllerFactory& make_controller,
                                           const std::vector<EvaluationEpisode>& episodes,
                                           int threads);

/// Runs the suite (one episode after another: deterministic) and, with a non-empty out_dir,
/// creates it and writes robustness_episodes.csv, robustness.csv and vehicle.csv; throws
/// std::runtime_error naming a path it cannot write. The config's task gets the model's
/// thruster count and maximum thrust.
RobustnessResult run_robustness(const sim::VehicleModel& model, EvaluationConfig config,
                                agent::Controller& controller, int episodes_per_group,
                                std::uint64_t seed, const std::string& out_dir);
/// run_robustness with the episodes on `threads` threads (run_drawn_episodes): the same result.
RobustnessResult run_robustness(const sim::VehicleModel& model, EvaluationConfig config,
                                const ControllerFactory& make_controller, int threads,
                                int episodes_per_group, std::uint64_t seed,
                                const std::string& out_dir);

/// Writes robustness_episodes.csv (columns in docs/usage.md); rows[i] is episodes[i]'s.
void write_robustness_episodes_csv(const std::string& path,
                                   const std::vector<EvaluationEpisode>& episodes,
                                   const std::vector<SummaryRow>& rows, int num_thrusters);
/// Writes robustness.csv; descriptions come from the groups of the same name.
void write_robustness_csv(const std::string& path, const std::vector<GroupMetrics>& groups,
                          const std::vector<RobustnessGroup>& definitions);

/// One screen of text: one line per group.
std::string format_robustness_table(const std::vector<GroupMetrics>& groups);

/// `auvrl eval --scenario robustness`: runs the controller into request.out_dir, prints the
/// table and the time taken; with request.robustness_with_pid (a policy only) also the PID
/// baseline into out_dir/pid, then writes and prints out_dir/robustness_comparison.md.
RobustnessResult run_robustness_request(const EvalRequest& request, std::ostream& out);

}  // namespace auvrl::eval
