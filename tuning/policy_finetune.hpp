// Fine-tuning of a trained policy by evolution strategies (Salimans et al. 2017, "Evolution
// Strategies as a Scalable Alternative to Reinforcement Learning"), on the evaluation's own
// criterion: how soon the vehicle gets within the reach radius of a way-point, and how close it
// then stays. `auvrl train` runs it after the TD3 phase (the `finetune:` section).
//
// Why: TD3 with the PID's Q-filtered labels learns the PID's way to a way-point, and its reward
// (progress, precision, hold) prices every step of it, so it brakes as early as the PID does.
// The evaluation asks something simpler: the first moment within 0.5 m, then a small mean
// error. Each iteration perturbs all the actor's weights in +-sigma * eps pairs, runs every
// perturbed policy on a fixed set of way-points of the training region through the
// evaluation's own episode code (agent::run_episode, as the evaluation runs it), ranks the results,
// and moves the weights along the rank-weighted perturbations (nn::Adam). What it bought and
// what was tried: docs/lab-notes/2026-11-24-finetuning.md.
//
// The objective's way-points are drawn from the task's goal region with a stream of their own
// (never the evaluation's suite nor the launcher's validation way-points), from the task's
// fixed start, a fraction of them facing a random heading (as test2 does), a fraction under the
// conditions the fine-tuning's own randomisation (finetune.randomise) draws, and a fraction of
// the others with sensor noise only.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "agent/controller.hpp"
#include "agent/episode.hpp"
#include "common/nn/mlp.hpp"
#include "common/task/task.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::tuning {

