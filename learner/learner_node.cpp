#include "learner/learner_node.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <auvrl_lcm/policy_summary_t.hpp>
#include <cmath>
#include <filesystem>
#include <optional>

#include "common/channels.hpp"
#include "common/nn/serialize.hpp"
#include "common/unrecoverable.hpp"
#include "learner/checkpoint.hpp"

namespace auvrl::learner {

namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

bool all_finite(const std::vector<std::vector<float>>& rows) {
  for (const auto& row : rows) {
    for (float v : row) {
      if (!std::isfinite(v)) return false;
    }
  }
  return true;
}

/// Record of the learner's own state in a checkpoint (the algorithm and the buffer follow it).
constexpr const char* kCheckpointMagic = "AUVRLCK";
constexpr std::uint32_t kCheckpointVersion = 3;

}  // namespace

LearnerNode::LearnerNode(LearnerNodeConfig config, transport::Transport& transport,
                         std::ostream& log)
    : config_(std::move(config)),
      transport_(transport),
      log_(log),
      average_(config_.average_every_updates, config_.average_window_updates),
      sample_rng_(config_.ddpg.seed ^ 0x5851F42D4C957F2Dull),
      batch_(config_.ddpg.state_dim, config_.ddpg.action_dim,
             std::max(1, config_.ddpg.batch_size)) {
  config_.ddpg.validate();
  if (config_.updates_per_transition < 0 || !std::isfinite(config_.updates_per_transition)) {
    throw std::invalid_argument("updates_per_transition must be finite and >= 0");
  }
  if (config_.max_actors < 1) throw std::invalid_argument("max_actors must be >= 1");
  if (config_.broadcast_every_updates < 1) {
    throw std::invalid_argument("broadcast_every_updates must be >= 1");
  }
  ddpg_ = std::make_unique<Ddpg>(config_.ddpg);
  replay_ = std::make_unique<ReplayBuffer>(config_.ddpg.state_dim, config_.ddpg.action_dim,
                                           config_.ddpg.replay_capacity);
  if (config_.her) {
    if (config_.task.state_dim() != config_.ddpg.state_dim ||
        config_.task.num_thrusters != config_.ddpg.action_dim) {
      throw std::invalid_argument(
          "her: the task's state/action sizes (" + std::to_string(config_.task.state_dim()) + ", " +
          std::to_string(config_.task.num_thrusters) + ") differ from the learner's");
    }
    her_ = std::make_unique<HindsightRelabeler>(config_.task, config_.her_k);
  }
  last_batch_seq_.assign(static_cast<std::size_t>(config_.max_actors), -1);
  if (config_.reproducible) {
    round_schedule_ = {config_.round_weights_every_steps, config_.max_actors,
                       config_.updates_per_transition};
    round_schedule_.validate();
    if (config_.snapshot_every_updates < 0 || config_.checkpoint_every_updates < 0) {
      throw std::invalid_argument(
          "snapshot_every_updates and checkpoint_every_updates must be >= 0");
    }
    // An episode's transitions come one or more to a batch.
    collector_ = std::make_unique<RoundCollector>(config_.max_actors, config_.task.max_steps);
    // Round 0 has no experience: its only weights are the initial networks'.
    round_weights_.begin(0);
    round_updates_owed_ = round_updates_done_ = 0;
    record_round_weights(true);  // published at the first poll (broadcast_requested_)
  }

  using transport::subscribe;
  subscriptions_.push_back(subscribe<auvrl_lcm::experience_batch_t>(
      transport_, channels::kExperience,
      [this](const std::string&, const auvrl_lcm::experience_batch_t& m) { on_experience(m); },
      &decode_stats_, 10000));
  subscriptions_.push_back(subscribe<auvrl_lcm::weights_request_t>(
      transport_, channels::kWeightsRequest,
      [this](const std::string&, const auvrl_lcm::weights_request_t& m) { on_weights_request(m); },
      &decode_stats_));
  subscriptions_.push_back(subscribe<auvrl_lcm::episode_report_t>(
      transport_, channels::kEpisode,
      [this](const std::string&, const auvrl_lcm::episode_report_t& m) { on_episode(m); },
      &decode_stats_, 10000));

  const auto now = Clock::now();
  last_broadcast_ = now - seconds(3600);
  next_stats_ = now + seconds(config_.stats_period_s);
  next_checkpoint_ = now + seconds(config_.checkpoint_period_s);
  interval_start_ = now;
}

