// Configurations shared by the fuzz targets and the corpus generator (a seed must be made
// with the configuration its target runs).
#pragma once

#include "learner/learner_node.hpp"

namespace auvrl::fuzz {

/// A learner like auv_learner's (paper state layout, hindsight relabelling) with small networks
/// and buffer, so that an input runs in microseconds.
inline learner::LearnerNodeConfig small_learner_config() {
  learner::LearnerNodeConfig c;
  c.ddpg.state_dim = c.task.state_dim();
  c.ddpg.action_dim = c.task.num_thrusters;
  c.ddpg.actor_hidden = {8, 8};
  c.ddpg.critic_hidden = {8, 8};
  c.ddpg.batch_size = 4;
  c.ddpg.replay_capacity = 64;
  c.her = true;
  c.max_actors = 4;
  c.max_updates_per_poll = 2;
  c.broadcast_min_interval_s = 0.0;
  c.stats_period_s = 0.0;  // statistics after every poll: their code runs too
  return c;
}

/// The same in the reproducible mode: rounds from two actors, weights every 2 updates, a
/// checkpoint-free snapshot-free node (files would slow every input down).
inline learner::LearnerNodeConfig small_reproducible_learner_config() {
  learner::LearnerNodeConfig c = small_learner_config();
  c.reproducible = true;
  c.max_actors = 2;
  c.round_weights_every_steps = 1;
  c.checkpoint_every_updates = 0;
  return c;
}

/// The training run fuzz_training_monitor follows: two actors, its roles started in this order
/// as processes kMonitorFirstPid, kMonitorFirstPid + 1, ...
inline constexpr const char* kMonitorRoles[] = {"logger", "learner", "sim0",
                                                "sim1",   "actor0",  "actor1"};
inline constexpr int kMonitorActors = 2;
inline constexpr int kMonitorFirstPid = 10;

}  // namespace auvrl::fuzz
