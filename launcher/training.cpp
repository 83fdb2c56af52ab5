#include "launcher/training.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>

#include "common/channels.hpp"
#include "common/dds_security.hpp"
#include "common/listening_lines.hpp"
#include "common/nn/serialize.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"
#include "eval/evaluation.hpp"
#include "launcher/format.hpp"
#include "launcher/run_directory.hpp"
#include "launcher/telemetry.hpp"
#include "launcher/training_monitor.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

std::string snapshot_dir(const std::string& run_dir) {
  return (fs::path(run_dir) / "snapshots").string();
}

void apply_train_options(const TrainOptions& options, RunConfig& rc) {
  if (options.actors >= 0) rc.run.actors = options.actors;
  if (options.max_train_s >= 0) rc.run.max_train_s = options.max_train_s;
  if (options.seed >= 0) rc.run.seed = static_cast<std::uint64_t>(options.seed);
  if (options.reproducible) rc.run.reproducible = true;
  if (options.max_updates >= 0) rc.learner_max_updates = options.max_updates;
  if (options.finetune_iterations >= 0) rc.finetune.iterations = options.finetune_iterations;
}

void check_reproducible_budget(const RunConfig& rc) {
  if (!rc.run.reproducible || rc.learner_max_updates > 0 || rc.learner_max_episodes > 0) return;
  throw std::runtime_error(
      "--reproducible (run.reproducible) counts the training budget in updates, not seconds "
      "(run.max_train_s is not used): set learner.max_updates in the run file or give "
      "--max-updates N (the fast preset reaches about 600000 updates in its 85 s on 2 cores), "
      "or set learner.max_episodes");
}

RunContext load_run_context(const TrainOptions& options, ContextUse use) {
  RunContext ctx{
      options, options.run_dir, (fs::path(options.run_dir) / "config.yaml").string(), {}, {}, 1, 1};
  RunConfig& rc = ctx.rc;
  rc = read_run_config(ctx.config_path);
  apply_train_options(options, rc);
  if (use == ContextUse::kTraining) check_reproducible_budget(rc);
  ctx.cpus = std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
  ctx.actors = rc.run.actors > 0 ? rc.run.actors : ctx.cpus;
  ctx.model = sim::load_vehicle_file(rc.vehicle_path);
  task::apply_vehicle(ctx.model.facts(), rc.task);
  transport::apply_transport_arguments(options.transport_args, rc.transport);
  const bool dds = rc.transport.kind == transport::TransportKind::kDds;
  if (dds && rc.run.private_lockstep_bus && rc.transport.dds.domain_id + ctx.actors > 232) {
    throw std::runtime_error(
        fmt::format("DDS domain {} + one lockstep domain per actor ({}) passes 232: choose a "
                    "lower transport.dds_domain",
                    rc.transport.dds.domain_id, ctx.actors));
  }
  return ctx;
}