LearnerNode::~LearnerNode() {
  for (auto id : subscriptions_) transport_.unsubscribe(id);
}

LearnerCounters LearnerNode::counters() const {
  LearnerCounters c = counters_;
  c.dropped_decode = decode_stats_.failed;
  return c;
}

bool LearnerNode::training_done() const {
  return (config_.max_episodes > 0 && counters_.episodes >= config_.max_episodes) ||
         (config_.max_updates > 0 && ddpg_->updates() >= config_.max_updates);
}

void LearnerNode::note_other_sizes(const auvrl_lcm::experience_batch_t& msg) {
  // Sound experience of other sizes (the wire format sizes every row by state_dim and
  // action_dim) comes from an actor of another vehicle or layout: no restart mends that.
  // poll() stops the learner with this message; the batch is counted as dropped.
  if (msg.state_dim < 1 || msg.action_dim < 1 || !unrecoverable_.empty()) return;
  if (msg.state_dim == config_.ddpg.state_dim && msg.action_dim == config_.ddpg.action_dim) return;
  unrecoverable_ = fmt::format(
      "experience from actor {} has state {} and action {} values; this learner's networks "
      "take state {} and action {} (vehicle {}, {} layout): the actor serves another vehicle "
      "or layout",
      msg.actor_id, msg.state_dim, msg.action_dim, config_.ddpg.state_dim, config_.ddpg.action_dim,
      describe(config_.vehicle), task::to_string(config_.task.layout));
}

bool LearnerNode::sound_batch(const auvrl_lcm::experience_batch_t& msg) {
  const int n = msg.num_transitions;
  // A round's only batch may be empty (its episodes gave no experience).
  const bool empty_ok = config_.reproducible && n == 0 && msg.round_batches == 1;
  const auto rows_ok = [n](const auto& rows, int cols) {
    return static_cast<int>(rows.size()) == n &&
           std::all_of(rows.begin(), rows.end(),
                       [cols](const auto& r) { return static_cast<int>(r.size()) == cols; });
  };
  if (n >= 1 && n <= config_.max_transitions_per_batch) note_other_sizes(msg);
  if (msg.state_dim != config_.ddpg.state_dim || msg.action_dim != config_.ddpg.action_dim ||
      (n < 1 && !empty_ok) || n > config_.max_transitions_per_batch ||
      !rows_ok(msg.states, msg.state_dim) || !rows_ok(msg.next_states, msg.state_dim) ||
      !rows_ok(msg.actions, msg.action_dim) || !rows_ok(msg.achieved_position_ned_m, 3) ||
      !rows_ok(msg.goal_ned_m, 3) ||
      (msg.expert_rows != 0 && !rows_ok(msg.expert_actions, msg.action_dim))) {
    ++counters_.dropped_dims;
    return false;
  }
  const bool finite =
      all_finite(msg.states) && all_finite(msg.next_states) && all_finite(msg.actions) &&
      all_finite(msg.achieved_position_ned_m) && all_finite(msg.goal_ned_m) &&
      all_finite(msg.expert_actions) &&
      std::all_of(msg.rewards.begin(), msg.rewards.end(), [](float r) { return std::isfinite(r); });
  // Actions come out of tanh: anything beyond [-1, 1] did not come from a policy.
  const auto in_range = [](const std::vector<std::vector<float>>& rows) {
    return std::all_of(rows.begin(), rows.end(), [](auto& a) {
      return std::all_of(a.begin(), a.end(), [](float v) { return std::abs(v) <= 1.0f + 1e-6f; });
    });
  };
  if (!finite || !in_range(msg.actions) || !in_range(msg.expert_actions)) {
    ++counters_.dropped_non_finite;
    return false;
  }
  return true;
}

