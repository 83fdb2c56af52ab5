// auv_actor's logic: runs episodes of the goal-driven task against its own vehicle of auv_sim
// in lockstep, acting with its newest copy of the policy plus exploration noise, and sends the
// transitions to the learner and a report of every episode.
#pragma once

#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <ostream>
#include <random>
#include <vector>

#include "agent/controller.hpp"
#include "agent/episode.hpp"
#include "agent/policy_receiver.hpp"
#include "agent/vehicle_link.hpp"
#include "common/sim_client.hpp"
#include "common/task/task.hpp"
#include "common/transport.hpp"

namespace auvrl::config {
template <class T>
class Table;
}  // namespace auvrl::config

namespace auvrl::agent {

/// Everything auv_actor is configured with besides the transport.
struct ActorNodeConfig {
  int actor_id = 0;
  int vehicle_id = 0;  ///< its vehicle in auv_sim
  /// The vehicle it expects (its file's facts); the simulator's every reset reply must name it.
  /// task's thruster count, maximum thrust and control step are taken from it.
  VehicleFacts vehicle;
  task::TaskConfig task;
  ExplorationNoise::Kind noise = ExplorationNoise::Kind::kOrnsteinUhlenbeck;
  double noise_sigma = 0.2;     ///< OU or Gaussian standard deviation (actions in [-1, 1])
  double noise_theta = 0.15;    ///< OU mean reversion per step
  std::uint64_t seed = 1;       ///< way-points and noise; each actor needs its own
  double initial_beta_m = 1.5;  ///< goal radius until the learner's first weights say otherwise
  int max_transitions_per_message = 256;  ///< keeps an experience message near one datagram
  double weights_request_period_s = 0.5;  ///< while it has no policy, ask this often
  double weights_silence_s = 10.0;        ///< with a policy: ask again after this long unheard
  std::int64_t max_episodes = 0;          ///< stop after this many (0: until told to stop)
  /// Flow control: before an episode, wait while the learner owes more updates than this
  /// (0: never wait). Keeps the update-to-data ratio when actors outrun the learner.
  double max_learner_backlog = 0.0;
  double max_wait_s = 5.0;  ///< ...but never longer than this (a learner that went away)
  /// Lockstep: a step unanswered within timeout_ms is sent again (the simulator answers a
  /// repeated command with the state it already computed), up to attempts times; then the
  /// episode ends (END_SIM_TIMEOUT). Each lost datagram costs one timeout_ms.
  LockstepTiming lockstep;
  /// Demonstrations: this share of episodes is driven by `demonstrator` (with the same
  /// exploration noise) instead of the policy. Their experience goes to the learner like any
  /// other; they are not reported as episodes (success rates and the goal schedule are the
  /// policy's). A policy that learns only from its own episodes found one way to every
  /// way-point, turning round and reversing; the baseline's episodes show it another.
  double demonstration_fraction = 0.0;
  std::shared_ptr<Controller> demonstrator;  ///< required when demonstration_fraction > 0
  /// Expert labels (actor.expert_labels): every transition sent carries what `expert` (its own
  /// instance, e.g. the PID baseline) would have commanded in that state, for the learner's
  /// Q-filtered imitation term. The expert never drives. The run file's flag says whether auv_actor
  /// builds one.
  bool expert_labels = false;
  std::shared_ptr<Controller> expert;  ///< required when expert_labels

  /// Reproducible mode (common/round_schedule.hpp): one episode per round, numbered by the
  /// learner; every random draw of round r comes from (seed, r); at step j of round r the actor
  /// acts with the learner's weights of round r - 1 at the index the schedule fixes, waiting for
  /// them if need be. A restarted actor, or one whose learner went back to a checkpoint, takes
  /// up the round the learner awaits and computes it again, the same.
  bool reproducible = false;
  int round_weights_every_steps = 100;  ///< RoundSchedule::weights_every_steps
  /// Reproducible mode: a round sent and not taken after this long is sent again, s.
  double round_resend_s = 1.0;
  /// Reproducible mode: weights waited for this long are asked for again, s.
  double round_request_s = 0.2;
};

/// The keys of an `actor:` section (agent/actor_config.cpp).
const config::Table<ActorNodeConfig>& actor_table();

/// Counters for logs and tests.
struct ActorCounters {
  std::int64_t episodes = 0;
  std::int64_t demonstrations = 0;  ///< of the episodes, those the demonstrator drove
  std::int64_t steps = 0;
  std::int64_t transitions_sent = 0;
  std::int64_t batches_sent = 0;
  std::int64_t episodes_discarded = 0;  ///< blow-up or simulator timeout: nothing sent
  std::int64_t weights_applied = 0;
  std::int64_t weights_rejected = 0;  ///< checksum, format or size mismatch
  std::int64_t weights_requests = 0;
  double waited_s = 0.0;              ///< time spent waiting for the learner (flow control)
  std::int64_t rounds_sent = 0;       ///< reproducible mode
  std::int64_t rounds_abandoned = 0;  ///< reproducible mode: the learner had moved elsewhere
  std::int64_t rounds_resent = 0;     ///< reproducible mode: sent again, not taken in time
  double round_start_wait_s = 0.0;    ///< reproducible mode: waiting for a round to start
  double round_step_wait_s = 0.0;     ///< reproducible mode: waiting for weights mid-round
};

/// The actor as a transport participant. Single-threaded.
class ActorNode {
 public:
  /// Weights, experience and reports on `transport`; the vehicle in lockstep on
  /// `lockstep_transport` (the same one, or a bus of its own shared only with its simulator).
  ActorNode(ActorNodeConfig config, transport::Transport& transport, std::ostream& log,
            transport::Transport* lockstep_transport = nullptr);
  ~ActorNode();
  ActorNode(const ActorNode&) = delete;
  ActorNode& operator=(const ActorNode&) = delete;

