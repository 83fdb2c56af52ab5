#include "eval/quick_evaluator.hpp"

#include <algorithm>
#include <random>

#include "agent/pid_controller.hpp"
#include "common/parallel.hpp"
#include "common/random.hpp"

namespace auvrl::eval {

QuickEvaluator::QuickEvaluator(const sim::VehicleModel& model, const task::TaskConfig& task,
                               int suite_episodes, int turned)
    : model_(model), task_(task) {
  config_.task = task;
  task::apply_vehicle(model.facts(), config_.task);
  config_.suite_episodes = suite_episodes + turned;
  // Validation way-points of their own: the scenarios the run reports (test1, test2, fault
  // and the suite's seed 1) must not be the ones that choose the policy, or the reported
  // times would be the best of many draws on the very tests.
  config_.seed = kValidationSeed;
  episodes_ = scenario_episodes(config_, Scenario::kSuite);
  std::mt19937_64 rng(kValidationSeed + 1);
  for (int i = suite_episodes; i < suite_episodes + turned; ++i) {
    episodes_[static_cast<std::size_t>(i)].start.euler_rpy_rad[2] =
        (2.0 * draw::unit(rng) - 1.0) * 3.14159265358979323846;
  }
  agent::PidController pid(model_, agent::pid_gains_for(model_).gains);
  reference_ = run(pid);
}

ValidationScore QuickEvaluator::evaluate(const nn::Mlp& network, int threads) const {
  // A controller per thread; each way-point's row in its own slot, the same rows as one thread.
  const int used = std::max(1, std::min<int>(threads, static_cast<int>(episodes_.size())));
  std::vector<agent::PolicyController> controllers;
  for (int w = 0; w < used; ++w) controllers.emplace_back(network, task_);
  std::vector<SummaryRow> rows(episodes_.size());
  for_each_index(used, episodes_.size(), [&](int w, std::size_t i) {
    rows[i] = run_evaluation_episode(model_, config_, controllers[static_cast<std::size_t>(w)],
                                     episodes_[i], nullptr);
  });
  return score_against_reference(rows, reference_);
}

std::vector<SummaryRow> QuickEvaluator::run(agent::Controller& controller) const {
  std::vector<SummaryRow> rows;
  for (const EvaluationEpisode& e : episodes_) {
    rows.push_back(run_evaluation_episode(model_, config_, controller, e, nullptr));
  }
  return rows;
}

}  // namespace auvrl::eval