double LearnerNode::add_transitions(const auvrl_lcm::experience_batch_t& msg) {
  // Algorithm 1, line 11: a step trains only once |R| > m, so only transitions stored beyond
  // that threshold earn updates.
  const auto threshold = static_cast<std::size_t>(
      std::max<std::int64_t>(config_.ddpg.batch_size, config_.warmup_transitions));
  double credit = 0.0;
  using Vec = Eigen::Map<const nn::Vector>;
  for (int i = 0; i < msg.num_transitions; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const auto& pos = msg.achieved_position_ned_m[k];
    const auto& goal = msg.goal_ned_m[k];
    const TransitionView t{
        Vec(msg.states[k].data(), msg.state_dim), Vec(msg.actions[k].data(), msg.action_dim),
        msg.rewards[k], Vec(msg.next_states[k].data(), msg.state_dim), msg.terminal[k] != 0,
        Eigen::Vector3f(pos[0], pos[1], pos[2]), Eigen::Vector3f(goal[0], goal[1], goal[2]),
        // Episode ids are per actor: the actor id in the top bits makes them global.
        (static_cast<std::uint64_t>(msg.actor_id) << 40) |
            (static_cast<std::uint64_t>(msg.episode_id[k]) & ((std::uint64_t{1} << 40) - 1)),
        static_cast<std::uint32_t>(msg.step_index[k]),
        msg.expert_rows != 0 ? msg.expert_actions[k].data() : nullptr};
    const std::size_t slot = replay_->next_slot();
    const bool overwrote = replay_->size() == replay_->capacity();
    const std::uint64_t overwritten_episode = overwrote ? replay_->episode_id(slot) : 0;
    replay_->add(t);
    if (her_) her_->on_add(*replay_, slot, overwrote, overwritten_episode);
    if (replay_->size() > threshold) credit += config_.updates_per_transition;
  }
  counters_.transitions_received += msg.num_transitions;
  interval_transitions_ += msg.num_transitions;
  return credit;
}

void LearnerNode::on_experience(const auvrl_lcm::experience_batch_t& msg) {
  ++counters_.batches_received;
  if (msg.actor_id < 0 || msg.actor_id >= config_.max_actors) {
    ++counters_.dropped_unknown_actor;
    return;
  }
  if ((msg.round >= 1) != config_.reproducible && unrecoverable_.empty()) {
    // No restart mends a mix of modes: the launcher starts every process in the same one.
    unrecoverable_ =
        fmt::format("actor {} sends {} experience but this learner runs in the {} mode",
                    msg.actor_id, msg.round >= 1 ? "reproducible (rounds of)" : "asynchronous",
                    config_.reproducible ? "reproducible" : "asynchronous");
    return;
  }
  if (!sound_batch(msg)) return;
  if (config_.reproducible) {
    switch (collector_->offer(msg, round_weights_.round() + 1)) {
      case RoundCollector::Offer::kStored:
        break;
      case RoundCollector::Offer::kDuplicate:
        ++counters_.round_duplicates;
        break;
      case RoundCollector::Offer::kOtherRound:
        ++counters_.round_out_of_turn;
        break;
      case RoundCollector::Offer::kMalformed:
        ++counters_.dropped_dims;
        break;
    }
    return;
  }
  std::int64_t& last = last_batch_seq_[static_cast<std::size_t>(msg.actor_id)];
  if (last >= 0 && msg.batch_seq > last + 1) counters_.batches_lost += msg.batch_seq - last - 1;
  last = msg.batch_seq;  // a lower number means the actor restarted: follow it
  const double owed = update_credit_ + add_transitions(msg);
  update_credit_ = std::min(owed, config_.max_update_backlog);
  counters_.updates_skipped += static_cast<std::int64_t>(owed - update_credit_);
}

void LearnerNode::on_weights_request(const auvrl_lcm::weights_request_t& msg) {
  ++counters_.weights_requests;
  if (config_.reproducible) {
    answer_round_request(msg);
  } else {
    broadcast_requested_ = true;
  }
}

void LearnerNode::on_episode(const auvrl_lcm::episode_report_t& msg) {
  if (msg.actor_id < 0 || msg.actor_id >= config_.max_actors) {
    ++counters_.dropped_unknown_actor;
    return;
  }
  // The reproducible mode counts a round's episodes when it takes the round.
  if (!config_.reproducible) ++counters_.episodes;
}

void LearnerNode::update_once() {
  UpdateStats stats;
  if (her_) {
    replay_->sample(sample_rng_, config_.ddpg.batch_size, batch_);
    her_->relabel(*replay_, beta_m(), sample_rng_, batch_);
    stats = ddpg_->update(batch_);
  } else {
    stats = ddpg_->update(*replay_);
  }
  average_.observe(ddpg_->updates(), ddpg_->actor());
  ++interval_updates_;
  interval_critic_loss_ += stats.critic_loss;
  interval_actor_loss_ += stats.actor_loss;
  interval_mean_q_ += stats.mean_q;
  if (stats.actor_updated) {
    interval_expert_share_ += stats.expert_share;
    interval_smooth_temporal_ += stats.smooth_temporal;
    interval_smooth_spatial_ += stats.smooth_spatial;
    ++interval_actor_updates_;
  }
}