  /// Runs one episode and reports it (a demonstration is not reported); returns its summary.
  /// In the reproducible mode: the round the learner awaits (one episode); it returns an empty
  /// summary (length 0) when training ended while it waited.
  EpisodeSummary run_one_episode();
  /// Reproducible mode: the round being acted in or waited for (-100 before the learner is
  /// heard).
  std::int64_t round() const { return round_; }
  /// Whether the last episode run was a demonstration.
  bool last_was_demonstration() const { return last_was_demonstration_; }
  /// What the last episode's randomisation drew (task.randomise).
  const task::EpisodeConditions& last_conditions() const { return last_conditions_; }

  /// The learner said training is over.
  bool training_done() const { return policy_.training_done() || learner_done_; }
  std::int64_t policy_version() const { return policy_.version(); }
  double beta_m() const { return policy_.beta_m(); }
  const ActorCounters& counters() const { return counters_; }

 private:
  class ExploringController;

  /// Applies the newest weights that have arrived (drained, newest kept); asks when due.
  void refresh_policy();
  /// WEIGHTS_REQUEST for round want_round's index want_index (-1: the newest weights).
  void send_weights_request(std::int64_t want_round, std::int32_t want_index);
  /// Draws the episode's way-point, start and conditions, runs it (transitions kept) and counts
  /// it; goal receives the way-point.
  EpisodeSummary play_episode(std::vector<Transition>& transitions, Eigen::Vector3d& goal);
  /// Blow-up or simulator timeout: nothing of the episode goes to the learner.
  static bool discarded(const EpisodeSummary& summary);
  /// The experience messages of an episode (at most max_transitions_per_message each).
  std::vector<auvrl_lcm::experience_batch_t> experience_messages(
      const std::vector<Transition>& transitions, const Eigen::Vector3d& goal);
  void send_report(const EpisodeSummary& summary, const Eigen::Vector3d& goal);

  ActorNodeConfig config_;
  transport::Transport& transport_;
  std::ostream& log_;
  std::unique_ptr<VehicleLink> link_;
  /// The newest weights (asynchronous mode; the reproducible one queues them all).
  std::unique_ptr<transport::Latest<auvrl_lcm::policy_weights_t>> weights_;
  std::unique_ptr<ExploringController> controller_;
  ExplorationNoise noise_;
  std::mt19937_64 goal_rng_;
  std::mt19937_64 start_rng_;  ///< its own stream: exploring starts leave the goals unchanged
  /// Its own stream too: randomised episodes (task.randomise) leave goals and starts unchanged.
  std::mt19937_64 conditions_rng_;
  std::mt19937_64 demonstration_rng_;
  bool last_was_demonstration_ = false;
  task::EpisodeConditions last_conditions_;
  ActorCounters counters_;
  /// Waits (flow control) while the learner's backlog is above the configured limit.
  void wait_for_learner();

  // Reproducible mode (agent/actor_rounds.cpp).
  /// Thrown out of an episode when the learner no longer awaits its round.
  struct RoundAbandoned {};
  static constexpr std::int64_t kNoRound = -100;
  /// Runs rounds until one is sent (or training ends while waiting).
  EpisodeSummary run_round();
  /// Draws every random stream of round (episode) r from the seed and r.
  void seed_round(std::int64_t round);
  /// Takes in the weights that arrived; follows the learner to the round it awaits.
  void pump_weights();
  void on_round_weights(const auvrl_lcm::policy_weights_t& msg);
  /// Waits until round_ can start (the weights of round_ - 1, index 0, are held); false when
  /// training ended first.
  bool await_round_start();
  /// Puts in place the weights for step `step` of the round, waiting for them if need be.
  /// Throws RoundAbandoned when the learner moved on or went back.
  void use_round_weights(std::int64_t step);
  void request_round_weights(std::int64_t round, std::int32_t index);

  std::int64_t round_ = kNoRound;
  bool round_abandoned_ = false;
  bool learner_done_ = false;
  std::int64_t learner_round_ = kNoRound;  ///< the round of the newest weights heard
  std::map<std::int32_t, auvrl_lcm::policy_weights_t> round_weights_;  ///< of round_ - 1
  std::int32_t applied_index_ = -1;  ///< index of round_ - 1 in place (-1: none)
  std::int64_t sent_round_ = kNoRound;
  std::vector<auvrl_lcm::experience_batch_t> sent_;  ///< kept until the learner takes it
  std::chrono::steady_clock::time_point round_progress_;
  std::chrono::steady_clock::time_point waiting_since_;  ///< for weights mid-round
  std::deque<auvrl_lcm::policy_weights_t> weights_queue_;
  transport::SubscriptionId weights_subscription_ = -1;

  /// The policy, its version (-1: none yet, noise alone), beta and the learner's backlog.
  PolicyReceiver policy_;
  std::int64_t batch_seq_ = 0;
  std::int64_t episode_id_ = 0;
  std::chrono::steady_clock::time_point last_weights_;
  std::chrono::steady_clock::time_point last_request_;
};

}  // namespace auvrl::agent
