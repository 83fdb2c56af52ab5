#include "agent/actor_config.hpp"

#include "common/config/table.hpp"
#include "common/task/task_yaml.hpp"
#include "common/vehicle_facts.hpp"

namespace auvrl::agent {
namespace {

const char* noise_name(ExplorationNoise::Kind kind) {
  switch (kind) {
    case ExplorationNoise::Kind::kNone:
      return "none";
    case ExplorationNoise::Kind::kGaussian:
      return "gaussian";
    default:
      return "ou";
  }
}

config::Table<ActorNodeConfig> make_actor_table() {
  using C = ActorNodeConfig;
  config::Table<C> t("actor", "auv_actor: exploration noise, messages, flow control, lockstep");
  t.choice("noise", &C::noise, parse_noise_kind, noise_name, "ou, gaussian, none",
           "exploration noise");
  t.field("noise_sigma", &C::noise_sigma, "action units", "noise standard deviation");
  t.field("noise_theta", &C::noise_theta, "per step", "OU mean reversion");
  t.field("max_transitions_per_message", &C::max_transitions_per_message, "transitions",
          "keeps an experience message near one datagram");
  t.field("weights_request_period_s", &C::weights_request_period_s, "s",
          "while it has no policy, ask for weights this often");
  t.field("weights_silence_s", &C::weights_silence_s, "s",
          "with a policy: ask again after this long unheard");
  t.field("max_episodes", &C::max_episodes, "episodes, 0: until stopped", "stop after this many");

  t.field("max_learner_backlog", &C::max_learner_backlog, "updates, 0: never wait",
          "before an episode, wait while the learner owes more updates than this...");
  t.field("max_wait_s", &C::max_wait_s, "s", "...but never longer than this");
  t.field(
       "lockstep_timeout_ms", [](C& c) -> int& { return c.lockstep.timeout_ms; }, "ms",
       "a lockstep step unanswered this long is sent again")
      .range(1);
  t.field(
       "lockstep_attempts", [](C& c) -> int& { return c.lockstep.attempts; }, "",
       "attempts per step before the episode ends (END_SIM_TIMEOUT)")
      .range(1);
  t.field("demonstration_fraction", &C::demonstration_fraction, "",
          "share of episodes driven by the PID baseline (experience only, not reported)")
      .range(0, 1);
  t.field("expert_labels", &C::expert_labels, "",
          "label every transition with the PID baseline's command (the learner's imitation)");
  return t;
}

}  // namespace

const config::Table<ActorNodeConfig>& actor_table() {
  static const config::Table<ActorNodeConfig> table = make_actor_table();
  return table;
}

void read_actor_config_file(const std::string& path, ActorNodeConfig& c,
                            std::string* vehicle_path) {
  config::Section root = config::load_file(path);
  const std::string vehicle = read_vehicle_path(root);
  if (vehicle_path) *vehicle_path = vehicle;
  task::read_task_config(root.child("task"), c.task);
  const task::GoalSchedule schedule =
      task::read_goal_schedule(root.child("schedule"), task::GoalSchedule());
  c.initial_beta_m = schedule.beta_m(0);
  actor_table().read(root.child("actor"), c);
  config::finish_run_file(root);
}

}  // namespace auvrl::agent