void LearnerNode::run_updates() {
  if (config_.reproducible) {
    run_round_updates();
    return;
  }
  const auto threshold = static_cast<std::size_t>(
      std::max<std::int64_t>(config_.ddpg.batch_size, config_.warmup_transitions));
  int done = 0;
  while (update_credit_ >= 1.0 && replay_->size() > threshold &&
         done < config_.max_updates_per_poll && !training_done()) {
    update_once();
    update_credit_ -= 1.0;
    ++done;
    maybe_publish_weights();
  }
}

void LearnerNode::after_update() {
  const std::int64_t updates = ddpg_->updates();
  if (config_.checkpoint_every_updates > 0 && updates % config_.checkpoint_every_updates == 0) {
    checkpoint();
  }
  if (config_.snapshot_every_updates > 0 && !config_.snapshot_dir.empty() &&
      updates % config_.snapshot_every_updates == 0) {
    write_snapshot();
  }
}

void LearnerNode::write_snapshot() {
  const std::string path = snapshot_path(config_.snapshot_dir, ddpg_->updates());
  try {
    std::filesystem::create_directories(config_.snapshot_dir);
    nn::save_network_file(path, ddpg_->actor());
  } catch (const std::exception& e) {
    // Training goes on; the launcher's choice of the best policy misses this one.
    log_ << "auv_learner: SNAPSHOT FAILED: " << e.what() << "\n";
  }
}

void LearnerNode::take_round_if_complete() {
  if (round_updates_done_ < round_updates_owed_ || !collector_->complete()) return;
  const std::int64_t round = round_weights_.round() + 1;
  double credit = 0.0;
  for (const auvrl_lcm::experience_batch_t& batch : collector_->take()) {
    if (batch.round_batch == 0) counters_.episodes += batch.round_episodes;
    credit += add_transitions(batch);
  }
  update_credit_ += credit;
  round_updates_owed_ = static_cast<std::int64_t>(std::floor(update_credit_));
  update_credit_ -= static_cast<double>(round_updates_owed_);
  round_updates_done_ = 0;
  round_weights_.begin(round);
  round_next_index_ = 0;
  ++counters_.rounds;
  publish_round_weights(round_updates_owed_ == 0);
}

void LearnerNode::run_round_updates() {
  int done = 0;
  while (round_updates_done_ < round_updates_owed_ && done < config_.max_updates_per_poll &&
         !training_done()) {
    update_once();
    ++round_updates_done_;
    ++done;
    if (round_updates_done_ == round_updates_owed_) {
      publish_round_weights(true);
    } else {
      while (round_schedule_.updates_for_index(round_next_index_) <= round_updates_done_) {
        publish_round_weights(false);
      }
    }
    after_update();
  }
}

const RoundWeights& LearnerNode::record_round_weights(bool final) {
  RoundWeights w;
  w.index = round_next_index_++;
  w.final = final;
  w.version = ddpg_->updates();
  w.beta_m = beta_m();
  w.episodes = counters_.episodes;
  w.network = nn::network_to_bytes(ddpg_->actor());
  round_weights_.add(std::move(w));
  return *round_weights_.newest();
}

void LearnerNode::publish_round_weights(bool final) {
  publish_weights_message(
      round_weights_message(record_round_weights(final), round_weights_.round(), training_done()));
}

void LearnerNode::answer_round_request(const auvrl_lcm::weights_request_t& msg) {
  const RoundWeights* newest = round_weights_.newest();
  const RoundWeights* answer = nullptr;
  if (msg.want_round < round_weights_.round()) {
    answer = newest;  // -1 (the newest), or a round already passed: the actor moves on
  } else if (msg.want_round == round_weights_.round()) {
    answer = round_weights_.find(msg.want_index);
    if (!answer && newest && newest->final && newest->index < msg.want_index) answer = newest;
  }
  // Otherwise not yet published: it goes out when due.
  if (answer) {
    publish_weights_message(
        round_weights_message(*answer, round_weights_.round(), training_done()));
  }
}

