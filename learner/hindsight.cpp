#include "learner/hindsight.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace auvrl::learner {

HindsightRelabeler::HindsightRelabeler(task::TaskConfig task, int k)
    : task_(std::move(task)), relabel_probability_(k / (k + 1.0)) {
  if (k < 1) throw std::invalid_argument("her_k must be >= 1");
  task_.validate();
}

void HindsightRelabeler::on_add(const ReplayBuffer& replay, std::size_t slot, bool overwrote,
                                std::uint64_t overwritten_episode) {
  // An episode that lost a transition to the ring is forgotten as a whole: its remaining
  // transitions are the oldest in the buffer and will be overwritten soon anyway.
  if (overwrote) episodes_.erase(overwritten_episode);
  std::vector<std::int64_t>& slots = episodes_[replay.episode_id(slot)];
  const std::size_t step = replay.step_index(slot);
  // Beyond the task's episode length: not from an actor of this task (a hostile or corrupt
  // step index would otherwise size this episode's index, 8 bytes per claimed step).
  if (step >= static_cast<std::size_t>(std::max(task_.max_steps, 1))) return;
  if (slots.size() <= step) slots.resize(step + 1, -1);
  slots[step] = static_cast<std::int64_t>(slot);
}

void HindsightRelabeler::rebuild(const ReplayBuffer& replay) {
  episodes_.clear();
  // Oldest to newest, so that where an episode id repeats the newest transitions win.
  const std::size_t n = replay.size();
  const std::size_t first = n < replay.capacity() ? 0 : replay.next_slot();
  for (std::size_t i = 0; i < n; ++i) on_add(replay, (first + i) % replay.capacity(), false, 0);
}

void HindsightRelabeler::relabel(const ReplayBuffer& replay, double beta_m, nn::Rng& rng,
                                 Batch& batch) const {
  task::StateVector state, next_state;
  task::ActionVector action, previous_action;
  for (int i = 0; i < batch.size; ++i) {
    if (nn::uniform01(rng) >= relabel_probability_) continue;
    const std::size_t slot = batch.slot[static_cast<std::size_t>(i)];
    const auto it = episodes_.find(replay.episode_id(slot));
    if (it == episodes_.end()) continue;
    const std::vector<std::int64_t>& slots = it->second;
    const std::size_t step = replay.step_index(slot);
    if (step >= slots.size()) continue;
    // A later step (this one included: its own achieved position is a valid future goal).
    const std::size_t future =
        step + static_cast<std::size_t>(nn::uniform_index(rng, slots.size() - step));
    const std::int64_t future_slot = slots[future];
    if (future_slot < 0 ||
        replay.episode_id(static_cast<std::size_t>(future_slot)) != replay.episode_id(slot)) {
      continue;
    }
    const Eigen::Vector3d old_goal = replay.goal_ned_m(slot).cast<double>();
    const Eigen::Vector3d new_goal =
        replay.achieved_position_ned_m(static_cast<std::size_t>(future_slot)).cast<double>();
    const Eigen::Vector3d achieved = replay.achieved_position_ned_m(slot).cast<double>();

    state = batch.state.col(i);
    next_state = batch.next_state.col(i);
    action = batch.action.col(i);
    const Eigen::Vector3d before = task::position_from_state(task_, old_goal, state);

    // A failure that did not depend on the goal (a flip) stays one: terminal with the failure
    // reward while still inside beta_max of the original goal.
    const double old_distance = (old_goal - achieved).norm();
    const bool failed =
        batch.terminal(0, i) > 0.5f &&
        std::abs(batch.reward(0, i) - static_cast<float>(task_.failure_reward)) < 1e-4f &&
        task_.failure_reward != task_.goal_reward;
    const bool flipped = failed && old_distance <= task_.beta_max_m;

    task::relabel_state(task_, old_goal, new_goal, state);
    task::relabel_state(task_, old_goal, new_goal, next_state);
    // The command change price: u_t-1 is in the state (relabelling leaves it).
    task::previous_action_from_state(task_, state, previous_action);
    const task::StepOutcome outcome =
        task::evaluate_step(task_, (new_goal - before).norm(), (new_goal - achieved).norm(),
                            flipped, action, beta_m, static_cast<int>(step) + 1, previous_action);
    batch.state.col(i) = state;
    batch.next_state.col(i) = next_state;
    batch.reward(0, i) = static_cast<float>(outcome.reward);
    batch.terminal(0, i) = outcome.terminal ? 1.0f : 0.0f;
    // The expert's label was for the old goal.
    batch.has_expert(0, i) = 0.0f;
    ++relabelled_;
  }
}

}  // namespace auvrl::learner
