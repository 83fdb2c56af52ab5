#include "agent/actor_node.hpp"

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/weights_request_t.hpp>
#include <stdexcept>

#include "common/channels.hpp"
#include "common/nn/serialize.hpp"
#include "common/random.hpp"
#include "common/unrecoverable.hpp"

namespace auvrl::agent {

// The report's condition bits are the randomisation's.
namespace {
constexpr bool same_bit(int wire, unsigned kind) { return static_cast<unsigned>(wire) == kind; }
using Report = auvrl_lcm::episode_report_t;
using Conditions = task::EpisodeConditions;
static_assert(same_bit(Report::CONDITION_FAULT, Conditions::kFault) &&
              same_bit(Report::CONDITION_CURRENT, Conditions::kCurrent) &&
              same_bit(Report::CONDITION_VARYING_CURRENT, Conditions::kVaryingCurrent) &&
              same_bit(Report::CONDITION_SENSOR_NOISE, Conditions::kSensorNoise) &&
              same_bit(Report::CONDITION_MODEL, Conditions::kModel));
}  // namespace

using Clock = std::chrono::steady_clock;

/// Acts with the newest policy the actor holds, checking for new weights every step so the
/// actor never acts on a stale version longer than one control step; zeros (noise alone)
/// until the first weights arrive.
class ActorNode::ExploringController final : public Controller {
 public:
  explicit ExploringController(ActorNode& node) : node_(node) {}
  void reset() override { step_ = 0; }
  void act(const task::Observation& obs, const Eigen::Vector3d& goal,
           const task::StateVector& state, task::ActionVector& action) override {
    if (node_.config_.reproducible) {
      node_.use_round_weights(step_++);
    } else {
      node_.refresh_policy();
    }
    if (PolicyController* policy = node_.policy_.policy()) {
      policy->act(obs, goal, state, action);
    } else {
      action.setZero(node_.config_.task.num_thrusters);
    }
  }
  std::string name() const override { return "actor"; }

 private:
  ActorNode& node_;
  std::int64_t step_ = 0;  ///< of the episode (the reproducible mode's round)
};

ActorNode::ActorNode(ActorNodeConfig config, transport::Transport& transport, std::ostream& log,
                     transport::Transport* lockstep_transport)
    : config_(std::move(config)),
      transport_(transport),
      log_(log),
      link_(make_lockstep_link(lockstep_transport ? *lockstep_transport : transport,
                               config_.vehicle_id, config_.vehicle, config_.lockstep)),