void LearnerNode::maybe_publish_weights() {
  if (config_.reproducible) {
    // At the start and after a resume: every weights of the round, for actors that went back.
    if (broadcast_requested_) {
      for (const RoundWeights& w : round_weights_.all()) {
        publish_weights_message(round_weights_message(w, round_weights_.round(), training_done()));
      }
      broadcast_requested_ = false;
    }
    return;
  }
  const std::int64_t updates = ddpg_->updates();
  const bool due_by_count = updates - last_broadcast_updates_ >= config_.broadcast_every_updates;
  const bool rate_ok = Clock::now() - last_broadcast_ >= seconds(config_.broadcast_min_interval_s);
  if (broadcast_requested_ || (due_by_count && rate_ok)) publish_weights();
}

auvrl_lcm::policy_weights_t LearnerNode::weights_message() const {
  auvrl_lcm::policy_weights_t msg;
  msg.utime = transport::now_utime();
  msg.version = ddpg_->updates();
  msg.beta_m = beta_m();
  msg.episodes = counters_.episodes;
  msg.training_done = training_done();
  msg.updates_owed = update_credit_;
  msg.round = -1;
  msg.round_index = 0;
  msg.round_final = false;
  const std::vector<std::uint8_t> bytes = nn::network_to_bytes(ddpg_->actor());
  msg.num_bytes = static_cast<std::int32_t>(bytes.size());
  msg.network.assign(bytes.begin(), bytes.end());
  return msg;
}

void LearnerNode::publish_weights() {
  if (config_.reproducible) {
    // The newest of the round, with the schedule's end if it has come.
    if (const RoundWeights* w = round_weights_.newest()) {
      publish_weights_message(round_weights_message(*w, round_weights_.round(), training_done()));
    }
    return;
  }
  publish_weights_message(weights_message());
}

void LearnerNode::publish_weights_message(const auvrl_lcm::policy_weights_t& weights) {
  transport::publish(transport_, channels::kPolicyWeights, weights);
  auvrl_lcm::policy_summary_t summary;
  summary.utime = weights.utime;
  summary.version = weights.version;
  summary.num_bytes = weights.num_bytes;
  std::uint32_t crc = 0;
  for (int i = 0; i < 4; ++i) {
    crc |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(
               weights.network[weights.network.size() - 4 + static_cast<std::size_t>(i)]))
           << (8 * i);
  }
  summary.crc32 = crc;
  summary.beta_m = weights.beta_m;
  summary.episodes = weights.episodes;
  summary.architecture = ddpg_->actor().spec().describe();
  transport::publish(transport_, channels::kPolicySummary, summary);
  ++counters_.weights_published;
  last_broadcast_updates_ = weights.version;
  last_broadcast_ = Clock::now();
  broadcast_requested_ = false;
}

void LearnerNode::publish_stats() {
  const auto now = Clock::now();
  const double dt = std::max(1e-9, std::chrono::duration<double>(now - interval_start_).count());
  auvrl_lcm::learner_stats_t s;
  s.utime = transport::now_utime();
  s.pid = static_cast<std::int32_t>(getpid());
  s.algo = to_string(config_.ddpg.algo);
  s.updates = ddpg_->updates();
  s.updates_per_s = static_cast<double>(interval_updates_) / dt;
  s.transitions_received = counters_.transitions_received;
  s.transitions_per_s = static_cast<double>(interval_transitions_) / dt;
  s.buffer_size = static_cast<std::int64_t>(replay_->size());
  s.buffer_capacity = static_cast<std::int64_t>(replay_->capacity());
  const double k = interval_updates_ > 0 ? 1.0 / static_cast<double>(interval_updates_) : 0.0;
  s.critic_loss = interval_critic_loss_ * k;
  s.actor_loss = interval_actor_loss_ * k;
  s.mean_q = interval_mean_q_ * k;
  s.weights_published = counters_.weights_published;
  s.episodes = counters_.episodes;
  s.beta_m = beta_m();
  s.dropped_dims = counters_.dropped_dims;
  s.dropped_non_finite = counters_.dropped_non_finite;
  s.dropped_unknown_actor = counters_.dropped_unknown_actor;
  s.batches_dropped =
      s.dropped_dims + s.dropped_non_finite + s.dropped_unknown_actor + decode_stats_.failed;
  s.batches_lost = counters_.batches_lost;
  s.checkpoints_written = counters_.checkpoints_written;
  const double per_actor_step =
      interval_actor_updates_ > 0 ? 1.0 / static_cast<double>(interval_actor_updates_) : 0.0;
  s.expert_share = interval_expert_share_ * per_actor_step;
  s.smooth_temporal = interval_smooth_temporal_ * per_actor_step;
  s.smooth_spatial = interval_smooth_spatial_ * per_actor_step;
  transport::publish(transport_, channels::kLearnerStats, s);
  interval_updates_ = interval_transitions_ = 0;
  interval_critic_loss_ = interval_actor_loss_ = interval_mean_q_ = interval_expert_share_ = 0.0;
  interval_smooth_temporal_ = interval_smooth_spatial_ = 0.0;
  interval_actor_updates_ = 0;
  interval_start_ = now;
  next_stats_ = now + seconds(config_.stats_period_s);
}