/// Settings of the fine-tuning (the `finetune:` section of a run configuration).
struct FinetuneConfig {
  int iterations = 0;           ///< 0: no fine-tuning
  int pairs = 16;               ///< antithetic perturbation pairs per iteration
  double sigma = 0.02;          ///< perturbation scale, in weight units
  double learning_rate = 0.01;  ///< Adam's step on the rank-weighted direction
  int episodes = 24;            ///< way-points the objective averages over (fixed for the run)
  double random_heading_fraction = 0.25;  ///< of them, starting at a random heading
  /// Of those turned starts, this share (spread through them) face straight away from their
  /// way-point instead: the start where a policy must choose which way to turn, and one that
  /// has not learnt to may back towards the way-point for seconds before it does.
  double facing_away_fraction = 0.0;
  /// Of them, this share (spread through the list) starts at rest anywhere in the way-points'
  /// region instead of at the task's start (as the robustness suite's any_start group and a
  /// mission's later legs do), from a stream of its own, at least 1 m from its way-point; the
  /// safety sphere grows by the start's distance, as the suite's does. The fixed start shows
  /// only the climbs and dives the region allows from there (the fast preset's: climbs of 4 m
  /// at most).
  double any_start_fraction = 0.0;
  /// Of them, this share (spread through the list) also gets the conditions `randomise` draws:
  /// faults, currents, sensor noise, a wrong model; from the fine-tuning's own stream. 0: the
  /// vehicle file's, in still water. The faults among them take the thrusters in turn (each as
  /// often as the next), their efficiencies drawn.
  double randomised_fraction = 0.0;
  /// The fine-tuning's own randomisation (the actors' is task.randomise): TD3 can learn in still
  /// water, where it learns fastest, and the fine-tuning still see the conditions a vehicle
  /// meets.
  task::EpisodeRandomisation randomise;
  /// Of the way-points without randomised conditions, this share (spread through them) gets
  /// sensor noise only: randomise's sensor_noise_* levels times a factor drawn from its
  /// sensor_noise_scale, from a stream of its own. Noise on the faulted way-points as well
  /// would make them harder than the faults the fine-tuning is there to learn.
  double noisy_fraction = 0.0;
  /// Of the way-points without randomised conditions, this share (spread through them) is a
  /// steep dive from the task's start instead, from a stream of its own: depth in the lower
  /// half of what the region allows below the start, and at most dive_across_m across (one of
  /// them that any_start_fraction also picks starts elsewhere, as the others do). Drawn
  /// uniformly from the region, such a dive is one way-point in twenty or so, and a policy that
  /// pitches ever further nose-down there (the flip margin's price) is seldom priced for it.
  double dive_fraction = 0.0;
  double dive_across_m = 5.0;  ///< a dive's largest horizontal distance from its start, m
  /// Objective of one way-point, s: the time to within the reach radius (interpolated
  /// between control steps, so that braking a little later counts before it gains a whole
  /// step) plus hold_weight times the mean distance over the arrival step and the hold_steps
  /// after it (s per m); the episode ends there.
  double hold_weight = 2.0;
  int hold_steps = 150;
  /// Plus hold_turn_weight s per rad/s of the heading's net change over the same steps, per
  /// second of them. The task gives no heading to hold, and a trained policy may turn slowly
  /// on the spot while it holds; against a current the push then goes round in its frame from
  /// one pair of thrusters to the other, and it drifts off while they change over (a PID
  /// holds its heading). The net change, not the mean yaw rate: small corrections either way
  /// cost nothing, so that the policy need not chase noise on the measured rates.
  double hold_turn_weight = 0.0;
  /// Plus flip_margin_weight s per rad that |roll| or |pitch| ever exceeds flip_margin_rad:
  /// the rank-weighted steps otherwise learn to pitch ever further nose-down (surge then
  /// helps the slow heave), until a steep dive the few way-points did not include flips the
  /// vehicle (1.2 rad).
  double flip_margin_rad = 0.7;
  double flip_margin_weight = 20.0;
  /// Each episode's length; a way-point not reached costs this time plus the closest
  /// approach (at 1 s per m).
  int episode_steps = 250;
  /// The randomised way-points' episode length (0: episode_steps). A thruster fault slows the
  /// arrival, and an episode ends at its length even before hold_steps of hold have passed:
  /// with the common length a late arrival's hold is priced for its first seconds only.
  int randomised_episode_steps = 0;
  /// Integrator steps per control step in the objective's episodes (0: the vehicle file's).
  /// They only rank perturbed weights; the validation and the evaluation run the vehicle's
  /// own; a coarser integrator ranks them the same at a fraction of the cost.
  int integration_substeps = 0;
  /// Plus pid_lag_weight s per s that the arrival comes later than pid_lead_s before the PID
  /// baseline's on the same way-point (run once, before the first iteration). The mean alone
  /// lets a step trade a way-point the PID already reaches near the plant's limit (test1:
  /// PID 8.24 s, open loop 8.1 s with a stop) for a second elsewhere; the evaluation compares
  /// with the PID per scenario.
  double pid_lag_weight = 0.0;
  double pid_lead_s = 0.0;
  /// Plus energy_weight s per unit of thrust energy (the evaluation's: the sum over the
  /// episode's control steps of the mean squared normalised command) and smoothness_weight s
  /// per unit of the episode's command smoothness (eval::command_smoothness: the mean absolute
  /// change of the normalised command per step and thruster). Both over the episode as it runs,
  /// to hold_steps after the arrival or to its end: the objective can price thrust and chatter
  /// as well as time.
  double energy_weight = 0.0;
  double smoothness_weight = 0.0;
  int threads = 2;  ///< policies evaluated at once (0: one per CPU)
  /// Searches from the same trained policy, one after another, each with a seed of its own
  /// (tuning::candidate_seed: the first is the run's); of their kept weights the pipeline keeps
  /// those that pass the most criteria at selection_seed: the robustness groups against the PID
  /// and the way-points straight behind (tuning::choose_candidate). 1: one search, no choice.
  int candidates = 1;
  /// Where every search (two or more) kept weights: their mean (nn::mean_of) is a further
  /// choice, scored as they are, and kept unless the search chosen among them passes more
  /// criteria (tuning::keep_mean).
  bool average_candidates = false;
  /// An asynchronous run's fine-tuning starts a further candidate only when, at the pace of
  /// those before, it would end within this many seconds of the training's start (its TD3 phase,
  /// or `auvrl finetune`'s start; s; 0: no limit), so that a slower machine keeps the training's
  /// minute with fewer candidates. A reproducible run searches them all.
  double candidates_within_s = 0.0;
  /// With candidates_within_s: a further candidate starts when this share of its iterations
  /// would end in time, at the pace of those before, and then ends by candidates_within_s
  /// (the iteration it ends at is validated, and the best validated weights are kept), so that
  /// a machine with time for most of a further search still gets a second choice. 1: only a
  /// whole further search starts (and none is cut at candidates_within_s).
  double candidate_min_fraction = 1.0;
  /// An asynchronous run's wall-clock cap on each search, from that search's start (s; 0: no
  /// cap): a search ends early once, at the mean pace of its iterations so far, the next would
  /// end past it; the iteration it ends at is validated, and the best validated weights so far
  /// are kept. With the TD3 phase's own cap (run.max_train_s) it bounds the training, so that a
  /// slower or busy machine keeps the training's minute with a shorter search (a further one
  /// starts only within candidates_within_s); a longer TD3 phase asked for (`--max-seconds`)
  /// leaves the searches their time. A reproducible run runs every iteration.
  double max_search_s = 0.0;
  /// The robustness suite's draw that chooses among the candidates, and on which the pipeline's
  /// select stage counts the trained policies' flips: a validation draw of its own, never the
  /// evaluation's (seed 1).
  std::uint64_t selection_seed = 7890;

