#include "launcher/run_config.hpp"

#include <stdexcept>

#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"
#include "common/task/task_yaml.hpp"
#include "common/vehicle_facts.hpp"

namespace auvrl::launcher {

namespace {

config::Table<RunSettings> make_run_table() {
  using C = RunSettings;
  config::Table<C> t("run", "the launcher (auvrl train): processes, budget, supervision");
  t.field("actors", &C::actors, "0: one per CPU", "exploration actors").range(0);
  t.field("seed", &C::seed, "",
          "actor i uses seed * 1000 + i (+ a restart offset, none when reproducible)");
  t.field("max_train_s", &C::max_train_s, "s, 0: until the learner ends",
          "wall-clock training budget (not used when reproducible)");
  t.field("reproducible", &C::reproducible, "",
          "the same seed, configuration and build give byte-identical checkpoints, policies "
          "and evaluation; budgets count updates, not seconds");
  t.field("round_weights_every_steps", &C::round_weights_every_steps, "actor steps",
          "reproducible: an actor switches to the learner's next weights this often")
      .range(1);
  t.field("best_eval_every_updates", &C::best_eval_every_updates, "updates",
          "reproducible: quick evaluation of the learner's weights this often")
      .range(1);
  t.field("best_eval_period_s", &C::best_eval_period_s, "s",
          "quick evaluation of the newest weights this often (not reproducible)");
  t.field("best_eval_suite", &C::best_eval_suite, "way-points",
          "validation way-points in that quick evaluation");
  t.field("best_eval_max_hold_m", &C::best_eval_max_hold_m, "m, > 0",
          "the best policy holds within this on average");
  t.field("learner_cpu", &C::learner_cpu, "-1: not pinned", "CPU the learner is pinned to");
  t.field("private_lockstep_bus", &C::private_lockstep_bus, "",
          "each simulator and its actor talk on a bus of their own");
  t.field("max_restarts", &C::max_restarts, "",
          "a role restarted more often than this within restart_window_s stops the run");
  t.field("restart_window_s", &C::restart_window_s, "s", "see max_restarts");
  t.field("heartbeat_timeout_s", &C::heartbeat_timeout_s, "s, 0: not watched",
          "a process silent this long is taken as hung and restarted");
  t.field("discard_fault_s", &C::discard_fault_s, "s",
          "an actor discarding every episode this long (its simulator alive) ends the run")
      .range(0.1);
  return t;
}

/// The objective of the fine-tuning's episodes.
void add_objective_fields(config::Table<tuning::FinetuneConfig>& t) {
  using C = tuning::FinetuneConfig;
  t.field("hold_weight", &C::hold_weight, "s per m",
          "weight of the mean distance over the arrival and hold_steps after it");
  t.field("hold_steps", &C::hold_steps, "steps", "steps of holding the objective prices");
  t.field("hold_turn_weight", &C::hold_turn_weight, "s per rad/s",
          "price of the heading's net change over the same steps, per second (turning on the "
          "spot)");
  t.field("flip_margin_rad", &C::flip_margin_rad, "rad",
          "|roll| or |pitch| beyond this costs flip_margin_weight");
  t.field("flip_margin_weight", &C::flip_margin_weight, "s per rad", "see flip_margin_rad");
  t.field("episode_steps", &C::episode_steps, "steps", "each episode's length");
  t.field("randomised_episode_steps", &C::randomised_episode_steps, "steps, 0: episode_steps",
          "the randomised way-points' episode length");
  t.field("pid_lag_weight", &C::pid_lag_weight, "s per s",
          "cost of arriving later than pid_lead_s before the PID baseline");
  t.field("pid_lead_s", &C::pid_lead_s, "s", "see pid_lag_weight");
  t.field("energy_weight", &C::energy_weight, "s per unit of energy",
          "price of thrust energy (sum of the mean squared normalised command per step)");
  t.field("smoothness_weight", &C::smoothness_weight, "s per unit",
          "price of the mean absolute change of the normalised command per step");
  t.field("integration_substeps", &C::integration_substeps, "0: the vehicle file's",
          "integrator steps per control step in the objective's episodes");
}

config::Table<tuning::FinetuneConfig> make_finetune_table() {
  using C = tuning::FinetuneConfig;
  config::Table<C> t("finetune", "fine-tuning of the trained policy (evolution strategies)");
  t.field("iterations", &C::iterations, "0: no fine-tuning", "fine-tuning iterations");
  t.field("pairs", &C::pairs, "", "antithetic perturbation pairs per iteration");
  t.field("sigma", &C::sigma, "weight units", "perturbation scale");
  t.field("learning_rate", &C::learning_rate, "", "Adam's step on the rank-weighted direction");
  t.field("episodes", &C::episodes, "way-points", "way-points the objective averages over");
  t.field("random_heading_fraction", &C::random_heading_fraction, "0..1",
          "of them, starting at a random heading");
  t.field("facing_away_fraction", &C::facing_away_fraction, "0..1",
          "of those, facing straight away from their way-point instead");
  t.field("any_start_fraction", &C::any_start_fraction, "0..1",
          "of them, starting at rest anywhere in the way-points' region");
  t.field("randomised_fraction", &C::randomised_fraction, "0..1",
          "of them, under the conditions finetune.randomise draws (faults, currents, noise, "
          "model)");
  t.section("randomise", task::randomise_table(), &C::randomise);
  t.field("noisy_fraction", &C::noisy_fraction, "0..1",
          "of the others, with sensor noise only (finetune.randomise's levels and scale)");
  t.field("dive_fraction", &C::dive_fraction, "0..1",
          "of the others, a steep dive from the task's start (the lower half of the depth the "
          "region allows below it)");
  t.field("dive_across_m", &C::dive_across_m, "m", "a dive's largest distance across");
  add_objective_fields(t);
  t.field("threads", &C::threads, "0: one per CPU", "policies evaluated at once");
  t.field("candidates", &C::candidates, "searches",
          "searches from the trained policy, each with its own seed; the kept one passes the "
          "most criteria at selection_seed (the robustness groups, way-points straight behind)");
  t.field("average_candidates", &C::average_candidates, "",
          "where every search (two or more) kept weights: their mean is kept unless the search "
          "chosen among them passes more criteria at selection_seed");
  t.field("candidates_within_s", &C::candidates_within_s, "s, 0: no limit",
          "an asynchronous run starts a further candidate only if it would end within this "
          "many seconds of the training's start, at the pace of those before");
  t.field("candidate_min_fraction", &C::candidate_min_fraction, "0..1, 1: whole searches",
          "with candidates_within_s: a further candidate starts if this share of it would end "
          "in time, and then ends by candidates_within_s");
  t.field("max_search_s", &C::max_search_s, "s, 0: no cap",
          "an asynchronous run's wall-clock cap on each search, from its own start: a search "
          "ends once its next iteration would end past it, keeping the best validated weights");
  t.field("selection_seed", &C::selection_seed, "not 1",
          "the robustness suite's draw that chooses among the candidates, and on which the "
          "trained policies' flips are counted (select)");
  return t;
}

}  // namespace

const config::Table<RunSettings>& run_table() {
  static const config::Table<RunSettings> table = make_run_table();
  return table;
}

const config::Table<tuning::FinetuneConfig>& finetune_table() {
  static const config::Table<tuning::FinetuneConfig> table = make_finetune_table();
  return table;
}

RunConfig read_run_config(const std::string& path) {
  RunConfig c;
  config::Section root = config::load_file(path);
  c.vehicle_path = read_vehicle_path(root);
  task::read_task_config(root.child("task"), c.task);
  config::Section learner = root.child("learner");
  learner.read("max_episodes", c.learner_max_episodes);
  learner.read("max_updates", c.learner_max_updates);
  learner.read("average_window_updates", c.learner_average_window_updates);
  config::Section run = root.child("run");
  run_table().read_keys(run, c.run);
  if (!(c.run.best_eval_max_hold_m > 0.0)) {
    run.fail("best_eval_max_hold_m", "expected a hold error in metres greater than 0");
  }
  run.finish();
  transport::read_transport_section(root.child("transport"), c.transport);
  config::Section finetune = root.child("finetune");
  finetune_table().read(finetune, c.finetune);
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
