#include "agent/episode.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "common/random.hpp"

namespace auvrl::agent {

ExplorationNoise::Kind parse_noise_kind(const std::string& name) {
  if (name == "none") return ExplorationNoise::Kind::kNone;
  if (name == "ou") return ExplorationNoise::Kind::kOrnsteinUhlenbeck;
  if (name == "gaussian") return ExplorationNoise::Kind::kGaussian;
  throw std::invalid_argument("noise '" + name + "': expected none, ou or gaussian");
}

ExplorationNoise::ExplorationNoise(Kind kind, int dim, double sigma, double theta,
                                   std::uint64_t seed)
    : kind_(kind), sigma_(sigma), theta_(theta), state_(Eigen::VectorXd::Zero(dim)), rng_(seed) {
  if (!(sigma >= 0) || !(theta >= 0)) {
    throw std::invalid_argument("exploration noise: sigma and theta must be >= 0");
  }
}

void ExplorationNoise::reset() { state_.setZero(); }

void ExplorationNoise::reseed(std::uint64_t seed) {
  rng_.seed(seed);
  state_.setZero();
}

void ExplorationNoise::apply(task::ActionVector& action) {
  if (kind_ == Kind::kNone) return;
  for (Eigen::Index i = 0; i < action.size(); ++i) {
    double n = 0.0;
    if (kind_ == Kind::kGaussian) {
      n = sigma_ * draw::standard_normal(rng_);
    } else {
      // Ornstein-Uhlenbeck, dt = one step: x += theta (0 - x) + sigma N(0, 1).
      state_[i] += -theta_ * state_[i] + sigma_ * draw::standard_normal(rng_);
      n = state_[i];
    }
    action[i] = static_cast<float>(std::clamp(static_cast<double>(action[i]) + n, -1.0, 1.0));
  }
}

/// What an episode measures of where the vehicle went, step by step: the distances, the thrust
/// energy, the first arrival within the reach radius and the mean error from then on.
class EpisodeFigures {
 public:
  EpisodeFigures(EpisodeSummary& summary, double reach_radius_m, double control_step_s)
      : summary_(summary), reach_radius_m_(reach_radius_m), control_step_s_(control_step_s) {}

  /// Step `step` commanded `action` and left the vehicle `measured_m` from the goal.
  void record(int step, const task::ActionVector& action, double measured_m) {
    summary_.length_steps = step;
    summary_.thrust_energy += static_cast<double>(action.squaredNorm()) / action.size();
    summary_.final_distance_m = measured_m;
    summary_.min_distance_m = std::min(summary_.min_distance_m, measured_m);
    if (summary_.time_to_reach_s < 0 && measured_m <= reach_radius_m_) {
      summary_.time_to_reach_s = step * control_step_s_;
    }
    if (summary_.time_to_reach_s >= 0) {
      error_sum_after_reach_m_ += measured_m;
      ++steps_after_reach_;
    }
  }

  int steps_after_reach() const { return steps_after_reach_; }

  /// The mean error after arrival, once the episode is over.
  void finish() {
    if (steps_after_reach_ > 0) {
      summary_.mean_error_after_reach_m = error_sum_after_reach_m_ / steps_after_reach_;
    }
  }

