#include "learner/learner_config.hpp"

#include "common/task/task_yaml.hpp"

namespace auvrl::learner {

void read_learner_section(config::Section s, LearnerNodeConfig& c) {
  std::string algo = to_string(c.ddpg.algo);
  s.read("algo", algo);
  try {
    c.ddpg.algo = parse_algo(algo);
  } catch (const std::invalid_argument& e) {
    s.fail("algo", e.what());
  }
  DdpgConfig& d = c.ddpg;
  s.read("actor_hidden", d.actor_hidden);
  s.read("critic_hidden", d.critic_hidden);
  s.read("critic_action_layer", d.critic_action_layer);
  s.read("actor_lr", d.actor_lr);
  s.read("critic_lr", d.critic_lr);
  s.read("critic_weight_decay", d.critic_weight_decay);
  s.read("actor_weight_decay", d.actor_weight_decay);
  s.read("actor_grad_clip_norm", d.actor_grad_clip_norm);
  s.read("critic_grad_clip_norm", d.critic_grad_clip_norm);
  s.read("gamma", d.gamma);
  s.read("tau", d.tau);
  s.read("batch_size", d.batch_size);
  std::uint64_t capacity = d.replay_capacity;
  s.read("replay_capacity", capacity);
  d.replay_capacity = capacity;
  s.read("td3_target_noise", d.td3_target_noise);
  s.read("td3_target_noise_clip", d.td3_target_noise_clip);
  s.read("td3_policy_delay", d.td3_policy_delay);
  s.read("expert_weight", d.expert_weight);
  s.read("expert_q_filter", d.expert_q_filter);
  s.read("expert_weight_half_life_updates", d.expert_weight_half_life_updates);
  s.read("seed", d.seed);
  s.read("updates_per_transition", c.updates_per_transition);
  s.read("warmup_transitions", c.warmup_transitions);
  s.read("max_update_backlog", c.max_update_backlog);
  s.read("max_updates_per_poll", c.max_updates_per_poll);
  s.read("broadcast_every_updates", c.broadcast_every_updates);
  s.read("broadcast_min_interval_s", c.broadcast_min_interval_s);
  s.read("max_actors", c.max_actors);
  s.read("stats_period_s", c.stats_period_s);
  s.read("max_episodes", c.max_episodes);
  s.read("max_updates", c.max_updates);
  s.read("checkpoint_period_s", c.checkpoint_period_s);
  s.read("keep_checkpoints", c.keep_checkpoints);
  s.read("her", c.her);
  s.read("her_k", c.her_k);
  s.finish();
  try {
    d.validate();
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(s.file() + ": learner: " + e.what());
  }
}

void read_learner_config_file(const std::string& path, LearnerNodeConfig& c) {
  config::Section root = config::load_file(path);
  task::read_task_config(root.child("task"), c.task);
  c.schedule = task::read_goal_schedule(root.child("schedule"), c.schedule);
  c.ddpg.state_dim = c.task.state_dim();
  c.ddpg.action_dim = c.task.num_thrusters;
  read_learner_section(root.child("learner"), c);
  config::finish_run_file(root);
}

}  // namespace auvrl::learner
