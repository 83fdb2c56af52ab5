#include "agent/episode.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

namespace {
/// A report the task can use: a NaN or infinity anywhere (not only in the position) would
/// otherwise reach the state vector and the learner's replay buffer.
bool usable(const VehicleReport& r) {
  const task::Observation& o = r.observation;
  return !r.blown_up && o.position_ned_m.allFinite() && o.euler_rpy_rad.allFinite() &&
         o.velocity_body_mps.allFinite() && o.angular_rate_body_rad_s.allFinite();
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

EpisodeSummary run_episode(const task::TaskConfig& task, VehicleLink& link, Controller& controller,
                           const EpisodeOptions& options) {
  const int n = link.num_thrusters();
  if (n != task.num_thrusters) {
    throw std::invalid_argument("the vehicle has " + std::to_string(n) +
                                " thrusters, the task expects " +
                                std::to_string(task.num_thrusters));
  }
  EpisodeSummary summary;
  controller.reset();
  if (options.expert) options.expert->reset();
  if (options.noise) options.noise->reset();

  std::optional<VehicleReport> report = link.reset(options.start);
  if (!report) {
    summary.end_reason = task::EndReason::kSimTimeout;
    return summary;
  }
  if (!usable(*report)) {
    summary.end_reason = task::EndReason::kBlowUp;
    return summary;
  }
  const Eigen::Vector3d& goal = options.goal_ned_m;
  task::ActionVector previous_action = task::ActionVector::Zero(n);
  task::ActionVector action(n);
  task::ActionVector expert_action;
  task::StateVector state, next_state;
  task::build_state(task, report->observation, goal, previous_action, state,
                    report->thrust_realised_n);
  double distance = (goal - report->observation.position_ned_m).norm();
  // The figures measure where the vehicle is: its true position where the link knows it (a
  // simulator in process, whose sensor noise only the controller sees), else what it reports.
  const auto true_distance = [&goal](const VehicleReport& r, double reported_m) {
    return r.true_position_ned_m ? (goal - *r.true_position_ned_m).norm() : reported_m;
  };
  summary.min_distance_m = true_distance(*report, distance);
  std::vector<double> thrust_n(static_cast<std::size_t>(n));
  EpisodeFigures figures(summary, options.reach_radius_m, task.control_step_s);
  bool task_ended = false;  // reached (when running the full time anyway)

  for (int t = 1; t <= task.max_steps; ++t) {
    controller.act(report->observation, goal, state, action);
    if (options.expert) options.expert->act(report->observation, goal, state, expert_action);
    if (options.noise) options.noise->apply(action);
    for (int i = 0; i < n; ++i) {
      thrust_n[static_cast<std::size_t>(i)] = static_cast<double>(action[i]) * task.max_thrust_n;
    }
    std::optional<VehicleReport> next = link.step(thrust_n);
    if (!next) {
      summary.end_reason = task::EndReason::kSimTimeout;
      break;
    }
    if (!usable(*next)) {
      summary.end_reason = task::EndReason::kBlowUp;
      break;
    }
    const double next_distance = (goal - next->observation.position_ned_m).norm();
    const task::StepOutcome outcome = task::evaluate_step(
        task, distance, next_distance, task::is_flipped(task, next->observation.euler_rpy_rad),
        action, options.beta_m, t, previous_action);
    task::build_state(task, next->observation, goal, action, next_state, next->thrust_realised_n);

    if (!task_ended) {
      if (options.on_transition) {
        Transition tr{state,      action,           outcome.reward,
                      next_state, outcome.terminal, next->observation.position_ned_m,
                      t - 1,      expert_action};
        options.on_transition(tr);
      }
      summary.episode_return += outcome.reward;
    }
    const double measured_m = true_distance(*next, next_distance);
    figures.record(t, action, measured_m);
    if (outcome.inside_goal) summary.success = true;
    if (options.trajectory) {
      options.trajectory->push_back(
          {next->time_s, next->observation, thrust_n, next->thrust_realised_n, measured_m});
    }

    report = std::move(next);
    state.swap(next_state);
    previous_action = action;
    distance = next_distance;
    if (episode_stops(outcome, options, t, task.max_steps, figures.steps_after_reach(), summary,
                      task_ended)) {
      break;
    }
  }
  if (summary.end_reason == task::EndReason::kNone)
    summary.end_reason = task::EndReason::kTimeLimit;
  figures.finish();
  return summary;
}

}  // namespace auvrl::agent