namespace {

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// A role whose command line is the same at every start.
RoleSpec fixed_role(const RunContext& ctx, std::string name, RoleKind kind,
                    std::vector<std::string> argv) {
  const std::string log_path = (fs::path(ctx.run_dir) / "processes" / (name + ".log")).string();
  RoleSpec role;
  role.name = std::move(name);
  role.kind = kind;
  role.argv = [argv = std::move(argv)](std::size_t) { return argv; };
  role.log_path = log_path;
  return role;
}

/// The DDS Security identity of participant `name` (scripts/pki.sh's names: learner, logger,
/// launcher, actor-I, sim-I), when the run is secured.
std::vector<std::string> identity_args(const RunContext& ctx, const std::string& name) {
  const transport::TransportConfig& t = ctx.rc.transport;
  if (t.kind != transport::TransportKind::kDds || t.dds.security_dir.empty()) return {};
  return {"--dds-identity", name};
}

/// A secured run refuses to start unless scripts/pki.sh's directory holds a valid identity for
/// every participant it will start (a missing actor-3 is named before anything runs).
void check_identities(const RunContext& ctx) {
  if (identity_args(ctx, "launcher").empty()) return;
  std::vector<std::string> names = {"launcher", "learner", "logger"};
  for (int i = 0; i < ctx.actors; ++i) {
    names.push_back("actor-" + std::to_string(i));
    names.push_back("sim-" + std::to_string(i));
  }
  transport::check_dds_identities(ctx.rc.transport.dds.security_dir, names);
}

/// The private lockstep bus of pair i: an LCM port, or a DDS domain, of its own.
std::vector<std::string> lockstep_args(const RunContext& ctx, int i) {
  if (!ctx.rc.run.private_lockstep_bus) return {};
  if (ctx.rc.transport.kind == transport::TransportKind::kDds) {
    return {"--lockstep-dds-domain", std::to_string(ctx.rc.transport.dds.domain_id + 1 + i)};
  }
  return {"--lockstep-lcm-url",
          fmt::format("udpm://239.255.76.67:{}?ttl=0&recv_buf_size=1048576", 7668 + i)};
}

/// The flags of reproducible mode that the learner and the actors share (none otherwise).
std::vector<std::string> reproducible_args(const RunContext& ctx) {
  if (!ctx.rc.run.reproducible) return {};
  return {"--reproducible", "--round-weights-every-steps",
          std::to_string(ctx.rc.run.round_weights_every_steps)};
}

/// The learner's flags that the launcher's settings add to its configuration: a --max-updates
/// override (the learner reads learner.max_updates from config.yaml itself) and, in
/// reproducible mode, the snapshots the best policy is chosen from.
std::vector<std::string> learner_schedule_args(const RunContext& ctx) {
  std::vector<std::string> args = reproducible_args(ctx);
  if (ctx.rc.run.reproducible) {
    args.insert(args.end(),
                {"--snapshot-dir", snapshot_dir(ctx.run_dir), "--snapshot-every-updates",
                 std::to_string(ctx.rc.run.best_eval_every_updates)});
  }
  if (ctx.options.max_updates >= 0) {
    args.insert(args.end(), {"--max-updates", std::to_string(ctx.options.max_updates)});
  }
  return args;
}

/// The learner's command line (pinned to run.learner_cpu when set).
std::vector<std::string> learner_argv(const RunContext& ctx, const std::string& bin) {
  std::vector<std::string> argv = {
      bin + "auv_learner", "--config", ctx.config_path, "--checkpoint-dir",
      (fs::path(ctx.run_dir) / "checkpoints").string(), "--policy-out",
      (fs::path(ctx.run_dir) / "policy.nn").string(), "--average-policy-out",
      (fs::path(ctx.run_dir) / kAveragePolicyFile).string(), "--max-actors",
      std::to_string(std::max(ctx.actors, 1)),
      // The run's seed also seeds the networks, the minibatches
      // and TD3's noise.
      "--seed", std::to_string(ctx.rc.run.seed)};
  argv = concat(argv, learner_schedule_args(ctx));
  if (ctx.rc.run.learner_cpu >= 0 && ctx.rc.run.learner_cpu < ctx.cpus) {
    argv.insert(argv.begin(), {"/usr/bin/taskset", "-c", std::to_string(ctx.rc.run.learner_cpu)});
  }
  return argv;
}

/// Actor i's role: a restarted actor explores anew (another seed) rather than repeating its
/// first life; in reproducible mode it is the same actor (the same seed), and the learner tells
/// it where to resume.
RoleSpec actor_role(const RunContext& ctx, int i, int cpu, const std::string& bin,
                    const std::vector<std::string>& transport_args) {
  const std::uint64_t seed = ctx.rc.run.seed * 1000 + static_cast<std::uint64_t>(i);
  const std::uint64_t restart_seed_step = ctx.rc.run.reproducible ? 0 : 7919;
  // Its first episode waits until the learner and the logger read its experience (DDS).
  const std::vector<std::string> rest =
      concat(concat(reproducible_args(ctx), lockstep_args(ctx, i)),
             concat({"--wait-for-readers", "learner,logger"},
                    concat(transport_args, identity_args(ctx, "actor-" + std::to_string(i)))));
  const std::string config_path = ctx.config_path;
  RoleSpec role = fixed_role(ctx, "actor" + std::to_string(i), RoleKind::kActor, {});
  role.actor_id = i;
  // Over LCM (no discovery) only this keeps its first episodes from going out unheard.
  role.starts_after_listeners = true;
  role.argv = [=](std::size_t restarts) {
    return concat({bin + "auv_actor", "--config", config_path, "--actor-id", std::to_string(i),
                   "--vehicle-id", std::to_string(i), "--seed",
                   std::to_string(seed + restart_seed_step * restarts), "--pin-cpu",
                   std::to_string(cpu), "--report-every", "100"},
                  rest);
  };
  return role;
}

}  // namespace

