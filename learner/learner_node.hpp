// auv_learner's logic: owns the replay buffer and the networks, turns actors' experience into
// DDPG/TD3 updates at a set ratio, broadcasts the actor's weights, owns the training schedule
// (episodes, beta), publishes its figures and checkpoints everything.
#pragma once

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/weights_request_t.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "common/round_schedule.hpp"
#include "common/task/goal_schedule.hpp"
#include "common/task/task.hpp"
#include "common/transport.hpp"
#include "learner/ddpg.hpp"
#include "learner/hindsight.hpp"
#include "learner/replay_buffer.hpp"
#include "learner/rounds.hpp"
#include "learner/weight_average.hpp"

namespace auvrl::learner {

/// Everything auv_learner is configured with besides the transport.
struct LearnerNodeConfig {
  DdpgConfig ddpg;  ///< algorithm, dims, networks, rates (replay_capacity sizes the buffer)

  /// Gradient updates per transition received (the paper: one per environment step).
  double updates_per_transition = 1.0;
  /// Updates start once the buffer holds more than max(batch_size, this) transitions
  /// (Algorithm 1, line 11: |R| > m).
  std::int64_t warmup_transitions = 0;
  /// Most updates owed at once: when actors produce faster than the learner updates, the
  /// surplus is forgotten rather than owed forever (counted in updates_skipped()).
  double max_update_backlog = 1000.0;
  /// Most updates between two looks at the network, so requests are answered promptly.
  int max_updates_per_poll = 16;

  /// Weights go out after every this many updates...
  int broadcast_every_updates = 1;
  /// ...but at most once per this interval (0: no limit), s.
  double broadcast_min_interval_s = 0.05;

  int max_actors = 64;  ///< accepted actor ids: 0 .. max_actors - 1
  int max_transitions_per_batch = 10000;
  double stats_period_s = 1.0;

  task::GoalSchedule schedule;  ///< beta from the episode count
  /// Hindsight relabelling ("future" strategy) of sampled minibatches with the task's reward;
  /// needs `task` to be the actors' task configuration.
  bool her = false;
  int her_k = 4;  ///< future goals per real one
  /// The vehicle (its file's facts, applied to task): named in the messages about experience
  /// or checkpoints of other sizes.
  VehicleFacts vehicle;
  task::TaskConfig task;
  std::int64_t max_episodes = 0;  ///< training ends after this many episodes (0: never)
  std::int64_t max_updates = 0;   ///< or after this many updates (0: never)

  std::string checkpoint_dir;          ///< empty: no checkpoints
  double checkpoint_period_s = 300.0;  ///< asynchronous mode
  /// Reproducible mode: a checkpoint after every this many updates (0: none but the last).
  std::int64_t checkpoint_every_updates = 100000;
  int keep_checkpoints = 2;
  std::string policy_path;  ///< where finish() writes the actor network (optional)

  /// Reproducible mode (common/round_schedule.hpp): experience in rounds from exactly
  /// max_actors actors, taken in actor order; weights published by round and index; every
  /// period counted in updates. The same seed then gives the same bytes.
  bool reproducible = false;
  int round_weights_every_steps = 100;  ///< RoundSchedule::weights_every_steps
  /// Reproducible mode: the actor network is written to snapshot_dir/policy-<updates>.nn
  /// every snapshot_every_updates updates (the launcher's choice of the best policy).
  std::string snapshot_dir;
  std::int64_t snapshot_every_updates = 0;

  /// The uniform mean of the actor over its last average_window_updates updates (a copy every
  /// average_every_updates; learner/weight_average.hpp), written by finish() to
  /// average_policy_path. Window 0 or no path: none.
  std::int64_t average_every_updates = 5000;
  std::int64_t average_window_updates = 0;
  std::string average_policy_path;
};

/// The keys of a `learner:` section: ddpg_table() and the node's own (learner_config.cpp).
const config::Table<LearnerNodeConfig>& learner_table();

/// Counters of what arrived and what was done with it.
struct LearnerCounters {
  std::int64_t transitions_received = 0;
  std::int64_t batches_received = 0;
  std::int64_t dropped_dims = 0;
  std::int64_t dropped_non_finite = 0;
  std::int64_t dropped_unknown_actor = 0;
  std::int64_t batches_lost = 0;
  std::int64_t weights_published = 0;
  std::int64_t weights_requests = 0;
  std::int64_t episodes = 0;
  std::int64_t checkpoints_written = 0;
  std::int64_t updates_skipped = 0;
  std::int64_t dropped_decode = 0;
  std::int64_t rounds = 0;             ///< reproducible mode: rounds taken
  std::int64_t round_duplicates = 0;   ///< reproducible mode: resent batches already held
  std::int64_t round_out_of_turn = 0;  ///< reproducible mode: batches of another round
};

/// The learner as a transport participant. Single-threaded: call poll() in a loop.
class LearnerNode {
 public:
  LearnerNode(LearnerNodeConfig config, transport::Transport& transport, std::ostream& log);
  ~LearnerNode();
  LearnerNode(const LearnerNode&) = delete;
  LearnerNode& operator=(const LearnerNode&) = delete;

  /// Handles what has arrived (waiting up to timeout_ms when there is nothing to update),
  /// runs the updates owed, and publishes weights, statistics and checkpoints when due.
  void poll(int timeout_ms);