void LearnerNode::poll(int timeout_ms) {
  // A round completed by the last poll's messages starts now, not after the wait below.
  if (config_.reproducible && !training_done()) take_round_if_complete();
  const bool owed =
      config_.reproducible ? round_updates_done_ < round_updates_owed_ : update_credit_ >= 1.0;
  const bool can_update = owed && !training_done();
  transport_.handle(can_update || broadcast_requested_ ? 0 : timeout_ms);
  if (!unrecoverable_.empty()) throw UnrecoverableFault(unrecoverable_);
  if (config_.reproducible && !training_done()) take_round_if_complete();
  run_updates();
  maybe_publish_weights();  // requests, and weights held back by the rate limit
  const auto now = Clock::now();
  if (now >= next_stats_) publish_stats();
  // The reproducible mode checkpoints by update count (after_update).
  if (!config_.reproducible && !config_.checkpoint_dir.empty() && now >= next_checkpoint_) {
    checkpoint();
  }
}

void LearnerNode::save(nn::Writer& w) const {
  w.bytes(kCheckpointMagic, 8);
  w.u32(kCheckpointVersion);
  w.u64(static_cast<std::uint64_t>(counters_.episodes));
  w.u64(static_cast<std::uint64_t>(counters_.transitions_received));
  w.f64(update_credit_);
  w.u32(static_cast<std::uint32_t>(last_batch_seq_.size()));
  for (std::int64_t seq : last_batch_seq_) w.u64(static_cast<std::uint64_t>(seq));
  nn::write_rng(w, sample_rng_);
  ddpg_->save(w);
  replay_->save(w);
  // Version 2: the reproducible mode's round (its experience is taken; its updates are done
  // up to round_updates_done_; the weights published for it so far).
  w.u8(config_.reproducible ? 1 : 0);
  if (config_.reproducible) {
    w.u64(static_cast<std::uint64_t>(round_updates_owed_));
    w.u64(static_cast<std::uint64_t>(round_updates_done_));
    w.u32(static_cast<std::uint32_t>(round_next_index_));
    w.u64(static_cast<std::uint64_t>(counters_.rounds));
    round_weights_.save(w);
  }
  average_.save(w);  // version 3
}

std::string LearnerNode::checkpoint() {
  next_checkpoint_ = Clock::now() + seconds(config_.checkpoint_period_s);
  if (config_.checkpoint_dir.empty()) return "";
  try {
    const std::string path =
        write_checkpoint(config_.checkpoint_dir, ddpg_->updates(), config_.keep_checkpoints,
                         [this](nn::Writer& w) { save(w); });
    ++counters_.checkpoints_written;
    log_ << "auv_learner: checkpoint " << path << " (" << ddpg_->updates() << " updates, "
         << replay_->size() << " transitions)\n";
    return path;
  } catch (const std::exception& e) {
    // Training goes on; the previous checkpoint is intact. Say so loudly.
    log_ << "auv_learner: CHECKPOINT FAILED, previous one kept: " << e.what() << "\n";
    return "";
  }
}

