#include "learner/learner_config.hpp"

#include <fmt/format.h>

#include "common/config/table.hpp"
#include "common/task/task_yaml.hpp"
#include "common/vehicle_facts.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::learner {
namespace {

/// Networks and optimisers.
void add_network_fields(config::Table<DdpgConfig>& t) {
  using C = DdpgConfig;
  t.choice("algo", &C::algo, parse_algo, to_string, "ddpg, td3", "the algorithm");
  t.field("actor_hidden", &C::actor_hidden, "units", "hidden sizes of the actor mu");
  t.field("critic_hidden", &C::critic_hidden, "units", "hidden sizes of the critic Q");
  t.field("critic_action_layer", &C::critic_action_layer, "0 or 1",
          "critic layer receiving the action (0 with the state, 1 after the first hidden)");
  t.field("actor_lr", &C::actor_lr, "", "Adam learning rate of the actor");
  t.field("critic_lr", &C::critic_lr, "", "Adam learning rate of the critic");
  t.field("critic_weight_decay", &C::critic_weight_decay, "",
          "L2 weight decay of the critic's weights (not biases)");
  t.field("actor_weight_decay", &C::actor_weight_decay, "", "L2 weight decay of the actor");
  t.field("actor_grad_clip_norm", &C::actor_grad_clip_norm, "0: off",
          "global-norm clipping of the actor's gradient");
  t.field("critic_grad_clip_norm", &C::critic_grad_clip_norm, "0: off",
          "global-norm clipping of the critic's gradient");
}

config::Table<DdpgConfig> make_ddpg_table() {
  using C = DdpgConfig;
  config::Table<C> t("learner", "the algorithm's settings");
  add_network_fields(t);
  t.field("gamma", &C::gamma, "", "discount");
  t.field("tau", &C::tau, "", "soft target update rate (Eq. 7)");
  t.field("batch_size", &C::batch_size, "transitions", "minibatch size m").range(1);
  t.field("replay_capacity", &C::replay_capacity, "transitions", "replay buffer capacity").range(1);
  t.field("td3_target_noise", &C::td3_target_noise, "", "TD3: std of the target policy noise");
  t.field("td3_target_noise_clip", &C::td3_target_noise_clip, "",
          "TD3: the target noise is clipped to +- this");
  t.field("td3_policy_delay", &C::td3_policy_delay, "updates",
          "TD3: critic updates per actor and target update");
  t.field("expert_weight", &C::expert_weight, "0: off",
          "weight of the Q-filtered imitation of the actors' expert labels");
  t.field("expert_q_filter", &C::expert_q_filter, "",
          "imitate only where the critic prefers the expert's action");
  t.field("expert_weight_half_life_updates", &C::expert_weight_half_life_updates,
          "updates, 0: constant", "the expert weight halves every this many updates");
  t.field("smooth_temporal_weight", &C::smooth_temporal_weight, "0: off",
          "CAPS: weight (x mean|Q|) of the price of commands changing from x to the next state")
      .range(0.0);
  t.field("smooth_spatial_weight", &C::smooth_spatial_weight, "0: off",
          "CAPS: weight (x mean|Q|) of the price of commands changing under a perturbed state")
      .range(0.0);
  t.field("smooth_spatial_sigma", &C::smooth_spatial_sigma, "state units",
          "CAPS: standard deviation of that perturbation of the network's input")
      .range(0.0);
  t.field("seed", &C::seed, "", "seed of the networks, sampling and TD3 noise");
  return t;
}

config::Table<LearnerNodeConfig> make_learner_table() {
  using C = LearnerNodeConfig;
  config::Table<C> t("learner", "auv_learner: algorithm, replay, updates, broadcasts, checkpoints");
  t.include(ddpg_table(), &C::ddpg);
  t.field("updates_per_transition", &C::updates_per_transition, "",
          "gradient updates per transition received (paper: 1)");
  t.field("warmup_transitions", &C::warmup_transitions, "transitions",
          "updates start once the buffer holds more than max(batch_size, this)");
  t.field("max_update_backlog", &C::max_update_backlog, "updates",
          "most updates owed at once (the surplus is skipped)");
  t.field("max_updates_per_poll", &C::max_updates_per_poll, "updates",
          "most updates between two looks at the network");
  t.field("broadcast_every_updates", &C::broadcast_every_updates, "updates",
          "weights go out after every this many updates...");
  t.field("broadcast_min_interval_s", &C::broadcast_min_interval_s, "s, 0: no limit",
          "...but at most once per this interval");
  t.field("max_actors", &C::max_actors, "", "actor ids accepted: 0 .. max_actors - 1");
  t.field("stats_period_s", &C::stats_period_s, "s", "period of LEARNER_STATS");
  t.field("max_episodes", &C::max_episodes, "episodes, 0: never", "end of training");
  t.field("max_updates", &C::max_updates, "updates, 0: never", "end of training");
  t.field("checkpoint_period_s", &C::checkpoint_period_s, "s",
          "time between checkpoints (asynchronous mode)");
  t.field("checkpoint_every_updates", &C::checkpoint_every_updates, "updates, 0: only the last",
          "updates between checkpoints (reproducible mode)")
      .range(0);
  t.field("keep_checkpoints", &C::keep_checkpoints, "", "checkpoints kept");
  t.field("average_window_updates", &C::average_window_updates, "updates, 0: off",
          "the mean of the actor over its last this many updates is written beside the policy")
      .range(0);
  t.field("average_every_updates", &C::average_every_updates, "updates",
          "updates between the copies of the actor that mean is taken over")
      .range(1);
  t.field("her", &C::her, "", "hindsight relabelling (future strategy) with the task's reward");
  t.field("her_k", &C::her_k, "", "HER: future goals per real one");
  return t;
}

}  // namespace

const config::Table<DdpgConfig>& ddpg_table() {
  static const config::Table<DdpgConfig> table = make_ddpg_table();
  return table;
}

const config::Table<LearnerNodeConfig>& learner_table() {
  static const config::Table<LearnerNodeConfig> table = make_learner_table();
  return table;
}

void read_learner_section(config::Section s, LearnerNodeConfig& c) {
  learner_table().read(s, c);
  try {
    c.ddpg.validate();
    [[maybe_unused]] const WeightAverage window(c.average_every_updates, c.average_window_updates);
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(fmt::format("{}: learner: {}", s.file(), e.what()));
  }
}

void apply_vehicle_file(const std::string& vehicle_path, LearnerNodeConfig& c) {
  c.vehicle = sim::load_vehicle_file(vehicle_path).facts();
  task::apply_vehicle(c.vehicle, c.task);
  c.ddpg.state_dim = c.task.state_dim();
  c.ddpg.action_dim = c.task.num_thrusters;
}

void read_learner_config_file(const std::string& path, LearnerNodeConfig& c,
                              std::string* vehicle_path) {
  config::Section root = config::load_file(path);
  const std::string vehicle = read_vehicle_path(root);
  if (vehicle_path) *vehicle_path = vehicle;
  task::read_task_config(root.child("task"), c.task);
  c.schedule = task::read_goal_schedule(root.child("schedule"), c.schedule);
  apply_vehicle_file(vehicle, c);
  read_learner_section(root.child("learner"), c);
  config::finish_run_file(root);
}

}  // namespace auvrl::learner