  /// True once the schedule's end (max_episodes or max_updates) is reached.
  bool training_done() const;

  /// Writes a checkpoint now (if a directory is configured); returns its path or "".
  std::string checkpoint();
  /// Restores the newest usable checkpoint of the configured directory. Throws
  /// std::runtime_error (naming the file and what is wrong) if there is none.
  void resume();
  /// Final checkpoint, policy file and a last broadcast of the weights.
  void finish();

  std::int64_t updates() const { return ddpg_->updates(); }
  std::int64_t episodes() const { return counters_.episodes; }
  double beta_m() const { return config_.schedule.beta_m(counters_.episodes); }
  const ReplayBuffer& replay() const { return *replay_; }
  const Ddpg& algorithm() const { return *ddpg_; }
  /// The actor's recent weights, whose mean finish() writes to average_policy_path.
  const WeightAverage& weight_average() const { return average_; }
  LearnerCounters counters() const;

  /// The policy_weights_t for the current actor network.
  auvrl_lcm::policy_weights_t weights_message() const;

 private:
  /// Sets unrecoverable_ when a sound batch has other sizes than the networks.
  void note_other_sizes(const auvrl_lcm::experience_batch_t& msg);
  /// Checks a batch's sizes and values (counting what it drops); true when it may be used.
  bool sound_batch(const auvrl_lcm::experience_batch_t& msg);
  /// Stores the batch's transitions; returns the updates they earn.
  double add_transitions(const auvrl_lcm::experience_batch_t& msg);
  void on_experience(const auvrl_lcm::experience_batch_t& msg);
  void on_weights_request(const auvrl_lcm::weights_request_t& msg);
  void on_episode(const auvrl_lcm::episode_report_t& msg);
  void run_updates();
  /// After each update: checkpoints and snapshots due by update count.
  void after_update();

  // Reproducible mode (learner/rounds.hpp).
  /// Takes the awaited round once complete: its transitions in actor order, the updates owed.
  void take_round_if_complete();
  /// Runs the current round's updates, publishing each index as it falls due.
  void run_round_updates();
  /// Publishes index `index` of the current round (final when the round's updates are done).
  void publish_round_weights(bool final);
  void answer_round_request(const auvrl_lcm::weights_request_t& msg);
  /// Adds the next index of the current round's weights to the history and returns it.
  const RoundWeights& record_round_weights(bool final);
  /// Publishes weights (and their summary) and counts them.
  void publish_weights_message(const auvrl_lcm::policy_weights_t& weights);
  void write_snapshot();
  void update_once();
  /// The reproducible mode's round as a checkpoint holds it.
  struct RoundState {
    std::int64_t owed = 0;
    std::int64_t done = 0;
    std::int32_t next_index = 0;
    std::int64_t rounds = 0;
    RoundWeightsHistory weights;
  };
  static RoundState read_round_state(nn::Reader& r);
  void restore_round_state(RoundState state);
  /// Publishes the weights if requested, or if due by update count and allowed by the rate.
  void maybe_publish_weights();
  void publish_weights();
  void publish_stats();
  void save(nn::Writer& w) const;
  /// Writes the mean of the actor's recent weights to average_policy_path (when configured).
  void write_average_policy();

  LearnerNodeConfig config_;
  transport::Transport& transport_;
  std::ostream& log_;
  std::unique_ptr<Ddpg> ddpg_;
  std::unique_ptr<ReplayBuffer> replay_;
  std::unique_ptr<HindsightRelabeler> her_;
  WeightAverage average_;
  nn::Rng sample_rng_;  ///< minibatches when relabelling (otherwise the algorithm samples)
  Batch batch_;
  LearnerCounters counters_;
  /// Experience of other dimensions (set in the transport's callback, thrown by poll()).
  std::string unrecoverable_;
  transport::DecodeStats decode_stats_;
  std::vector<transport::SubscriptionId> subscriptions_;
  std::vector<std::int64_t> last_batch_seq_;  ///< per actor, -1: none yet

  double update_credit_ = 0.0;

  // Reproducible mode.
  RoundSchedule round_schedule_;
  std::unique_ptr<RoundCollector> collector_;
  RoundWeightsHistory round_weights_;  ///< round_weights_.round(): the last round taken
  std::int64_t round_updates_owed_ = 0;
  std::int64_t round_updates_done_ = 0;
  std::int32_t round_next_index_ = 0;
  std::int64_t last_broadcast_updates_ = -1;
  bool broadcast_requested_ = true;  ///< answer a request (or announce a start) at once
  std::chrono::steady_clock::time_point last_broadcast_;
  std::chrono::steady_clock::time_point next_stats_;
  std::chrono::steady_clock::time_point next_checkpoint_;

  // Statistics over the current stats interval.
  std::int64_t interval_updates_ = 0;
  std::int64_t interval_transitions_ = 0;
  double interval_critic_loss_ = 0.0;
  double interval_actor_loss_ = 0.0;
  double interval_mean_q_ = 0.0;
  double interval_expert_share_ = 0.0;     ///< summed over the interval's actor steps
  double interval_smooth_temporal_ = 0.0;  ///< summed over the interval's actor steps
  double interval_smooth_spatial_ = 0.0;   ///< summed over the interval's actor steps
  std::int64_t interval_actor_updates_ = 0;
  std::chrono::steady_clock::time_point interval_start_;
};

}  // namespace auvrl::learner
