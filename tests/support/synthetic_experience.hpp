// Reproducible experience batches for tests and benchmarks of the learner: values in [-1, 1]
// that follow from (actor, batch sequence number), every 17th transition terminal.
#pragma once

#include <auvrl_lcm/experience_batch_t.hpp>
#include <random>

namespace auvrl::test_support {

inline auvrl_lcm::experience_batch_t synthetic_experience_batch(int actor_id, std::int64_t seq,
                                                                int n, int state_dim,
                                                                int action_dim) {
  auvrl_lcm::experience_batch_t b{};
  b.actor_id = actor_id;
  b.batch_seq = seq;
  b.state_dim = state_dim;
  b.action_dim = action_dim;
  b.num_transitions = n;
  std::mt19937 rng(static_cast<unsigned>(actor_id * 100000 + seq));
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < n; ++i) {
    std::vector<float> s(static_cast<std::size_t>(state_dim)), s2(s.size()),
        a(static_cast<std::size_t>(action_dim));
    for (auto& v : s) v = u(rng);
    for (auto& v : s2) v = u(rng);
    for (auto& v : a) v = u(rng);
    b.states.push_back(s);
    b.next_states.push_back(s2);
    b.actions.push_back(a);
    b.rewards.push_back(u(rng));
    b.terminal.push_back(i % 17 == 0);
    b.achieved_position_ned_m.push_back({u(rng), u(rng), u(rng)});
    b.goal_ned_m.push_back({1.0f, 2.0f, 3.0f});
    b.episode_id.push_back(seq);
    b.step_index.push_back(i);
  }
  return b;
}

}  // namespace auvrl::test_support
