// The reproducible mode's schedule (auvrl train --reproducible): experience in rounds, and
// which of the learner's weights an actor acts with at each step of a round. Shared by the
// learner and the actors, so that both count the same way.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "common/cli.hpp"

namespace auvrl {

/// Round r (1, 2, ...) is one episode of every actor. The learner takes round r of every actor, in
/// actor order, then owes it U_r updates (updates_per_transition per transition past the warm-up,
/// the fraction carried over). While it works them off it publishes the weights of round r at
/// index k = 0, 1, ... after updates_for_index(k) of them, and a final index after all U_r.
/// An actor acts in round r + 1 with the weights of round r: at its step j of the round, index
/// min(index_for_step(j), the final index). Both sides are counted, never timed, so the same
/// seed gives the same run whatever the machine's load.
struct RoundSchedule {
  /// An actor moves to the next index every this many of its steps.
  int weights_every_steps = 100;
  /// The actors taking part (every one of them contributes to every round).
  int actors = 1;
  /// The learner's gradient updates per transition received.
  double updates_per_transition = 1.0;

  /// Throws std::invalid_argument unless weights_every_steps >= 1 and actors >= 1.
  void validate() const {
    if (weights_every_steps < 1) {
      throw std::invalid_argument("round_weights_every_steps must be >= 1");
    }
    if (actors < 1) throw std::invalid_argument("a reproducible run needs at least one actor");
  }
  /// The index an actor acts with at its step j (0-based) of a round, before the final cap.
  std::int64_t index_for_step(std::int64_t step) const { return step / weights_every_steps; }
  /// The learner's updates of a round after which index k is published: every actor's steps
  /// up to that index produce that many updates between them.
  std::int64_t updates_for_index(std::int64_t k) const {
    return static_cast<std::int64_t>(
        std::ceil(static_cast<double>(k) * weights_every_steps * actors * updates_per_transition));
  }
};

/// The reproducible mode's flags, the same for auv_learner and auv_actor: --reproducible and
/// --round-weights-every-steps (RoundSchedule::weights_every_steps).
inline void add_reproducible_options(cli::CommandLine& cmd, bool* reproducible,
                                     int* weights_every_steps) {
  cmd.flag("reproducible", reproducible,
           "reproducible mode: experience in rounds numbered by the learner, weights by round and "
           "index, every period counted (common/round_schedule.hpp); every process or none");
  cmd.option("round-weights-every-steps", weights_every_steps,
             "reproducible mode: an actor's steps per weights index (the same for every process)");
}

}  // namespace auvrl
