#include "agent/actor_config.hpp"

#include "common/task/task_yaml.hpp"

namespace auvrl::agent {

void read_actor_config_file(const std::string& path, ActorNodeConfig& c,
                            std::string* vehicle_path) {
  config::Section root = config::load_file(path);
  if (vehicle_path) {
    std::string vehicle = *vehicle_path;
    root.read("vehicle", vehicle);
    if (!vehicle.empty()) *vehicle_path = config::resolve_path(root, vehicle);
  }
  task::read_task_config(root.child("task"), c.task);
  const task::GoalSchedule schedule =
      task::read_goal_schedule(root.child("schedule"), task::GoalSchedule());
  c.initial_beta_m = schedule.beta_m(0);
  config::Section s = root.child("actor");
  std::string noise = c.noise == ExplorationNoise::Kind::kNone       ? "none"
                      : c.noise == ExplorationNoise::Kind::kGaussian ? "gaussian"
                                                                     : "ou";
  s.read("noise", noise);
  try {
    c.noise = parse_noise_kind(noise);
  } catch (const std::invalid_argument& e) {
    s.fail("noise", e.what());
  }
  s.read("noise_sigma", c.noise_sigma);
  s.read("noise_theta", c.noise_theta);
  s.read("max_transitions_per_message", c.max_transitions_per_message);
  s.read("weights_request_period_s", c.weights_request_period_s);
  s.read("weights_silence_s", c.weights_silence_s);
  s.read("max_episodes", c.max_episodes);
  s.read("max_learner_backlog", c.max_learner_backlog);
  s.read("max_wait_s", c.max_wait_s);
  s.read("lockstep_timeout_ms", c.lockstep.timeout_ms);
  s.read("lockstep_attempts", c.lockstep.attempts);
  s.read("demonstration_fraction", c.demonstration_fraction);
  if (!(c.demonstration_fraction >= 0 && c.demonstration_fraction <= 1)) {
    s.fail("demonstration_fraction", "must be in [0, 1]");
  }
  s.read("expert_labels", c.expert_labels);
  if (c.lockstep.timeout_ms < 1) s.fail("lockstep_timeout_ms", "must be >= 1");
  if (c.lockstep.attempts < 1) s.fail("lockstep_attempts", "must be >= 1");
  s.finish();
  config::finish_run_file(root);
}

}  // namespace auvrl::agent
