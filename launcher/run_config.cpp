#include "launcher/run_config.hpp"

#include <stdexcept>

#include "common/config/yaml_config.hpp"
#include "common/task/task_yaml.hpp"

namespace auvrl::launcher {

RunConfig read_run_config(const std::string& path) {
  RunConfig c;
  config::Section root = config::load_file(path);
  std::string vehicle = "../vehicles/nessie7.yaml";
  root.read("vehicle", vehicle);
  c.vehicle_path = config::resolve_path(root, vehicle);
  task::read_task_config(root.child("task"), c.task);
  config::Section learner = root.child("learner");
  learner.read("max_episodes", c.learner_max_episodes);
  config::Section run = root.child("run");
  run.read("actors", c.run.actors);
  run.read("seed", c.run.seed);
  run.read("max_train_s", c.run.max_train_s);
  run.read("best_eval_period_s", c.run.best_eval_period_s);
  run.read("best_eval_suite", c.run.best_eval_suite);
  run.read("best_eval_max_hold_m", c.run.best_eval_max_hold_m);
  if (!(c.run.best_eval_max_hold_m > 0.0)) {
    run.fail("best_eval_max_hold_m", "expected a hold error in metres greater than 0");
  }
  run.read("learner_cpu", c.run.learner_cpu);
  run.read("private_lockstep_bus", c.run.private_lockstep_bus);
  run.read("max_restarts", c.run.max_restarts);
  run.read("restart_window_s", c.run.restart_window_s);
  run.read("heartbeat_timeout_s", c.run.heartbeat_timeout_s);
  run.finish();
  transport::read_transport_section(root.child("transport"), c.transport);
  config::Section finetune = root.child("finetune");
  finetune.read("iterations", c.finetune.iterations);
  finetune.read("pairs", c.finetune.pairs);
  finetune.read("sigma", c.finetune.sigma);
  finetune.read("learning_rate", c.finetune.learning_rate);
  finetune.read("episodes", c.finetune.episodes);
  finetune.read("random_heading_fraction", c.finetune.random_heading_fraction);
  finetune.read("hold_weight", c.finetune.hold_weight);
  finetune.read("hold_steps", c.finetune.hold_steps);
  finetune.read("flip_margin_rad", c.finetune.flip_margin_rad);
  finetune.read("flip_margin_weight", c.finetune.flip_margin_weight);
  finetune.read("episode_steps", c.finetune.episode_steps);
  finetune.read("pid_lag_weight", c.finetune.pid_lag_weight);
  finetune.read("pid_lead_s", c.finetune.pid_lead_s);
  finetune.read("integration_substeps", c.finetune.integration_substeps);
  finetune.read("threads", c.finetune.threads);
  finetune.finish();
  try {
    c.finetune.validate();
  } catch (const std::invalid_argument& e) {
    // "finetune: KEY must be ...": name the key, its file and line.
    const std::string what = std::string(e.what()).substr(std::string("finetune: ").size());
    finetune.fail(what.substr(0, what.find(' ')), what);
  }
  return c;
}

}  // namespace auvrl::launcher
