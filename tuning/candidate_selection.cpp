#include "tuning/candidate_selection.hpp"

#include <stdexcept>
#include <string>

#include "agent/controller.hpp"
#include "agent/pid_controller.hpp"
#include "agent/pid_gains.hpp"

namespace auvrl::tuning {

namespace {

eval::EvaluationConfig suite_config(const task::TaskConfig& task, std::uint64_t seed) {
  eval::EvaluationConfig config;
  config.task = task;
  config.seed = seed;
  return config;
}

/// The policy's groups on the suite drawn at seed, driving as the task says.
std::vector<eval::GroupMetrics> policy_groups(const sim::VehicleModel& model,
                                              const task::TaskConfig& task, std::uint64_t seed,
                                              int episodes_per_group, const nn::Mlp& policy) {
  agent::PolicyController controller(policy, task);
  return eval::run_robustness(model, suite_config(task, seed), controller, episodes_per_group, seed,
                              "")
      .groups;
}

/// Refuses the evaluation's own draw for a choice.
void require_validation_seed(std::uint64_t seed, const char* who) {
  if (seed == eval::EvaluationConfig{}.seed) {
    throw std::invalid_argument(std::string(who) + "'s robustness suite at seed " +
                                std::to_string(seed) +
                                ": that is the evaluation's own draw; choose on another seed");
  }
}

}  // namespace

std::uint64_t candidate_seed(std::uint64_t run_seed, int index) {
  if (index < 0) throw std::invalid_argument("candidate_seed: a negative index");
  return run_seed + static_cast<std::uint64_t>(index);
}

SuiteSelector::SuiteSelector(const sim::VehicleModel& model, const task::TaskConfig& task,
                             std::uint64_t seed, int episodes_per_group)
    : model_(model), task_(task), seed_(seed), episodes_per_group_(episodes_per_group) {
  require_validation_seed(seed, "the candidates");
  agent::PidController pid(model, agent::pid_gains_for(model).gains);
  pid_groups_ =
      eval::run_robustness(model, suite_config(task_, seed_), pid, episodes_per_group_, seed_, "")
          .groups;
}

std::vector<eval::GroupComparison> SuiteSelector::compare(const nn::Mlp& policy) const {
  return eval::compare_robustness(policy_groups(model_, task_, seed_, episodes_per_group_, policy),
                                  pid_groups_);
}

int SuiteSelector::groups_passing(const nn::Mlp& policy) const {
  int passing = 0;
  for (const eval::GroupComparison& c : compare(policy)) passing += c.passes() ? 1 : 0;
  return passing;
}

std::size_t choose_candidate(const std::vector<int>& groups_passing) {
  if (groups_passing.empty()) throw std::invalid_argument("choose_candidate: no candidate");
  std::size_t best = 0;
  for (std::size_t i = 1; i < groups_passing.size(); ++i) {
    if (groups_passing[i] > groups_passing[best]) best = i;
  }
  return best;
}

int suite_failures(const sim::VehicleModel& model, const task::TaskConfig& task, std::uint64_t seed,
                   const nn::Mlp& policy, int episodes_per_group) {
  require_validation_seed(seed, "the selection");
  int failures = 0;
  for (const eval::GroupMetrics& group :
       policy_groups(model, task, seed, episodes_per_group, policy)) {
    failures += group.flips + group.blow_ups;
  }
  return failures;
}

}  // namespace auvrl::tuning