std::vector<RoleSpec> make_roles(const RunContext& ctx,
                                 const std::vector<std::string>& transport_args) {
  const std::string bin = ctx.options.bin_dir + "/";
  const fs::path run_dir = ctx.run_dir;
  std::vector<RoleSpec> roles;
  roles.push_back(fixed_role(
      ctx, "logger", RoleKind::kLogger,
      concat(concat({bin + "auv_logger", "--dir", (run_dir / "logs").string()}, transport_args),
             identity_args(ctx, "logger"))));
  roles.back().listening_text = listening::kLogger;
  // Actors (each beside its simulator) on the CPUs the learner does not have, if any.
  std::vector<int> actor_cpus;
  for (int c = 0; c < ctx.cpus; ++c) {
    if (c != ctx.rc.run.learner_cpu || ctx.cpus == 1) actor_cpus.push_back(c);
  }
  const auto cpu_of = [&](int i) {
    return actor_cpus[static_cast<std::size_t>(i) % actor_cpus.size()];
  };
  for (int i = 0; i < ctx.actors; ++i) {
    std::vector<std::string> argv = {"/usr/bin/taskset", "-c",        std::to_string(cpu_of(i)),
                                     bin + "auv_sim",    "--vehicle", ctx.rc.vehicle_path,
                                     "--vehicles",       "1",         "--first-vehicle-id",
                                     std::to_string(i)};
    argv = concat(concat(argv, lockstep_args(ctx, i)),
                  concat(transport_args, identity_args(ctx, "sim-" + std::to_string(i))));
    roles.push_back(fixed_role(ctx, "sim" + std::to_string(i), RoleKind::kSim, argv));
  }
  RoleSpec learner = fixed_role(ctx, "learner", RoleKind::kLearner, {});
  const std::vector<std::string> base =
      concat(learner_argv(ctx, bin), concat(transport_args, identity_args(ctx, "learner")));
  const std::string checkpoints = (run_dir / "checkpoints").string();
  learner.argv = [base, checkpoints](std::size_t) {
    return has_checkpoint_file(checkpoints) ? concat(base, {"--resume"}) : base;
  };
  learner.listening_text = listening::kLearner;
  roles.push_back(std::move(learner));
  for (int i = 0; i < ctx.actors; ++i) {
    roles.push_back(actor_role(ctx, i, cpu_of(i), bin, transport_args));
  }
  return roles;
}

namespace {

/// One training stage: the transport, the supervised processes and what they report.
class TrainingSession {
 public:
  TrainingSession(const RunContext& ctx, std::ostream& out)
      : ctx_(ctx),
        out_(out),
        tty_(isatty(STDOUT_FILENO) != 0),
        trained_before_s_(trained_before_s(ctx.run_dir)),
        telemetry_(ctx.run_dir),
        supervisor_(
            {ctx.rc.run.max_restarts, ctx.rc.run.restart_window_s, ctx.rc.run.heartbeat_timeout_s},
            clock_, starter_, out, tty_) {}

  TrainingResult run();