  /// Throws std::invalid_argument naming the first setting out of range.
  void validate() const;
};

/// One way-point of the objective.
struct FinetuneEpisode {
  agent::EpisodeStart start;
  Eigen::Vector3d goal_ned_m = Eigen::Vector3d::Zero();
  /// The PID baseline's objective with only the arrival priced (set_pid_arrivals), s; NaN:
  /// none, and no lag term.
  double pid_arrival_s = std::numeric_limits<double>::quiet_NaN();
  /// The episode's safety sphere around the way-point, m (0: the task's beta_max_m).
  double safety_radius_m = 0.0;
  /// The episode's length, steps (0: FinetuneConfig::episode_steps).
  int max_steps = 0;
};

/// The objective's way-points for a run seed (see the file comment).
std::vector<FinetuneEpisode> finetune_episodes(const task::TaskConfig& task,
                                               const FinetuneConfig& config, std::uint64_t seed);

/// Sets each episode's pid_arrival_s: the PID baseline's arrival there (interpolated, as the
/// objective's), or, not arriving, the episode's time plus its closest approach.
void set_pid_arrivals(const sim::VehicleModel& model, const task::TaskConfig& task,
                      const FinetuneConfig& config, std::vector<FinetuneEpisode>& episodes);

/// The objective of one way-point split into its prices, each in s (FinetuneConfig says how
/// each is priced): what a search trades against what, and why it keeps what it keeps.
struct ObjectiveTerms {
  /// The interpolated time to the reach radius; not reached, the episode's time plus the
  /// closest approach (1 s per m).
  double arrival_s = 0.0;
  double hold_s = 0.0;        ///< hold_weight x the mean distance after the arrival
  double turn_s = 0.0;        ///< hold_turn_weight x the heading's net change per second held
  double flip_s = 0.0;        ///< flip_margin_weight x the tilt beyond flip_margin_rad
  double energy_s = 0.0;      ///< energy_weight x the thrust energy
  double smoothness_s = 0.0;  ///< smoothness_weight x the command smoothness
  double lag_s = 0.0;  ///< pid_lag_weight x the arrival's lateness against the PID's less the lead
  /// The objective, the sum of the prices as the search sums them (the parts, summed in another
  /// order, may differ from it in the last digit).
  double objective_s = 0.0;

  /// Price by price, for sums and means over way-points.
  ObjectiveTerms& operator+=(const ObjectiveTerms& other);
  ObjectiveTerms& operator/=(double divisor);
};

/// The objective of one way-point (see FinetuneConfig::hold_weight), s, for a controller, by
/// price.
ObjectiveTerms arrival_objective_terms(const sim::VehicleModel& model, const task::TaskConfig& task,
                                       agent::Controller& controller,
                                       const FinetuneEpisode& episode, const FinetuneConfig& config,
                                       double reach_radius_m = 0.5);

