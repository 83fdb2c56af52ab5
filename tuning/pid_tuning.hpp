// Tuning of the PID baseline's gains for one vehicle (`auvrl tune-pid`): a seeded random local
// search, the procedure that tuned Nessie VII's compiled defaults (agent/pid_gains.hpp), on
// validation way-points of its own, scored with the evaluation's own episodes and figures.
//
// Validation draws: `episodes` way-points drawn by task::sample_goal from the task's goal box
// with a stream of the tuning seed (never the evaluation's named scenarios nor its suite seed),
// each from rest at the task's start pose, for the evaluation's 70 s; the first
// fault_fraction of them with the vehicle's first thruster at fault_efficiency, the next
// current_fraction in a current_speed_mps water current of random horizontal direction, the
// rest nominal. Each episode is eval::run_evaluation_episode, so that "reached", the time to
// reach, the hold error and the energy are what `auvrl eval` reports.
//
// Objective (lower is better), with the weights of PidObjectiveWeights:
//   mean time to reach [s] + 20 s/m x mean hold error [m] + 500 s x missed fraction
//   + 0.02 s x mean thrust energy,
// times and hold errors averaged over the episodes not missed, energy over all; missed: never
// within the reach radius, or ended by a flip, leaving the region, a blow-up or a timeout.
//
// Search: start from the given gains (the compiled defaults for `auvrl tune-pid`); each
// iteration multiplies gains_per_step gains, drawn without replacement among those that act on
// the vehicle, by exp(sigma N(0, 1)) and keeps the result if its objective is lower. A gain at
// 0 (the roll loop, off by default) cannot move by a factor: when drawn it is switched on at its
// partner's value (the pitch loop's) times the factor. Deterministic for a seed, whatever the
// number of threads (each thread runs fixed episodes; the sums are taken in episode order).
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "agent/pid_gains.hpp"
#include "common/task/task.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::tuning {

/// The weights of the PID objective (see the file comment). Why these: the time to reach is
/// what the PID is compared on; 20 s per metre makes a hold error of 0.05 m (the defaults hold
/// 0.04 m on Nessie VII) cost a second, so holding is not traded for a faster arrival that
/// then wobbles; 500 s for the missed fraction outweighs any time saved elsewhere (with 100
/// way-points one miss costs 5 s); 0.02 per unit of energy (about 1 s for a typical 50) only
/// breaks ties in favour of quieter thrusters. The same weights tuned Nessie
/// VII's defaults (with a 2 x worst-distance term the evaluation's summary does not carry).
struct PidObjectiveWeights {
  double time = 1.0;           ///< per s of mean time to reach
  double hold_s_per_m = 20.0;  ///< per m of mean hold error
  double missed_s = 500.0;     ///< per unit of missed fraction
  double energy_s = 0.02;      ///< per unit of mean thrust energy
};

/// Settings of the tuning (flags of `auvrl tune-pid`).
struct PidTuningConfig {
  int iterations = 600;            ///< perturbations tried
  int episodes = 100;              ///< validation way-points
  double fault_fraction = 0.25;    ///< of them with the first thruster at fault_efficiency
  double fault_efficiency = 0.1;   ///< a 90 % thrust loss, as the evaluation's fault
  double current_fraction = 0.25;  ///< of them in a current of random horizontal direction
  double current_speed_mps = 0.3;  ///< as the evaluation's current
  int gains_per_step = 3;          ///< gains perturbed together
  double sigma = 0.3;              ///< a gain is multiplied by exp(sigma N(0, 1))
  int episode_steps = 700;         ///< 70 s, as the evaluation
  double reach_radius_m = 0.5;     ///< as the evaluation
  int threads = 2;                 ///< episodes run at once (0: one per CPU)
  PidObjectiveWeights weights;

  /// Throws std::invalid_argument naming the first setting out of range.
  void validate() const;
};

/// The objective on a set of episodes, and its parts.
struct PidObjective {
  double value = 0.0;        ///< the weighted sum (see PidObjectiveWeights)
  double mean_time_s = 0.0;  ///< over the episodes not missed; the episode's length if none
  double mean_hold_m = 0.0;  ///< over the episodes not missed; 0 if none
  double mean_energy = 0.0;  ///< over all episodes
  int missed = 0;            ///< never within the reach radius, or ended by a failure
  int episodes = 0;
};

/// One line of text: "12.345 (time 10.12 s, hold 0.052 m, missed 0/60, energy 51.3)".
std::string format_objective(const PidObjective& objective);

/// The validation way-points for a seed (see the file comment); `salt` picks another stream
/// of the same seed (the held-out draws use 1).
std::vector<eval::EvaluationEpisode> pid_validation_episodes(const task::TaskConfig& task,
                                                             const PidTuningConfig& config,
                                                             std::uint64_t seed,
                                                             std::uint64_t salt = 0);

/// The objective of gains on episodes (config.threads at once). Throws std::invalid_argument
/// for gains the controller refuses.
PidObjective pid_objective(const sim::VehicleModel& model, const task::TaskConfig& task,
                           const agent::PidGains& gains,
                           const std::vector<eval::EvaluationEpisode>& episodes,
                           const PidTuningConfig& config);

/// The gains the search perturbs on a vehicle: every key of agent::pid_gains_table() but
/// those of a DOF the vehicle does not control (sway, pitch, roll).
std::vector<std::string> tunable_gains(const sim::VehicleModel& model);

/// One iteration of the search.
struct PidTuningStep {
  int iteration = 0;                   ///< from 1
  bool accepted = false;               ///< the perturbation lowered the objective
  std::vector<std::string> perturbed;  ///< the gains it moved
  PidObjective tried;                  ///< the perturbation's objective
  PidObjective best;                   ///< the best so far (after this iteration)
  double elapsed_s = 0.0;              ///< since the start
};

/// What the search did.
struct PidTuningResult {
  agent::PidGains start;
  agent::PidGains best;
  PidObjective start_objective;  ///< on the tuning draws
  PidObjective best_objective;   ///< on the tuning draws; never above start_objective
  PidObjective start_holdout;    ///< on held-out draws of the same seed (salt 1)
  PidObjective best_holdout;
  int accepted = 0;  ///< iterations that improved
  double elapsed_s = 0.0;
};

/// Runs the search (see the file comment) from `start`; progress (may be empty) after each
/// iteration. Throws std::invalid_argument for bad settings or starting gains.
PidTuningResult tune_pid(const sim::VehicleModel& model, const task::TaskConfig& task,
                         const agent::PidGains& start, const PidTuningConfig& config,
                         std::uint64_t seed,
                         const std::function<void(const PidTuningStep&)>& progress = {});

/// What `auvrl tune-pid` was asked to do.
struct PidTuningRequest {
  std::string vehicle_path;  ///< required
  std::string out_path;      ///< empty: agent::pid_gains_path(vehicle_path)
  std::uint64_t seed = 1;
  PidTuningConfig config;
  std::string command_line;  ///< recorded in the gains file's header
};

/// The whole `auvrl tune-pid`: loads the vehicle, tunes from the compiled defaults with the
/// default task (its goal box and start pose), prints progress and the objective before and
/// after to `out`, writes the gains file with a header saying how it was produced. Throws
/// std::invalid_argument for a bad request and std::runtime_error for unusable files.
PidTuningResult run_pid_tuning_request(const PidTuningRequest& request, std::ostream& out);

}  // namespace auvrl::tuning