 private:
  double wall_s() const { return trained_before_s_ + clock_.now_s() - start_s_; }
  void subscribe();
  void start_processes();
  /// One line on the mode and the budget; in reproducible mode the snapshot folder.
  void announce_mode();
  SupervisionOutcome supervise_pass();
  /// Why the wall-clock budget stopped the run; where that came before learner.max_updates, the
  /// updates in the learner's last statistics message (the learner goes on until it is stopped).
  std::string budget_used_message(double max_train_s) const;
  void evaluate_newest_weights();
  /// Reproducible mode: the quick evaluation of up to max_count of the learner's snapshots.
  void review_snapshots(std::size_t max_count);
  /// Training time left by the budget, s (-1: unknown).
  double left_s() const;
  std::optional<std::string> show_progress();
  std::string status_line(double eta_s) const;
  void stop_processes();
  void print_summary(const SupervisionOutcome& outcome);
  /// A simulator that serves another vehicle than the run's is a fault (vehicle_fault_).
  void check_simulated_vehicle(const auvrl_lcm::sim_heartbeat_t& heartbeat);
  /// An actor that has discarded every episode for run.discard_fault_s while its simulator
  /// answers heartbeats: the run learns nothing (a hung simulator is the supervisor's).
  std::optional<std::string> discarding_actor() const;
  /// True when the monitor took the message; says so when the first message from outside the
  /// run arrives (sender: "process" or "actor id", and its number).
  bool heard(Heard verdict, const std::string& channel, const char* sender, int sender_id);

