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

/// The policy driving as the task says, a controller per thread.
eval::ControllerFactory policy_controllers(const nn::Mlp& policy, const task::TaskConfig& task) {
  return [&policy, &task] { return std::make_unique<agent::PolicyController>(policy, task); };
}

/// The PID baseline of the model's gains, a controller per thread.
eval::ControllerFactory pid_controllers(const sim::VehicleModel& model) {
  return [&model] {
    return std::make_unique<agent::PidController>(model, agent::pid_gains_for(model).gains);
  };
}

/// Refuses the evaluation's own draw for a choice.
void require_validation_seed(std::uint64_t seed, const char* who) {
  if (seed == eval::EvaluationConfig{}.seed) {
    throw std::invalid_argument(std::string(who) + "'s robustness suite at seed " +
                                std::to_string(seed) +
                                ": that is the evaluation's own draw; choose on another seed");
  }
}

/// The way-points where `policy` arrives more than kBehindLateMarginS after `pid`, or not at all
/// where the PID does.
int late_arrivals(const std::vector<eval::SummaryRow>& policy,
                  const std::vector<eval::SummaryRow>& pid) {
  int late = 0;
  for (std::size_t i = 0; i < policy.size() && i < pid.size(); ++i) {
    if (!pid[i].reached) continue;
    if (!policy[i].reached ||
        policy[i].time_to_reach_s > pid[i].time_to_reach_s + kBehindLateMarginS) {
      ++late;
    }
  }
  return late;
}

}  // namespace

std::uint64_t candidate_seed(std::uint64_t run_seed, int index) {
  if (index < 0) throw std::invalid_argument("candidate_seed: a negative index");
  return run_seed + static_cast<std::uint64_t>(index);
}

SuiteSelector::SuiteSelector(const sim::VehicleModel& model, const task::TaskConfig& task,
                             std::uint64_t seed, int episodes_per_group, int threads)
    : model_(model),
      task_(task),
      seed_(seed),
      episodes_per_group_(episodes_per_group),
      threads_(threads) {
  require_validation_seed(seed, "the candidates");
  const eval::ControllerFactory pid = pid_controllers(model);
  pid_groups_ = eval::run_robustness(model, suite_config(task_, seed_), pid, threads_,
                                     episodes_per_group_, seed_, "")
                    .groups;
  behind_ = eval::facing_away_episodes(suite_config(task_, seed_), model.num_thrusters(),
                                       kBehindEpisodes, seed_);
  pid_behind_ = eval::run_drawn_episodes(model, suite_config(task_, seed_), pid, behind_, threads_);
}

std::vector<eval::GroupComparison> SuiteSelector::compare(const nn::Mlp& policy) const {
  const std::vector<eval::GroupMetrics> groups =
      eval::run_robustness(model_, suite_config(task_, seed_), policy_controllers(policy, task_),
                           threads_, episodes_per_group_, seed_, "")
          .groups;
  return eval::compare_robustness(groups, pid_groups_);
}

int SuiteSelector::groups_passing(const nn::Mlp& policy) const {
  int passing = 0;
  for (const eval::GroupComparison& c : compare(policy)) passing += c.passes() ? 1 : 0;
  return passing;
}

CandidateScore SuiteSelector::score(const nn::Mlp& policy) const {
  CandidateScore s;
  s.groups_passing = groups_passing(policy);
  s.behind_late =
      late_arrivals(eval::run_drawn_episodes(model_, suite_config(task_, seed_),
                                             policy_controllers(policy, task_), behind_, threads_),
                    pid_behind_);
  s.behind_episodes = static_cast<int>(behind_.size());
  return s;
}

std::size_t choose_candidate(const std::vector<CandidateScore>& scores) {
  if (scores.empty()) throw std::invalid_argument("choose_candidate: no candidate");
  std::size_t best = 0;
  for (std::size_t i = 1; i < scores.size(); ++i) {
    const CandidateScore& a = scores[i];
    const CandidateScore& b = scores[best];
    if (a.criteria_passing() > b.criteria_passing() ||
        (a.criteria_passing() == b.criteria_passing() && a.behind_late < b.behind_late)) {
      best = i;
    }
  }
  return best;
}

bool keep_mean(const CandidateScore& mean, const CandidateScore& chosen_search) {
  return mean.criteria_passing() >= chosen_search.criteria_passing();
}

int suite_failures(const sim::VehicleModel& model, const task::TaskConfig& task, std::uint64_t seed,
                   const nn::Mlp& policy, int episodes_per_group) {
  require_validation_seed(seed, "the selection");
  int failures = 0;
  for (const eval::GroupMetrics& group :
       eval::run_robustness(model, suite_config(task, seed), policy_controllers(policy, task), 1,
                            episodes_per_group, seed, "")
           .groups) {
    failures += group.flips + group.blow_ups;
  }
  return failures;
}

}  // namespace auvrl::tuning