      controller_(std::make_unique<ExploringController>(*this)),
      noise_(config_.noise, config_.task.num_thrusters, config_.noise_sigma, config_.noise_theta,
             config_.seed * 0x9E3779B97F4A7C15ull + 1),
      goal_rng_(config_.seed),
      start_rng_(config_.seed * 0xBF58476D1CE4E5B9ull + 7),
      conditions_rng_(config_.seed * 0xD6E8FEB86659FD93ull + 13),
      demonstration_rng_(config_.seed * 0x94D049BB133111EBull + 11),
      policy_(config_.task.state_dim(), config_.task.num_thrusters, config_.initial_beta_m) {
  config_.task.validate();
  if (config_.vehicle.num_thrusters() != config_.task.num_thrusters) {
    throw std::invalid_argument("actor: the task's " + std::to_string(config_.task.num_thrusters) +
                                " thrusters are not the vehicle's " + describe(config_.vehicle));
  }
  if (!(config_.demonstration_fraction >= 0 && config_.demonstration_fraction <= 1)) {
    throw std::invalid_argument("actor.demonstration_fraction must be in [0, 1]");
  }
  if (config_.demonstration_fraction > 0 && !config_.demonstrator) {
    throw std::invalid_argument("actor.demonstration_fraction > 0 needs a demonstrator");
  }
  if (config_.expert_labels && !config_.expert) {
    throw std::invalid_argument("actor.expert_labels needs an expert controller");
  }
  if (!config_.expert_labels) config_.expert.reset();
  last_weights_ = last_request_ = Clock::now() - std::chrono::hours(1);
  if (config_.reproducible) {
    if (config_.round_weights_every_steps < 1) {
      throw std::invalid_argument("round_weights_every_steps must be >= 1");
    }
    // Every weights message counts (each round's indices in turn), not only the newest.
    weights_subscription_ = transport::subscribe<auvrl_lcm::policy_weights_t>(
        transport_, channels::kPolicyWeights,
        [this](const std::string&, const auvrl_lcm::policy_weights_t& m) {
          weights_queue_.push_back(m);
        },
        nullptr, 256);
    round_progress_ = last_request_ = Clock::now();
  } else {
    weights_ = std::make_unique<transport::Latest<auvrl_lcm::policy_weights_t>>(
        transport_, channels::kPolicyWeights, 8);
  }
}

ActorNode::~ActorNode() {
  if (weights_subscription_ >= 0) transport_.unsubscribe(weights_subscription_);
}

void ActorNode::refresh_policy() {
  // Weights supersede each other: drain what is pending, keep only the newest.
  transport_.drain();
  if (auto msg = weights_->take()) {
    std::string error;
    switch (policy_.apply(*msg, error)) {
      case WeightsOutcome::kApplied:
        last_weights_ = Clock::now();
        ++counters_.weights_applied;
        break;
      case WeightsOutcome::kRefreshed:
        last_weights_ = Clock::now();
        break;
      case WeightsOutcome::kWrongSizes:
        throw UnrecoverableFault(error + " (vehicle " + describe(config_.vehicle) + ", " +
                                 task::to_string(config_.task.layout) +
                                 " layout): the learner serves another vehicle or layout");
      case WeightsOutcome::kRejected:
        ++counters_.weights_rejected;
        log_ << "auv_actor " << config_.actor_id << ": weights version " << msg->version
             << " rejected: " << error << "\n";
        break;
    }
  }
  const auto now = Clock::now();
  const double silence = std::chrono::duration<double>(now - last_weights_).count();
  const double since_request = std::chrono::duration<double>(now - last_request_).count();
  const bool want = policy_.policy() == nullptr || silence > config_.weights_silence_s;
  if (want && since_request >= config_.weights_request_period_s) {
    send_weights_request(-1, 0);
  }
}

void ActorNode::send_weights_request(std::int64_t want_round, std::int32_t want_index) {
  auvrl_lcm::weights_request_t req{};
  req.utime = transport::now_utime();
  req.actor_id = config_.actor_id;
  req.have_version = policy_.version();
  req.want_round = want_round;
  req.want_index = want_index;
  transport::publish(transport_, channels::kWeightsRequest, req);
  last_request_ = Clock::now();
  ++counters_.weights_requests;
}

void ActorNode::wait_for_learner() {
  if (config_.max_learner_backlog <= 0) return;
  const auto start = Clock::now();
  refresh_policy();
  while (policy_.learner_backlog() > config_.max_learner_backlog && !policy_.training_done()) {
    // The learner broadcasts its weights (and backlog) as it works the backlog off; one
    // that went silent does not hold the actor up for longer than max_wait_s.
    if (std::chrono::duration<double>(Clock::now() - last_weights_).count() > config_.max_wait_s) {
      break;
    }
    transport_.handle(20);
    refresh_policy();
  }
  counters_.waited_s += std::chrono::duration<double>(Clock::now() - start).count();
}

EpisodeSummary ActorNode::run_one_episode() {
  if (config_.reproducible) return run_round();
  wait_for_learner();
  refresh_policy();
  ++episode_id_;
  std::vector<Transition> transitions;
  Eigen::Vector3d goal;
  const EpisodeSummary summary = play_episode(transitions, goal);
  if (!discarded(summary)) {
    for (const auto& msg : experience_messages(transitions, goal)) {
      transport::publish(transport_, channels::kExperience, msg);
      counters_.transitions_sent += msg.num_transitions;
      ++counters_.batches_sent;
    }
  }
  if (!last_was_demonstration_) send_report(summary, goal);
  return summary;
}

bool ActorNode::discarded(const EpisodeSummary& summary) {
  // A numerical blow-up or a lost simulator: none of the episode is trusted.
  return summary.end_reason == task::EndReason::kBlowUp ||
         summary.end_reason == task::EndReason::kSimTimeout;
}

EpisodeSummary ActorNode::play_episode(std::vector<Transition>& transitions,
                                       Eigen::Vector3d& goal) {
  EpisodeOptions options;
  options.goal_ned_m = task::sample_goal(config_.task, goal_rng_);
  goal = options.goal_ned_m;
  options.beta_m = policy_.beta_m();
  const task::StartState start = task::sample_start(config_.task, start_rng_);
  options.start.position_ned_m = start.position_ned_m;
  options.start.euler_rpy_rad = start.euler_rpy_rad;
  options.start.velocity_body_mps = start.velocity_body_mps;
  options.start.angular_rate_body_rad_s = start.angular_rate_body_rad_s;
  options.start.seed = config_.seed * 1000003ull + static_cast<std::uint64_t>(episode_id_);
  // Drawn every episode (a fixed count), so its stream does not depend on the probabilities.
  last_conditions_ =
      task::sample_conditions(config_.task.randomise, config_.task.num_thrusters, conditions_rng_);
  apply_conditions(last_conditions_, options.start);
  options.noise = &noise_;
  options.expert = config_.expert.get();
  // Drawn every episode, so the stream does not depend on the fraction's history.
  last_was_demonstration_ = draw::unit(demonstration_rng_) < config_.demonstration_fraction;
  Controller& controller = last_was_demonstration_ ? *config_.demonstrator : *controller_;
  transitions.clear();
  transitions.reserve(static_cast<std::size_t>(config_.task.max_steps));
  options.on_transition = [&transitions](const Transition& t) { transitions.push_back(t); };

  const EpisodeSummary summary = run_episode(config_.task, *link_, controller, options);
  ++counters_.episodes;
  if (last_was_demonstration_) ++counters_.demonstrations;
  counters_.steps += summary.length_steps;
  if (discarded(summary)) ++counters_.episodes_discarded;
  return summary;
}

std::vector<auvrl_lcm::experience_batch_t> ActorNode::experience_messages(
    const std::vector<Transition>& transitions, const Eigen::Vector3d& goal) {
  const int state_dim = config_.task.state_dim();
  const int action_dim = config_.task.num_thrusters;
  const std::vector<float> goal_row = {static_cast<float>(goal[0]), static_cast<float>(goal[1]),
                                       static_cast<float>(goal[2])};
  std::vector<auvrl_lcm::experience_batch_t> out;
  for (std::size_t begin = 0; begin < transitions.size();
       begin += static_cast<std::size_t>(config_.max_transitions_per_message)) {
    const std::size_t end = std::min(
        transitions.size(), begin + static_cast<std::size_t>(config_.max_transitions_per_message));
    auvrl_lcm::experience_batch_t msg{};
    msg.utime = transport::now_utime();
    msg.actor_id = config_.actor_id;
    msg.batch_seq = ++batch_seq_;
    msg.policy_version = std::max<std::int64_t>(policy_.version(), 0);
    msg.state_dim = state_dim;
    msg.action_dim = action_dim;
    msg.num_transitions = static_cast<std::int32_t>(end - begin);
    msg.round = 0;  // the asynchronous mode
    msg.expert_rows = config_.expert ? msg.num_transitions : 0;
    for (std::size_t i = begin; i < end; ++i) {
      const Transition& t = transitions[i];
      msg.states.emplace_back(t.state.data(), t.state.data() + state_dim);
      msg.actions.emplace_back(t.action.data(), t.action.data() + action_dim);
      msg.rewards.push_back(static_cast<float>(t.reward));
      msg.next_states.emplace_back(t.next_state.data(), t.next_state.data() + state_dim);
      msg.terminal.push_back(t.terminal ? 1 : 0);
      msg.achieved_position_ned_m.push_back({static_cast<float>(t.achieved_position_ned_m[0]),
                                             static_cast<float>(t.achieved_position_ned_m[1]),
                                             static_cast<float>(t.achieved_position_ned_m[2])});
      msg.goal_ned_m.push_back(goal_row);
      msg.episode_id.push_back(episode_id_);
      msg.step_index.push_back(t.step_index);
      if (config_.expert) {
        msg.expert_actions.emplace_back(t.expert_action.data(),
                                        t.expert_action.data() + action_dim);
      }
    }
    out.push_back(std::move(msg));
  }
  return out;
}

void ActorNode::send_report(const EpisodeSummary& summary, const Eigen::Vector3d& goal) {
  auvrl_lcm::episode_report_t report{};
  report.utime = transport::now_utime();
  report.actor_id = config_.actor_id;
  report.episode_id = episode_id_;
  report.policy_version = std::max<std::int64_t>(policy_.version(), 0);
  report.episode_return = summary.episode_return;
  report.length_steps = summary.length_steps;
  report.success = summary.success;
  report.final_distance_m = summary.final_distance_m;
  report.min_distance_m = summary.min_distance_m;
  report.beta_m = policy_.beta_m();
  for (int i = 0; i < 3; ++i) report.goal_ned_m[i] = goal[i];
  report.thrust_energy = summary.thrust_energy;
  report.end_reason = static_cast<std::int8_t>(summary.end_reason);
  report.conditions = static_cast<std::int32_t>(last_conditions_.kinds);
  transport::publish(transport_, channels::kEpisode, report);
}

}  // namespace auvrl::agent