 private:
  EpisodeSummary& summary_;
  double reach_radius_m_;
  double control_step_s_;
  double error_sum_after_reach_m_ = 0.0;
  int steps_after_reach_ = 0;
};

namespace {
/// A report the task can use: a NaN or infinity anywhere (not only in the position) would
/// otherwise reach the state vector and the learner's replay buffer.
bool usable(const VehicleReport& r) {
  const task::Observation& o = r.observation;
  return !r.blown_up && o.position_ned_m.allFinite() && o.euler_rpy_rad.allFinite() &&
         o.velocity_body_mps.allFinite() && o.angular_rate_body_rad_s.allFinite();
}

/// Why a report ends the episode: none from the vehicle (kSimTimeout), or one the task cannot
/// use (kBlowUp); kNone when it is usable.
task::EndReason unusable_reason(const std::optional<VehicleReport>& r) {
  if (!r) return task::EndReason::kSimTimeout;
  return usable(*r) ? task::EndReason::kNone : task::EndReason::kBlowUp;
}

/// After step `step` of an episode: whether it stops, recording why in `summary`. An episode
/// that reached its goal with options.run_full_time goes on (`task_ended` set: no more
/// transitions or return), so that the evaluation sees the vehicle hold station.
bool episode_stops(const task::StepOutcome& outcome, const EpisodeOptions& options, int step,
                   int max_steps, int steps_after_reach, EpisodeSummary& summary,
                   bool& task_ended) {
  if (options.steps_after_reach >= 0 && steps_after_reach > options.steps_after_reach) {
    if (summary.end_reason == task::EndReason::kNone) summary.end_reason = outcome.reason;
    return true;
  }
  if (!outcome.done) return false;
  const bool keep_going =
      options.run_full_time && outcome.reason == task::EndReason::kReached && step < max_steps;
  if (summary.end_reason == task::EndReason::kNone || !keep_going) {
    summary.end_reason = outcome.reason;
  }
  if (!keep_going) return true;
  task_ended = true;
  return false;
}
}  // namespace

EpisodeStepper::EpisodeStepper(const task::TaskConfig& task, VehicleLink& link,
                               Controller& controller, const EpisodeOptions& options)
    : task_(task),
      link_(link),
      options_(options),
      figures_(
          std::make_unique<EpisodeFigures>(summary_, options.reach_radius_m, task.control_step_s)) {
  const int n = link.num_thrusters();
  if (n != task.num_thrusters) {
    throw std::invalid_argument("the vehicle has " + std::to_string(n) +
                                " thrusters, the task expects " +
                                std::to_string(task.num_thrusters));
  }
  controller.reset();
  if (options.expert) options.expert->reset();
  if (options.noise) options.noise->reset();

  report_ = link.reset(options.start);
  summary_.end_reason = unusable_reason(report_);
  if (summary_.end_reason != task::EndReason::kNone) return;
  previous_action_ = task::ActionVector::Zero(n);
  action_.resize(n);
  task::build_state(task, report_->observation, options.goal_ned_m, previous_action_, state_,
                    report_->thrust_realised_n);
  distance_m_ = (options.goal_ned_m - report_->observation.position_ned_m).norm();
  summary_.min_distance_m = true_distance_m(*report_, distance_m_);
  thrust_n_.resize(static_cast<std::size_t>(n));
  running_ = task.max_steps >= 1;
}

EpisodeStepper::~EpisodeStepper() = default;

double EpisodeStepper::true_distance_m(const VehicleReport& r, double reported_m) const {
  // The figures measure where the vehicle is: its true position where the link knows it (a
  // simulator in process, whose sensor noise only the controller sees), else what it reports.
  return r.true_position_ned_m ? (options_.goal_ned_m - *r.true_position_ned_m).norm() : reported_m;
}

void EpisodeStepper::step() {
  if (!running_) throw std::logic_error("EpisodeStepper::step: the episode is over");
  const task::TaskConfig& task = task_;
  const EpisodeOptions& options = options_;
  const Eigen::Vector3d& goal = options.goal_ned_m;
  const int t = ++step_;
  if (options.expert) options.expert->act(report_->observation, goal, state_, expert_action_);
  if (options.noise) options.noise->apply(action_);
  for (std::size_t i = 0; i < thrust_n_.size(); ++i) {
    thrust_n_[i] = static_cast<double>(action_[static_cast<Eigen::Index>(i)]) * task.max_thrust_n;
  }
  std::optional<VehicleReport> next = link_.step(thrust_n_);
  running_ = false;  // until this step is through
  if (const task::EndReason why = unusable_reason(next); why != task::EndReason::kNone) {
    summary_.end_reason = why;
    return;
  }
  const double next_distance = (goal - next->observation.position_ned_m).norm();
  const task::StepOutcome outcome = task::evaluate_step(
      task, distance_m_, next_distance, task::is_flipped(task, next->observation.euler_rpy_rad),
      action_, options.beta_m, t, previous_action_);
  task::build_state(task, next->observation, goal, action_, next_state_, next->thrust_realised_n);

  if (!task_ended_) {
    if (options.on_transition) {
      Transition tr{state_,      action_,          outcome.reward,
                    next_state_, outcome.terminal, next->observation.position_ned_m,
                    t - 1,       expert_action_};
      options.on_transition(tr);
    }
    summary_.episode_return += outcome.reward;
  }
  const double measured_m = true_distance_m(*next, next_distance);
  figures_->record(t, action_, measured_m);
  if (outcome.inside_goal) summary_.success = true;
  if (options.trajectory) {
    options.trajectory->push_back(
        {next->time_s, next->observation, thrust_n_, next->thrust_realised_n, measured_m});
  }

  report_ = std::move(next);
  state_.swap(next_state_);
  previous_action_ = action_;
  distance_m_ = next_distance;
  running_ = !episode_stops(outcome, options, t, task.max_steps, figures_->steps_after_reach(),
                            summary_, task_ended_) &&
             t < task.max_steps;
}

EpisodeSummary EpisodeStepper::finish() {
  running_ = false;
  if (summary_.end_reason == task::EndReason::kNone) {
    summary_.end_reason = task::EndReason::kTimeLimit;
  }
  figures_->finish();
  return summary_;
}

EpisodeSummary run_episode(const task::TaskConfig& task, VehicleLink& link, Controller& controller,
                           const EpisodeOptions& options) {
  EpisodeStepper episode(task, link, controller, options);
  while (episode.running()) {
    controller.act(episode.observation(), options.goal_ned_m, episode.state(), episode.action());
    episode.step();
  }
  return episode.finish();
}

std::vector<EpisodeSummary> run_policy_episodes(nn::Mlp& network,
                                                const std::vector<PolicyEpisode>& episodes) {
  const auto count = static_cast<Eigen::Index>(episodes.size());
  if (count > network.max_batch()) {
    throw std::invalid_argument("run_policy_episodes: " + std::to_string(count) +
                                " episodes, more than the network's batch of " +
                                std::to_string(network.max_batch()));
  }
  for (const PolicyEpisode& e : episodes) {
    const nn::MlpSpec& own = e.controller->network().spec();
    if (own.input_dim != network.spec().input_dim || own.output_dim != network.spec().output_dim) {
      throw std::invalid_argument("run_policy_episodes: the network (" + network.spec().describe() +
                                  ") does not fit a controller's (" + own.describe() + ")");
    }
  }
  std::vector<std::unique_ptr<EpisodeStepper>> steppers;
  steppers.reserve(episodes.size());
  for (const PolicyEpisode& e : episodes) {
    steppers.push_back(
        std::make_unique<EpisodeStepper>(*e.task, *e.link, *e.controller, *e.options));
  }
  Eigen::MatrixXf input(network.spec().input_dim, count);
  std::vector<std::size_t> active;
  for (;;) {
    active.clear();
    for (std::size_t i = 0; i < steppers.size(); ++i) {
      if (!steppers[i]->running()) continue;
      const EpisodeStepper& s = *steppers[i];
      input.col(static_cast<Eigen::Index>(active.size())) = episodes[i].controller->network_input(
          s.observation(), episodes[i].options->goal_ned_m, s.state());
      active.push_back(i);
    }
    if (active.empty()) break;
    const auto output = network.forward(input.leftCols(static_cast<Eigen::Index>(active.size())));
    for (std::size_t k = 0; k < active.size(); ++k) {
      EpisodeStepper& s = *steppers[active[k]];
      s.action() = output.col(static_cast<Eigen::Index>(k));
      episodes[active[k]].controller->finish_action(s.state(), s.action());
      s.step();
    }
  }
  std::vector<EpisodeSummary> summaries;
  summaries.reserve(steppers.size());
  for (const auto& s : steppers) summaries.push_back(s->finish());
  return summaries;
}

}  // namespace auvrl::agent
