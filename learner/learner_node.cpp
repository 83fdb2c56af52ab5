#include "learner/learner_node.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <auvrl_lcm/policy_summary_t.hpp>
#include <cmath>

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
constexpr std::uint32_t kCheckpointVersion = 1;

}  // namespace

LearnerNode::LearnerNode(LearnerNodeConfig config, transport::Transport& transport,
                         std::ostream& log)
    : config_(std::move(config)),
      transport_(transport),
      log_(log),
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

void LearnerNode::on_experience(const auvrl_lcm::experience_batch_t& msg) {
  ++counters_.batches_received;
  if (msg.actor_id < 0 || msg.actor_id >= config_.max_actors) {
    ++counters_.dropped_unknown_actor;
    return;
  }
  const int n = msg.num_transitions;
  const auto rows_ok = [n](const auto& rows, int cols) {
    return static_cast<int>(rows.size()) == n &&
           std::all_of(rows.begin(), rows.end(),
                       [cols](const auto& r) { return static_cast<int>(r.size()) == cols; });
  };
  if (n >= 1 && n <= config_.max_transitions_per_batch) note_other_sizes(msg);
  if (msg.state_dim != config_.ddpg.state_dim || msg.action_dim != config_.ddpg.action_dim ||
      n < 1 || n > config_.max_transitions_per_batch || !rows_ok(msg.states, msg.state_dim) ||
      !rows_ok(msg.next_states, msg.state_dim) || !rows_ok(msg.actions, msg.action_dim) ||
      !rows_ok(msg.achieved_position_ned_m, 3) || !rows_ok(msg.goal_ned_m, 3) ||
      (msg.expert_rows != 0 && !rows_ok(msg.expert_actions, msg.action_dim))) {
    ++counters_.dropped_dims;
    return;
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
  const bool actions_in_range = in_range(msg.actions) && in_range(msg.expert_actions);
  if (!finite || !actions_in_range) {
    ++counters_.dropped_non_finite;
    return;
  }
  std::int64_t& last = last_batch_seq_[static_cast<std::size_t>(msg.actor_id)];
  if (last >= 0 && msg.batch_seq > last + 1) counters_.batches_lost += msg.batch_seq - last - 1;
  last = msg.batch_seq;  // a lower number means the actor restarted: follow it

  // Algorithm 1, line 11: a step trains only once |R| > m, so only transitions stored beyond
  // that threshold earn updates.
  const auto threshold = static_cast<std::size_t>(
      std::max<std::int64_t>(config_.ddpg.batch_size, config_.warmup_transitions));
  double credit = 0.0;
  using Vec = Eigen::Map<const nn::Vector>;
  for (int i = 0; i < n; ++i) {
    const auto& pos = msg.achieved_position_ned_m[static_cast<std::size_t>(i)];
    const auto& goal = msg.goal_ned_m[static_cast<std::size_t>(i)];
    const TransitionView t{
        Vec(msg.states[i].data(), msg.state_dim), Vec(msg.actions[i].data(), msg.action_dim),
        msg.rewards[static_cast<std::size_t>(i)], Vec(msg.next_states[i].data(), msg.state_dim),
        msg.terminal[static_cast<std::size_t>(i)] != 0, Eigen::Vector3f(pos[0], pos[1], pos[2]),
        Eigen::Vector3f(goal[0], goal[1], goal[2]),
        // Episode ids are per actor: the actor id in the top bits makes them global.
        (static_cast<std::uint64_t>(msg.actor_id) << 40) |
            (static_cast<std::uint64_t>(msg.episode_id[static_cast<std::size_t>(i)]) &
             ((std::uint64_t{1} << 40) - 1)),
        static_cast<std::uint32_t>(msg.step_index[static_cast<std::size_t>(i)]),
        msg.expert_rows != 0 ? msg.expert_actions[static_cast<std::size_t>(i)].data() : nullptr};
    const std::size_t slot = replay_->next_slot();
    const bool overwrote = replay_->size() == replay_->capacity();
    const std::uint64_t overwritten_episode = overwrote ? replay_->episode_id(slot) : 0;
    replay_->add(t);
    if (her_) her_->on_add(*replay_, slot, overwrote, overwritten_episode);
    if (replay_->size() > threshold) credit += config_.updates_per_transition;
  }
  counters_.transitions_received += n;
  interval_transitions_ += n;
  const double owed = update_credit_ + credit;
  update_credit_ = std::min(owed, config_.max_update_backlog);
  counters_.updates_skipped += static_cast<std::int64_t>(owed - update_credit_);
}

void LearnerNode::on_weights_request(const auvrl_lcm::weights_request_t&) {
  ++counters_.weights_requests;
  broadcast_requested_ = true;
}

void LearnerNode::on_episode(const auvrl_lcm::episode_report_t& msg) {
  if (msg.actor_id < 0 || msg.actor_id >= config_.max_actors) {
    ++counters_.dropped_unknown_actor;
    return;
  }
  ++counters_.episodes;
}

void LearnerNode::run_updates() {
  const auto threshold = static_cast<std::size_t>(
      std::max<std::int64_t>(config_.ddpg.batch_size, config_.warmup_transitions));
  int done = 0;
  while (update_credit_ >= 1.0 && replay_->size() > threshold &&
         done < config_.max_updates_per_poll && !training_done()) {
    UpdateStats stats;
    if (her_) {
      replay_->sample(sample_rng_, config_.ddpg.batch_size, batch_);
      her_->relabel(*replay_, beta_m(), sample_rng_, batch_);
      stats = ddpg_->update(batch_);
    } else {
      stats = ddpg_->update(*replay_);
    }
    update_credit_ -= 1.0;
    ++done;
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
    maybe_publish_weights();
  }
}

void LearnerNode::maybe_publish_weights() {
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
  const std::vector<std::uint8_t> bytes = nn::network_to_bytes(ddpg_->actor());
  msg.num_bytes = static_cast<std::int32_t>(bytes.size());
  msg.network.assign(bytes.begin(), bytes.end());
  return msg;
}

void LearnerNode::publish_weights() {
  const auvrl_lcm::policy_weights_t weights = weights_message();
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
  last_broadcast_updates_ = ddpg_->updates();
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
  const bool can_update = update_credit_ >= 1.0 && !training_done();
  transport_.handle(can_update || broadcast_requested_ ? 0 : timeout_ms);
  if (!unrecoverable_.empty()) throw UnrecoverableFault(unrecoverable_);
  run_updates();
  maybe_publish_weights();  // requests, and weights held back by the rate limit
  const auto now = Clock::now();
  if (now >= next_stats_) publish_stats();
  if (!config_.checkpoint_dir.empty() && now >= next_checkpoint_) checkpoint();
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
        if (version != kCheckpointVersion) {
          r.fail("format version " + std::to_string(version) + ", expected " +
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
        r.verify_checksum();
        ddpg_ = std::move(ddpg);
        replay_ = std::move(replay);
        counters_.episodes = episodes;
        counters_.transitions_received = transitions;
        update_credit_ = std::clamp(credit, 0.0, config_.max_update_backlog);
        seqs.resize(static_cast<std::size_t>(config_.max_actors), -1);
        last_batch_seq_ = std::move(seqs);
        sample_rng_ = sample_rng;
        if (her_) her_->rebuild(*replay_);
      },
      log_);
  broadcast_requested_ = true;
  log_ << "auv_learner: resumed from " << file.path << " (" << ddpg_->updates() << " updates, "
       << replay_->size() << " transitions, " << counters_.episodes << " episodes)\n";
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
  publish_weights();
  publish_stats();
}

}  // namespace auvrl::learner