  const RunContext& ctx_;
  std::ostream& out_;
  const bool tty_;
  const double trained_before_s_;
  SteadyClock clock_;
  ChildProcessStarter starter_;
  TrainingTelemetry telemetry_;
  Supervisor supervisor_;
  TrainingMonitor monitor_{ctx_.actors, clock_};
  std::unique_ptr<BestPolicyKeeper> best_;
  SnapshotReviewer snapshots_{snapshot_dir(ctx_.run_dir)};
  std::optional<std::string> vehicle_fault_;
  double start_s_ = clock_.now_s();
  double next_progress_s_ = 0;
  double next_best_eval_s_ = 0;
  double last_print_s_ = -1e9;
  // Last, so that it goes first: its handlers use the members above.
  std::unique_ptr<transport::Transport> transport_;
  std::unique_ptr<transport::Latest<auvrl_lcm::policy_weights_t>> weights_;
};

void TrainingSession::subscribe() {
  transport::TransportConfig config = ctx_.rc.transport;
  config.dds.role = "observer";
  config.dds.security_identity = "launcher";
  transport_ = transport::make_transport(config);
  transport::subscribe<auvrl_lcm::episode_report_t>(
      *transport_, channels::kEpisode,
      [this](const std::string& channel, const auvrl_lcm::episode_report_t& e) {
        if (!heard(monitor_.take_episode(e), channel, "actor id", e.actor_id)) return;
        supervisor_.heard_from_actor(e.actor_id);
        telemetry_.episodes.add(wall_s(), e);
      });
  transport::subscribe<auvrl_lcm::learner_stats_t>(
      *transport_, channels::kLearnerStats,
      [this](const std::string& channel, const auvrl_lcm::learner_stats_t& s) {
        if (!heard(monitor_.take_learner_stats(s), channel, "process", s.pid)) return;
        supervisor_.heard_from_pid(s.pid);
        telemetry_.learner.add(wall_s(), s);
      });
  transport::subscribe<auvrl_lcm::sim_heartbeat_t>(
      *transport_, channels::kSimHeartbeat,
      [this](const std::string& channel, const auvrl_lcm::sim_heartbeat_t& h) {
        if (!heard(monitor_.take_sim_heartbeat(h), channel, "process", h.pid)) return;
        supervisor_.heard_from_pid(h.pid);
        check_simulated_vehicle(h);
      });
  transport::subscribe<auvrl_lcm::logger_heartbeat_t>(
      *transport_, channels::kLoggerHeartbeat,
      [this](const std::string& channel, const auvrl_lcm::logger_heartbeat_t& h) {
        if (heard(monitor_.take_logger_heartbeat(h), channel, "process", h.pid)) {
          supervisor_.heard_from_pid(h.pid);
        }
      });
  // Reproducible mode evaluates the learner's snapshots instead of the broadcast weights.
  if (ctx_.rc.run.reproducible) return;
  weights_ = std::make_unique<transport::Latest<auvrl_lcm::policy_weights_t>>(
      *transport_, channels::kPolicyWeights, 4);
}

void TrainingSession::start_processes() {
  check_identities(ctx_);
  const std::vector<std::string> transport_args = transport::transport_arguments(ctx_.rc.transport);
  for (RoleSpec& role : make_roles(ctx_, transport_args)) supervisor_.add(std::move(role));
  const fs::path proc_dir = fs::path(ctx_.run_dir) / "processes";
  supervisor_.on_start([this, proc_dir](const std::string& name, int pid) {
    monitor_.started(name, pid);
    // PID in the run's namespace, for tools and tests started in that namespace.
    std::ofstream((proc_dir / (name + ".pid")).string()) << pid << "\n";
  });
  supervisor_.start_all();
  out_ << "auvrl train: " << ctx_.actors << " actors on " << ctx_.cpus << " CPUs, "
       << transport::describe(ctx_.rc.transport) << ", run " << ctx_.run_dir
       << "\n  watch it: scripts/spy.sh " << ctx_.run_dir << "\n";
}

void TrainingSession::announce_mode() {
  const RunConfig& rc = ctx_.rc;
  // (A resumed run keeps its mode: prepare_run_directory restores its command line.)
  if (!rc.run.reproducible) return;
  fs::create_directories(snapshot_dir(ctx_.run_dir));
  std::string budget;
  if (rc.learner_max_updates > 0) budget = fmt::format("{} updates", rc.learner_max_updates);
  if (rc.learner_max_episodes > 0) {
    budget += fmt::format("{}{} episodes", budget.empty() ? "" : " or ", rc.learner_max_episodes);
  }
  out_ << "auvrl train: reproducible mode: budget " << budget
       << " (the learner's schedule; run.max_train_s is not used), weights rounded every "
       << rc.run.round_weights_every_steps << " actor steps, best policy from snapshots every "
       << rc.run.best_eval_every_updates << " updates\n";
}

void TrainingSession::evaluate_newest_weights() {
  if (clock_.now_s() < next_best_eval_s_) return;
  next_best_eval_s_ = clock_.now_s() + ctx_.rc.run.best_eval_period_s;
  const auto w = weights_->take();
  if (!w || w->version == best_->best_version() || w->version <= 0) return;
  try {
    const nn::Mlp net = nn::network_from_bytes(
        reinterpret_cast<const std::uint8_t*>(w->network.data()), w->network.size(), 1);
    best_->consider(net, w->version, wall_s(), telemetry_.quick_eval);
  } catch (const std::exception& e) {
    out_ << "auvrl train: quick evaluation failed: " << e.what() << "\n";
  }
}

std::string TrainingSession::status_line(double eta_s) const {
  const std::string best_text =
      best_->has_best() ? fmt::format("{}/{}", best_->best().reached, best_->best().episodes) : "-";
  return fmt::format(
      "episodes {}  success(100) {:.0f}%  beta {:.2f} m  env {:.0f} steps/s  updates {:.0f}/s  "
      "best {}  elapsed {}  left {}",
      monitor_.learner_episodes(), 100 * monitor_.success_rate(), monitor_.beta_m(),
      monitor_.env_steps_per_s(), monitor_.updates_per_s(), best_text, format_duration(wall_s()),
      format_duration(eta_s));
}

void TrainingSession::review_snapshots(std::size_t max_count) {
  snapshots_.review(*best_, wall_s(), telemetry_.quick_eval, out_, max_count);
}

double TrainingSession::left_s() const {
  const RunConfig& rc = ctx_.rc;
  if (!rc.run.reproducible && rc.run.max_train_s > 0) return rc.run.max_train_s - wall_s();
  double left = -1;
  const std::int64_t learner_episodes = monitor_.learner_episodes();
  if (rc.learner_max_episodes > 0 && learner_episodes > 0 && monitor_.episodes_seen() > 0) {
    left = static_cast<double>(rc.learner_max_episodes - learner_episodes) *
           ((clock_.now_s() - start_s_) / static_cast<double>(monitor_.episodes_seen()));
  }
  // Reproducible mode: the updates still to do at the learner's rate (the sooner end counts).
  const double updates_per_s = monitor_.updates_per_s();
  if (rc.run.reproducible && rc.learner_max_updates > 0 && updates_per_s > 0) {
    const double updates_done = static_cast<double>(monitor_.learner_stats()->updates);
    const double by_updates =
        std::max(0.0, static_cast<double>(rc.learner_max_updates) - updates_done) / updates_per_s;
    left = left < 0 ? by_updates : std::min(left, by_updates);
  }
  return left;
}

std::optional<std::string> TrainingSession::show_progress() {
  if (clock_.now_s() < next_progress_s_) return std::nullopt;
  next_progress_s_ = clock_.now_s() + 1.0;
  const double eta_s = left_s();
  ProgressRow row{wall_s(),
                  monitor_.learner_episodes(),
                  monitor_.success_rate(),
                  monitor_.beta_m(),
                  monitor_.env_steps_per_s(),
                  monitor_.updates_per_s(),
                  0.0};
  if (best_->has_best()) {
    row.best_suite_success = static_cast<double>(best_->best().reached) / best_->best().episodes;
  }
  telemetry_.progress.add(row);
  if (auto error = telemetry_.flush()) return error;
  if (tty_) {
    out_ << "\r" << status_line(eta_s) << "   " << std::flush;
  } else if (wall_s() - last_print_s_ >= 5.0) {
    out_ << status_line(eta_s) << "\n";
    last_print_s_ = wall_s();
  }
  return std::nullopt;
}

void TrainingSession::check_simulated_vehicle(const auvrl_lcm::sim_heartbeat_t& h) {
  const VehicleFacts ours = ctx_.model.facts();
  const VehicleIdentity served{h.vehicle_name, h.num_thrusters,
                               static_cast<std::uint32_t>(h.vehicle_file_crc32)};
  if (!same_vehicle(identity_of(ours), served) && !vehicle_fault_) {
    vehicle_fault_ = vehicle_mismatch_message(
        "the run", ours, fmt::format("auv_sim (pid {}, {})", h.pid, h.vehicle_file), served);
  }
}

std::optional<std::string> TrainingSession::discarding_actor() const {
  const std::optional<DiscardingRun> run = monitor_.discarding_actor(ctx_.rc.run.discard_fault_s);
  if (!run) return std::nullopt;
  return fmt::format(
      "actor{} discarded every episode for {:.0f} s ({} episodes, the last ended by {}) while its "
      "simulator answers: nothing reaches the learner (see {}/processes/actor{}.log and "
      "sim{}.log)",
      run->actor_id, run->for_s, run->episodes,
      eval::end_reason_name(static_cast<task::EndReason>(run->last_end_reason)), ctx_.run_dir,
      run->actor_id, run->actor_id);
}

bool TrainingSession::heard(Heard verdict, const std::string& channel, const char* sender,
                            int sender_id) {
  if (verdict == Heard::kTaken) return true;
  if (verdict == Heard::kForeign && monitor_.foreign() == 1) {  // the first one
    out_ << (tty_ ? "\n" : "") << "auvrl train: ignoring " << channel << " from " << sender << " "
         << sender_id
         << ", which is not one of this run's (another system on the same bus?); "
            "further ones are counted in the summary\n";
  }
  return false;
}

std::string TrainingSession::budget_used_message(double max_train_s) const {
  std::string message = fmt::format("training budget of {} used", format_duration(max_train_s));
  // A slow machine ends the phase before learner.max_updates: say how far it got.
  const auto& stats = monitor_.learner_stats();
  if (ctx_.rc.learner_max_updates > 0 && stats && stats->updates < ctx_.rc.learner_max_updates) {
    message += fmt::format(" after {} of learner.max_updates {} updates", stats->updates,
                           ctx_.rc.learner_max_updates);
  }
  return message;
}

SupervisionOutcome TrainingSession::supervise_pass() {
  transport_->handle(100);
  if (signals::stop_requested()) return {true, 130, "stopped by the user"};
  if (vehicle_fault_) return {true, 1, *vehicle_fault_, false};
  if (auto discarding = discarding_actor()) return {true, 1, *discarding};
  // Reproducible mode ends with the learner's schedule: a wall-clock budget would make the
  // result depend on the machine's speed.
  const double max_train_s = ctx_.rc.run.reproducible ? 0.0 : ctx_.rc.run.max_train_s;
  if (max_train_s > 0 && wall_s() >= max_train_s) {
    return {true, 0, budget_used_message(max_train_s)};
  }
  SupervisionOutcome outcome = supervisor_.poll();
  if (outcome.stop) return outcome;
  // Keep the best policy: evaluate the newest weights now and then, or in reproducible mode
  // the learner's next snapshot (one per pass, so that supervision goes on between them).
  if (ctx_.rc.run.reproducible) {
    review_snapshots(1);
  } else {
    evaluate_newest_weights();
  }
  if (auto error = show_progress()) return {true, 1, *error};
  return {};
}

void TrainingSession::stop_processes() {
  // Actors first (no more experience), then the learner (final checkpoint and policy), then
  // the simulators and the logger (it flushes everything it received).
  supervisor_.stop(RoleKind::kActor, 5);
  supervisor_.stop(RoleKind::kLearner, 120);
  supervisor_.stop(RoleKind::kSim, 5);
  // Let the logger take in the last messages before it stops.
  transport_->handle(200);
  supervisor_.stop(RoleKind::kLogger, 10);
  telemetry_.flush();
}

void TrainingSession::print_summary(const SupervisionOutcome& outcome) {
  const fs::path run_dir = ctx_.run_dir;
  std::string best_text;
  if (best_->has_best()) {
    best_text =
        fmt::format("  (best so far: policy_best.nn, {})",
                    best_->best_version() == 0 ? std::string("from before the resume")
                                               : fmt::format("version {}", best_->best_version()));
  }
  out_ << "auvrl train: run directory " << run_dir.string() << "\n"
       << "  checkpoints  " << (run_dir / "checkpoints").string() << "\n"
       << "  policy       " << (run_dir / "policy.nn").string() << best_text << "\n"
       << "  logs         " << (run_dir / "logs").string() << "\n";
  if (monitor_.foreign() + monitor_.malformed() > 0) {
    out_ << "  ignored      " << monitor_.foreign() << " messages from outside the run, "
         << monitor_.malformed() << " with figures that are not finite\n";
  }
  if (outcome.exit_code != 0 && outcome.resumable) {
    out_ << "  continue it: auvrl train --resume " << run_dir.string() << "\n";
  }
}

TrainingResult TrainingSession::run() {
  signals::install_stop_handlers();
  announce_mode();
  subscribe();
  start_processes();
  // Supervise, show progress, keep the best policy.
  next_progress_s_ = clock_.now_s();
  next_best_eval_s_ = clock_.now_s() + ctx_.rc.run.best_eval_period_s;
  best_ = std::make_unique<BestPolicyKeeper>(ctx_.model, ctx_.rc.task, ctx_.rc.run.best_eval_suite,
                                             ctx_.rc.run.best_eval_max_hold_m, ctx_.run_dir);
  if (ctx_.options.resume) best_->restore(out_);
  SupervisionOutcome outcome;
  while (!outcome.stop) outcome = supervise_pass();
  if (tty_) out_ << "\n";
  out_ << "auvrl train: " << outcome.stop_reason << "; stopping\n";
  stop_processes();
  if (ctx_.rc.run.reproducible) {
    // Every snapshot is evaluated, however fast the machine. Stopped by the user, the rest
    // wait in snapshots/ for a --resume.
    if (outcome.exit_code != 130) {
      review_snapshots(std::numeric_limits<std::size_t>::max());
    } else if (const std::size_t left = list_snapshots(snapshot_dir(ctx_.run_dir)).size();
               left > 0) {
      out_ << "auvrl train: " << left
           << " snapshots not evaluated yet; a --resume evaluates them\n";
    }
    telemetry_.flush();
  }
  print_summary(outcome);
  return {outcome.exit_code, std::move(best_)};
}

}  // namespace

TrainingResult train(const RunContext& ctx, std::ostream& out) {
  TrainingSession session(ctx, out);
  return session.run();
}

}  // namespace auvrl::launcher