void LearnerNode::resume() {
  const CheckpointFile file = restore_latest_checkpoint(
      config_.checkpoint_dir,
      [this](nn::Reader& r) {
        // Everything is read into new objects first: a damaged file changes nothing.
        r.expect_magic(kCheckpointMagic);
        const std::uint32_t version = r.u32();
        if (version < 1 || version > kCheckpointVersion) {
          r.fail("format version " + std::to_string(version) + ", expected 1 to " +
                 std::to_string(kCheckpointVersion));
        }
        const auto episodes = static_cast<std::int64_t>(r.u64());
        const auto transitions = static_cast<std::int64_t>(r.u64());
        const double credit = r.f64();
        const std::uint32_t actors = r.u32();
        if (actors > 1000000) r.fail("implausible actor count " + std::to_string(actors));
        std::vector<std::int64_t> seqs(actors);
        for (auto& s : seqs) s = static_cast<std::int64_t>(r.u64());
        nn::Rng sample_rng;
        nn::read_rng(r, sample_rng);
        auto ddpg = std::make_unique<Ddpg>(config_.ddpg);
        ddpg->restore(r);
        auto replay = std::make_unique<ReplayBuffer>(
            config_.ddpg.state_dim, config_.ddpg.action_dim, config_.ddpg.replay_capacity);
        replay->restore(r);
        const bool reproducible = version >= 2 && r.u8() != 0;
        if (reproducible != config_.reproducible) {
          r.fail(reproducible
                     ? "a checkpoint of the reproducible mode; this learner is asynchronous"
                     : "a checkpoint of the asynchronous mode; this learner is reproducible");
        }
        RoundState round;
        if (reproducible) round = read_round_state(r);
        // Before version 3 no recent weights were kept: the mean starts afresh.
        WeightAverage average(config_.average_every_updates, config_.average_window_updates);
        if (version >= 3) average.restore(r, ddpg->actor().num_params());
        r.verify_checksum();
        ddpg_ = std::move(ddpg);
        replay_ = std::move(replay);
        counters_.episodes = episodes;
        counters_.transitions_received = transitions;
        update_credit_ =
            reproducible ? credit : std::clamp(credit, 0.0, config_.max_update_backlog);
        if (reproducible) restore_round_state(std::move(round));
        seqs.resize(static_cast<std::size_t>(config_.max_actors), -1);
        last_batch_seq_ = std::move(seqs);
        sample_rng_ = sample_rng;
        average_ = std::move(average);
        if (her_) her_->rebuild(*replay_);
      },
      log_);
  broadcast_requested_ = true;
  log_ << "auv_learner: resumed from " << file.path << " (" << ddpg_->updates() << " updates, "
       << replay_->size() << " transitions, " << counters_.episodes << " episodes)\n";
}

LearnerNode::RoundState LearnerNode::read_round_state(nn::Reader& r) {
  RoundState state;
  state.owed = static_cast<std::int64_t>(r.u64());
  state.done = static_cast<std::int64_t>(r.u64());
  state.next_index = static_cast<std::int32_t>(r.u32());
  state.rounds = static_cast<std::int64_t>(r.u64());
  state.weights.restore(r);
  if (state.owed < 0 || state.done < 0 || state.done > state.owed || state.next_index < 0 ||
      !state.weights.newest()) {
    r.fail("inconsistent round state (updates owed " + std::to_string(state.owed) + ", done " +
           std::to_string(state.done) + ")");
  }
  return state;
}

void LearnerNode::restore_round_state(RoundState state) {
  round_updates_owed_ = state.owed;
  round_updates_done_ = state.done;
  round_next_index_ = state.next_index;
  counters_.rounds = state.rounds;
  round_weights_ = std::move(state.weights);
  // Whatever was collected of the next round came before the restart: the actors send it again.
  collector_->clear();
}

void LearnerNode::finish() {
  checkpoint();
  if (!config_.policy_path.empty()) {
    try {
      nn::save_network_file(config_.policy_path, ddpg_->actor());
      log_ << "auv_learner: policy written to " << config_.policy_path << "\n";
    } catch (const std::exception& e) {
      log_ << "auv_learner: cannot write the policy: " << e.what() << "\n";
    }
  }
  write_average_policy();
  publish_weights();
  publish_stats();
}

void LearnerNode::write_average_policy() {
  if (config_.average_policy_path.empty() || !average_.enabled()) return;
  const std::optional<nn::Mlp> mean = average_.mean(ddpg_->actor());
  if (!mean) {
    log_ << "auv_learner: no weight average: training ended before update "
         << config_.average_every_updates << "\n";
    return;
  }
  try {
    nn::save_network_file(config_.average_policy_path, *mean);
    log_ << "auv_learner: mean of " << average_.copies() << " actors (updates "
         << average_.first_updates() << " to " << average_.last_updates() << ") written to "
         << config_.average_policy_path << "\n";
  } catch (const std::exception& e) {
    log_ << "auv_learner: cannot write the weight average: " << e.what() << "\n";
  }
}

}  // namespace auvrl::learner