/// The threads a search (and its validations) runs on: config.threads, or one per CPU where 0.
int search_threads(const FinetuneConfig& config);

/// The objectives of way-points (arrival_objective(...) of each, reach radius 0.5 m) for one
/// network driving them all at once, in lockstep through batched passes of the network
/// (agent::run_policy_episodes), with the task's driving aids as the fine-tuning drives
/// (finetune_driving_task): the same values as one way-point at a time, faster. Keeps its
/// buffers from one call to the next. One per thread.
class BatchedObjective {
 public:
  /// For up to max_episodes way-points at a time, starting with `network`'s weights.
  BatchedObjective(const sim::VehicleModel& model, const task::TaskConfig& task,
                   const nn::Mlp& network, const FinetuneConfig& config, std::size_t max_episodes);
  /// The weights that drive (set its params()).
  nn::Mlp& network() { return network_; }
  /// Each way-point's objective, s, in order. Throws std::invalid_argument for more than
  /// max_episodes.
  std::vector<double> operator()(const std::vector<FinetuneEpisode>& episodes);

 private:
  const sim::VehicleModel& model_;
  task::TaskConfig task_;
  FinetuneConfig config_;
  nn::Mlp network_;
  std::vector<agent::PolicyController> aids_;  ///< per way-point: the driving aids' state
  std::vector<std::vector<agent::TrajectoryRow>> trajectories_;
};

/// The objective of one way-point, s: arrival_objective_terms(...).objective_s.
double arrival_objective(const sim::VehicleModel& model, const task::TaskConfig& task,
                         agent::Controller& controller, const FinetuneEpisode& episode,
                         const FinetuneConfig& config, double reach_radius_m = 0.5);

/// The fine-tuning's way-points for a run seed, with the PID's arrivals set when the lag is
/// priced: what finetune_policy averages its objective over.
std::vector<FinetuneEpisode> objective_episodes(const sim::VehicleModel& model,
                                                const task::TaskConfig& task,
                                                const FinetuneConfig& config, std::uint64_t seed);

/// The task as the fine-tuning drives a policy in its episodes: the task's driving aids but
/// its fault accommodation, which is off. The network learns to live with a dead thruster
/// itself (the faulted way-points); the accommodation comes on top wherever the policy drives
/// (docs/usage.md, "Fault accommodation").
task::TaskConfig finetune_driving_task(const task::TaskConfig& task);

/// Each price's mean over the episodes for a controller, s.
ObjectiveTerms mean_objective_terms(const sim::VehicleModel& model, const task::TaskConfig& task,
                                    agent::Controller& controller,
                                    const std::vector<FinetuneEpisode>& episodes,
                                    const FinetuneConfig& config);

/// One iteration's figures.
struct FinetuneIteration {
  int iteration = 0;       ///< from 1
  double objective = 0.0;  ///< the updated weights' mean objective, s
  double elapsed_s = 0.0;  ///< since the start of the fine-tuning
};

/// What the fine-tuning did.
struct FinetuneResult {
  nn::Mlp network;               ///< the weights of the lowest mean objective seen
  double start_objective = 0.0;  ///< the trained policy's, s
  double best_objective = 0.0;   ///< network's, s
  int best_iteration = 0;        ///< 0: no iteration improved on the start
  std::vector<FinetuneIteration> iterations;
  /// The way-points the objective averaged over (objective_episodes), for reports on the same.
  std::vector<FinetuneEpisode> episodes;
};

/// Fine-tunes `start` (an actor network for the task's layout) for the task, driving it as
/// finetune_driving_task says; deterministic for
/// a seed whatever the number of threads. progress (may be empty) is called after each
/// iteration with its figures and the updated weights; stop (may be empty) before each, and
/// true ends the fine-tuning there. Throws
/// std::invalid_argument for bad settings or a network that does not fit.
FinetuneResult finetune_policy(
    const sim::VehicleModel& model, const task::TaskConfig& task, const nn::Mlp& start,
    const FinetuneConfig& config, std::uint64_t seed,
    const std::function<void(const FinetuneIteration&, const nn::Mlp& weights)>& progress = {},
    const std::function<bool()>& stop = {});

}  // namespace auvrl::tuning
