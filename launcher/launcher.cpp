#include "launcher/launcher.hpp"

#include <signal.h>
#include <unistd.h>

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

#include "agent/pid_controller.hpp"
#include "common/channels.hpp"
#include "common/config/yaml_config.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "common/process.hpp"
#include "common/signals.hpp"
#include "common/task/task_yaml.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"
#include "eval/evaluation.hpp"
#include "eval/quick_evaluator.hpp"
#include "eval/ranking.hpp"
#include "launcher/run_config.hpp"
#include "sim/vehicle_model.hpp"
#include "tuning/policy_finetune.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

std::string timestamp() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%d-%H%M%S", std::localtime(&now));
  return text;
}

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// One supervised process: what to start, how often it was restarted.
struct Role {
  std::string name;
  /// The command line for a start after `restarts` restarts.
  std::function<std::vector<std::string>(std::size_t restarts)> argv;
  std::string log_path;
  std::unique_ptr<process::ChildProcess> proc;
  std::deque<Clock::time_point> restarts;
  Clock::time_point restart_due{};
  bool waiting_restart = false;
  bool finished = false;  ///< ended by itself, successfully, and should stay ended
  int actor_id = -1;      ///< an actor's id (its signs of life are its EPISODE reports)
};

/// Whether dir holds a finished learner checkpoint (checkpoint-<updates>.ckpt). A learner
/// killed while writing leaves only its temporary file, which --resume cannot use.
bool has_checkpoint_file(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("checkpoint-", 0) == 0 && entry.path().extension() == ".ckpt") return true;
  }
  return false;
}

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long total = std::lround(s);
  std::ostringstream out;
  if (total >= 3600) out << total / 3600 << "h";
  out << std::setw(total >= 3600 ? 2 : 1) << std::setfill('0') << (total % 3600) / 60 << "m"
      << std::setw(2) << std::setfill('0') << total % 60 << "s";
  return out.str();
}

}  // namespace

std::string prepare_run_directory(TrainOptions& o) {
  if (o.resume) {
    if (!fs::is_regular_file(fs::path(o.run_dir) / "config.yaml")) {
      throw std::runtime_error("--resume " + o.run_dir + ": no config.yaml there (not a run)");
    }
    return (fs::path(o.run_dir) / "config.yaml").string();
  }
  if (o.config_path.empty() || !fs::is_regular_file(o.config_path)) {
    throw std::runtime_error("configuration '" + o.config_path + "' not found");
  }
  read_run_config(o.config_path);  // a broken configuration fails here, before anything starts
  if (o.run_dir.empty()) {
    o.run_dir = (fs::path(o.source_dir) / "runs" /
                 (fs::path(o.config_path).stem().string() + "-" + timestamp()))
                    .string();
  }
  if (fs::exists(fs::path(o.run_dir) / "config.yaml")) {
    throw std::runtime_error(o.run_dir + " already holds a run (use --resume to continue it)");
  }
  for (const char* sub : {"logs", "checkpoints", "eval", "plots", "processes"}) {
    fs::create_directories(fs::path(o.run_dir) / sub);
  }
  // The copy must resolve the vehicle path the same way: make it absolute.
  std::ifstream in(o.config_path);
  std::ofstream out(fs::path(o.run_dir) / "config.yaml");
  std::string line;
  const RunConfig parsed = read_run_config(o.config_path);
  out << "# Copied from " << fs::absolute(o.config_path).string() << " by auvrl train.\n";
  while (std::getline(in, line)) {
    if (line.rfind("vehicle:", 0) == 0) {
      out << "vehicle: " << fs::absolute(parsed.vehicle_path).lexically_normal().string() << "\n";
    } else {
      out << line << "\n";
    }
  }
  if (!out) throw std::runtime_error("cannot write " + o.run_dir + "/config.yaml");
  std::ofstream howto(fs::path(o.run_dir) / "README.txt");
  howto << "auvrl run directory\n"
        << "  config.yaml       the configuration of this run\n"
        << "  progress.csv      training progress (also on the terminal)\n"
        << "  episodes.csv      one row per episode; learner.csv: the learner's figures\n"
        << "  logs/             LCM event logs of all traffic (auv_log list logs/*.lcmlog)\n"
        << "  checkpoints/      learner checkpoints (auvrl train --resume " << o.run_dir << ")\n"
        << "  policy.nn         the last policy; policy_best.nn: the best by quick evaluation\n"
        << "  policy_finetuned.nn, finetune.csv   the fine-tuned policy and its progress\n"
        << "  quick_eval.csv    every quick evaluation (reached, mean time, hold error, worst\n"
           "                    time ratio to the PID's on the same way-points, kept)\n"
        << "  eval/, plots/, report.md   evaluation of the policy and the PID baseline\n"
        << "  processes/        each process's output\n"
        << "Watch the running system with lcm-spy: scripts/spy.sh " << o.run_dir << "\n";
  return (fs::path(o.run_dir) / "config.yaml").string();
}

namespace {

/// Fine-tunes the trained policy at start_path (progress to finetune.csv) and returns the path
/// of the policy to keep. The weights are scored on validation way-points (the quick
/// evaluation's, and half as many again facing a random heading) every validate_every
/// iterations and at the end; the best of them, if better
/// than the trained policy there, is written to policy_finetuned.nn and kept. (The
/// fine-tuning's own way-points are few: a step that lowers their objective can lose a
/// way-point elsewhere.) Ctrl-C ends the fine-tuning after the iteration under way.
std::string finetune_stage(const sim::VehicleModel& model, const task::TaskConfig& task,
                           const tuning::FinetuneConfig& config, std::uint64_t seed,
                           const eval::QuickEvaluator& quick, double max_hold_m,
                           const std::string& start_path, const fs::path& run_dir,
                           std::ostream& out) {
  constexpr int validate_every = 10;
  const nn::Mlp start = nn::network_from_bytes(nn::read_file(start_path), 1);
  out << "auvrl train: fine-tuning " << start_path << " (evolution strategies, "
      << config.iterations << " iterations of " << 2 * config.pairs << " policies on "
      << config.episodes << " way-points)\n";
  auto describe = [](const eval::ValidationScore& v) {
    std::ostringstream text;
    text << v.reached << "/" << v.episodes << " reached, mean " << std::fixed
         << std::setprecision(2) << v.mean_time_s << " s, hold " << v.mean_hold_m
         << " m, worst time ratio to the PID " << v.max_time_ratio;
    return text.str();
  };
  const eval::ValidationScore before = quick.evaluate(start);
  eval::ValidationScore best = before;
  std::optional<nn::Mlp> best_net;
  int best_iteration = 0;
  const std::string csv_path = (run_dir / "finetune.csv").string();
  std::ofstream csv(csv_path);
  csv << "iteration,objective_s,elapsed_s,validation_reached,validation_mean_time_s,"
         "validation_hold_m,validation_worst_time_ratio\n";
  const tuning::FinetuneResult result = tuning::finetune_policy(
      model, task, start, config, seed,
      [&](const tuning::FinetuneIteration& it, const nn::Mlp& weights) {
        csv << it.iteration << ',' << it.objective << ',' << it.elapsed_s;
        if (it.iteration % validate_every == 0 || it.iteration == config.iterations) {
          const eval::ValidationScore score = quick.evaluate(weights);
          csv << ',' << score.reached << ',' << score.mean_time_s << ',' << score.mean_hold_m << ','
              << score.max_time_ratio;
          if (eval::ranks_above(score, best, {max_hold_m, false})) {
            best = score;
            best_net = weights;
            best_iteration = it.iteration;
          }
          out << "auvrl train: fine-tuning " << it.iteration << "/" << config.iterations
              << "  objective " << std::fixed << std::setprecision(3) << it.objective
              << " s  validation " << score.reached << "/" << score.episodes << " mean "
              << std::setprecision(2) << score.mean_time_s << " s  elapsed "
              << format_duration(it.elapsed_s) << "\n";
        } else {
          csv << ",,,,";
        }
        csv << '\n';
      },
      [] { return signals::stop_requested(); });
  csv.flush();
  if (!csv) out << "auvrl train: could not write " << csv_path << "\n";
  out << "auvrl train: fine-tuned: objective " << std::fixed << std::setprecision(3)
      << result.start_objective << " -> " << result.best_objective << " s\n"
      << "  validation before: " << describe(before) << "\n";
  if (!best_net) {
    out << "  not kept: no fine-tuned weights scored better on the validation way-points\n";
    return start_path;
  }
  const std::string tuned_path = (run_dir / "policy_finetuned.nn").string();
  nn::save_network_file(tuned_path, *best_net);
  out << "  validation after:  " << describe(best) << " (iteration " << best_iteration << ")\n"
      << "  kept: " << tuned_path << "\n";
  return tuned_path;
}

}  // namespace

int run_training(const TrainOptions& options, std::ostream& out) {
  out << std::unitbuf;  // progress and supervision lines must reach a log file as they happen
  const fs::path run_dir = options.run_dir;
  const std::string config_path = (run_dir / "config.yaml").string();
  RunConfig rc = read_run_config(config_path);
  if (options.actors >= 0) rc.run.actors = options.actors;
  if (options.max_train_s >= 0) rc.run.max_train_s = options.max_train_s;
  if (options.seed >= 0) rc.run.seed = static_cast<std::uint64_t>(options.seed);
  if (options.finetune_iterations >= 0) rc.finetune.iterations = options.finetune_iterations;
  const int cpus = std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
  const int actors = rc.run.actors > 0 ? rc.run.actors : cpus;
  const sim::VehicleModel model = sim::load_vehicle_file(rc.vehicle_path);
  rc.task.num_thrusters = model.num_thrusters();
  rc.task.max_thrust_n = model.thruster_dynamics.max_thrust_n;

  // Time already trained in earlier invocations of this run (for --resume).
  double trained_before_s = 0;
  {
    std::ifstream progress(run_dir / "progress.csv");
    std::string line, last;
    while (std::getline(progress, line)) {
      if (!line.empty() && line[0] != 'w') last = line;
    }
    if (!last.empty()) trained_before_s = std::atof(last.c_str());
  }
  const bool has_checkpoint = has_checkpoint_file(run_dir / "checkpoints");

  transport::apply_transport_arguments(options.transport_args, rc.transport);
  // Every process opens the same transport as the launcher.
  const std::vector<std::string> transport_args = transport::transport_arguments(rc.transport);
  const bool dds = rc.transport.kind == transport::TransportKind::kDds;
  if (dds && rc.run.private_lockstep_bus && rc.transport.dds.domain_id + actors > 232) {
    throw std::runtime_error("DDS domain " + std::to_string(rc.transport.dds.domain_id) +
                             " + one lockstep domain per actor (" + std::to_string(actors) +
                             ") passes 232: choose a lower transport.dds_domain");
  }

  signals::install_stop_handlers();
  auto transport = transport::make_transport(rc.transport);

  // ---- What the run writes while it trains. ----
  const bool new_files = !fs::exists(run_dir / "episodes.csv");
  std::ofstream episodes_csv(run_dir / "episodes.csv", std::ios::app);
  std::ofstream learner_csv(run_dir / "learner.csv", std::ios::app);
  std::ofstream progress_csv(run_dir / "progress.csv", std::ios::app);
  const std::string quick_eval_header =
      "wall_s,policy_version,reached,episodes,mean_time_to_reach_s,mean_error_after_reach_m,"
      "max_time_ratio_to_pid,kept";
  if (fs::exists(run_dir / "quick_eval.csv")) {
    // A run resumed from an older version whose columns differ: keep its rows apart rather
    // than append rows that do not match the header.
    std::ifstream existing(run_dir / "quick_eval.csv");
    std::string header;
    std::getline(existing, header);
    if (header != quick_eval_header) {
      fs::rename(run_dir / "quick_eval.csv", run_dir / "quick_eval.old.csv");
    }
  }
  const bool new_quick_eval = !fs::exists(run_dir / "quick_eval.csv");
  std::ofstream quick_eval_csv(run_dir / "quick_eval.csv", std::ios::app);
  if (new_quick_eval) quick_eval_csv << quick_eval_header << '\n';
  if (new_files) {
    episodes_csv << "wall_s,actor_id,episode_id,policy_version,return,length_steps,success,"
                    "final_distance_m,min_distance_m,beta_m,end_reason,thrust_energy\n";
    learner_csv << "wall_s,updates,updates_per_s,transitions_received,transitions_per_s,"
                   "buffer_size,critic_loss,actor_loss,mean_q,episodes,beta_m,weights_published,"
                   "expert_share\n";
    progress_csv << "wall_s,episodes,success_rate,beta_m,env_steps_per_s,updates_per_s,"
                    "best_suite_success\n";
  }
  const auto start = Clock::now();
  const auto wall = [&] { return trained_before_s + seconds_since(start); };

  // Signs of life for the hang watch (RunSettings::heartbeat_timeout_s): the time of the last
  // heartbeat by process id (simulators, logger, learner) and of the last episode by actor id.
  std::map<int, Clock::time_point> alive_by_pid, alive_by_actor;
  std::deque<bool> recent_success;
  std::int64_t episodes_seen = 0;
  double beta_m = 0;
  transport::subscribe<auvrl_lcm::episode_report_t>(
      *transport, channels::kEpisode,
      [&](const std::string&, const auvrl_lcm::episode_report_t& e) {
        alive_by_actor[e.actor_id] = Clock::now();
        ++episodes_seen;
        beta_m = e.beta_m;
        recent_success.push_back(e.success);
        if (recent_success.size() > 100) recent_success.pop_front();
        episodes_csv << std::fixed << std::setprecision(3) << wall() << ',' << e.actor_id << ','
                     << e.episode_id << ',' << e.policy_version << ',' << std::setprecision(4)
                     << e.episode_return << ',' << e.length_steps << ',' << int(e.success) << ','
                     << e.final_distance_m << ',' << e.min_distance_m << ',' << e.beta_m << ','
                     << int(e.end_reason) << ',' << e.thrust_energy << '\n';
      });
  std::optional<auvrl_lcm::learner_stats_t> last_stats;
  std::int64_t learner_episodes = 0;
  transport::subscribe<auvrl_lcm::learner_stats_t>(
      *transport, channels::kLearnerStats,
      [&](const std::string&, const auvrl_lcm::learner_stats_t& s) {
        alive_by_pid[s.pid] = Clock::now();
        last_stats = s;
        learner_episodes = s.episodes;
        learner_csv << std::fixed << std::setprecision(3) << wall() << ',' << s.updates << ','
                    << std::setprecision(1) << s.updates_per_s << ',' << s.transitions_received
                    << ',' << s.transitions_per_s << ',' << s.buffer_size << ','
                    << std::setprecision(6) << s.critic_loss << ',' << s.actor_loss << ','
                    << s.mean_q << ',' << s.episodes << ',' << s.beta_m << ','
                    << s.weights_published << ',' << s.expert_share << '\n';
      });
  std::map<int, std::pair<double, std::int64_t>> sim_steps;  // pid -> (rate, total)
  transport::subscribe<auvrl_lcm::sim_heartbeat_t>(
      *transport, channels::kSimHeartbeat,
      [&](const std::string&, const auvrl_lcm::sim_heartbeat_t& h) {
        alive_by_pid[h.pid] = Clock::now();
        sim_steps[h.pid] = {h.steps_per_s, h.steps_total};
      });
  transport::subscribe<auvrl_lcm::logger_heartbeat_t>(
      *transport, channels::kLoggerHeartbeat,
      [&](const std::string&, const auvrl_lcm::logger_heartbeat_t& h) {
        alive_by_pid[h.pid] = Clock::now();
      });
  transport::Latest<auvrl_lcm::policy_weights_t> weights(*transport, channels::kPolicyWeights, 4);

  // ---- The processes. ----
  const std::string bin = options.bin_dir + "/";
  const fs::path proc_dir = run_dir / "processes";
  std::vector<std::unique_ptr<Role>> roles;
  const auto add_role = [&](const std::string& name,
                            std::function<std::vector<std::string>(std::size_t)> argv) {
    auto role = std::make_unique<Role>();
    role->name = name;
    role->argv = std::move(argv);
    role->log_path = (proc_dir / (name + ".log")).string();
    roles.push_back(std::move(role));
    return roles.back().get();
  };
  const auto with_transport = [transport_args](std::vector<std::string> argv) {
    argv.insert(argv.end(), transport_args.begin(), transport_args.end());
    return argv;
  };
  const auto fixed = [with_transport](std::vector<std::string> argv) {
    return [argv = with_transport(std::move(argv))](std::size_t) { return argv; };
  };
  Role* logger =
      add_role("logger", fixed({bin + "auv_logger", "--dir", (run_dir / "logs").string()}));
  std::vector<Role*> sims, actor_roles;
  // Actors (each beside its simulator) on the CPUs the learner does not have, if any.
  std::vector<int> actor_cpus;
  for (int c = 0; c < cpus; ++c) {
    if (c != rc.run.learner_cpu || cpus == 1) actor_cpus.push_back(c);
  }
  // The private lockstep bus of pair i: an LCM port, or a DDS domain, of its own.
  const auto lockstep_args = [&](int i) -> std::vector<std::string> {
    if (!rc.run.private_lockstep_bus) return {};
    if (dds) {
      return {"--lockstep-dds-domain", std::to_string(rc.transport.dds.domain_id + 1 + i)};
    }
    return {"--lockstep-lcm-url",
            "udpm://239.255.76.67:" + std::to_string(7668 + i) + "?ttl=0&recv_buf_size=1048576"};
  };
  for (int i = 0; i < actors; ++i) {
    const std::string cpu =
        std::to_string(actor_cpus[static_cast<std::size_t>(i) % actor_cpus.size()]);
    std::vector<std::string> argv = {
        "/usr/bin/taskset", "-c",         cpu, bin + "auv_sim",      "--vehicle",
        rc.vehicle_path,    "--vehicles", "1", "--first-vehicle-id", std::to_string(i)};
    const auto bus = lockstep_args(i);
    argv.insert(argv.end(), bus.begin(), bus.end());
    sims.push_back(add_role("sim" + std::to_string(i), fixed(argv)));
  }
  std::vector<std::string> learner_argv = {bin + "auv_learner", "--config", config_path,
                                           "--checkpoint-dir", (run_dir / "checkpoints").string(),
                                           "--policy-out", (run_dir / "policy.nn").string(),
                                           "--max-actors", std::to_string(std::max(actors, 1)),
                                           // The run's seed also seeds the networks, the
                                           // minibatches and TD3's noise.
                                           "--seed", std::to_string(rc.run.seed)};
  if (rc.run.learner_cpu >= 0 && rc.run.learner_cpu < cpus) {
    learner_argv.insert(learner_argv.begin(),
                        {"/usr/bin/taskset", "-c", std::to_string(rc.run.learner_cpu)});
  }
  Role* learner = add_role("learner", fixed(learner_argv));
  for (int i = 0; i < actors; ++i) {
    const std::uint64_t seed = rc.run.seed * 1000 + static_cast<std::uint64_t>(i);
    const int cpu = actor_cpus[static_cast<std::size_t>(i) % actor_cpus.size()];
    const std::vector<std::string> bus = lockstep_args(i);
    Role* actor = add_role("actor" + std::to_string(i), [=](std::size_t restarts) {
      // A restarted actor explores anew rather than repeating its first life.
      std::vector<std::string> argv = {bin + "auv_actor",
                                       "--config",
                                       config_path,
                                       "--actor-id",
                                       std::to_string(i),
                                       "--vehicle-id",
                                       std::to_string(i),
                                       "--seed",
                                       std::to_string(seed + 7919 * restarts),
                                       "--pin-cpu",
                                       std::to_string(cpu),
                                       "--report-every",
                                       "100"};
      argv.insert(argv.end(), bus.begin(), bus.end());
      return with_transport(argv);
    });
    actor->actor_id = i;
    actor_roles.push_back(actor);
  }
  const auto start_role = [&](Role& r, bool resume_learner) {
    std::vector<std::string> argv = r.argv(r.restarts.size());
    if (&r == learner && resume_learner) argv.push_back("--resume");
    r.proc = std::make_unique<process::ChildProcess>(argv, r.log_path, true);
    // The new process is watched from its own first sign of life on.
    alive_by_pid.erase(r.proc->pid());
    if (r.actor_id >= 0) alive_by_actor.erase(r.actor_id);
    // PID in the run's namespace, for tools and tests started in that namespace.
    std::ofstream((proc_dir / (r.name + ".pid")).string()) << r.proc->pid() << "\n";
  };
  start_role(*logger, false);
  for (Role* s : sims) start_role(*s, false);
  start_role(*learner, has_checkpoint);
  for (Role* a : actor_roles) start_role(*a, false);
  out << "auvrl train: " << actors << " actors on " << cpus << " CPUs, "
      << transport::describe(rc.transport) << ", run " << run_dir.string()
      << "\n  watch it: scripts/spy.sh " << run_dir.string() << "\n";

  // ---- Supervise, show progress, keep the best policy. ----
  const bool tty = isatty(STDOUT_FILENO) != 0;
  auto next_progress = Clock::now();
  auto next_best_eval =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(rc.run.best_eval_period_s));
  const eval::QuickEvaluator quick(model, rc.task, rc.run.best_eval_suite);
  const double max_hold_m = rc.run.best_eval_max_hold_m;
  eval::ValidationScore best;
  std::int64_t best_version = -1;
  if (options.resume && fs::exists(run_dir / "policy_best.nn")) {
    // A resumed run keeps its best policy unless a newer one scores better.
    try {
      const nn::Mlp previous =
          nn::network_from_bytes(nn::read_file((run_dir / "policy_best.nn").string()), 1);
      best = quick.evaluate(previous);
      best_version = 0;
    } catch (const std::exception& e) {
      out << "auvrl train: " << (run_dir / "policy_best.nn").string()
          << " not used as the best so far: " << e.what() << "\n";
    }
  }
  std::string stop_reason;
  int exit_code = 0;
  bool learner_done = false;
  double last_print_s = -1e9;
  auto last_check = Clock::now();
  while (true) {
    transport->handle(100);
    if (signals::stop_requested()) {
      stop_reason = "stopped by the user";
      exit_code = 130;
      break;
    }
    if (rc.run.max_train_s > 0 && wall() >= rc.run.max_train_s) {
      stop_reason = "training budget of " + format_duration(rc.run.max_train_s) + " used";
      break;
    }
    // The launcher's own pauses (a quick evaluation, starved of CPU by busier processes, a
    // blocked write) are not the processes' silence: a gap between two passes here beyond 1 s
    // moves every sign of life forward by it (measured: a nice 19 launcher on a machine
    // loaded by other work stalled 80 s at a time and took every process for hung).
    // And when nobody at all was heard for half the timeout, the machine (or the bus) is the
    // likelier culprit than every process at once: nobody is killed for silence then.
    bool anyone_heard = false;
    {
      const auto now = Clock::now();
      if (now - last_check > std::chrono::seconds(1)) {
        for (auto* alive : {&alive_by_pid, &alive_by_actor}) {
          for (auto& entry : *alive)
            entry.second = std::min(now, entry.second + (now - last_check));
        }
      }
      last_check = now;
      for (const auto* alive : {&alive_by_pid, &alive_by_actor}) {
        for (const auto& entry : *alive) {
          anyone_heard =
              anyone_heard || seconds_since(entry.second) < rc.run.heartbeat_timeout_s / 2;
        }
      }
    }
    // Supervision: restart what died, with back-off; give up on a role that keeps dying.
    for (auto& r : roles) {
      if (r->finished) continue;
      if (r->waiting_restart) {
        if (Clock::now() >= r->restart_due) {
          r->waiting_restart = false;
          out << (tty ? "\n" : "") << "auvrl train: restarting " << r->name << "\n";
          start_role(*r, r.get() == learner && has_checkpoint_file(run_dir / "checkpoints"));
        }
        continue;
      }
      if (r->proc->running()) {
        // Hang watch: silent too long after its first sign of life -> SIGKILL; the restart
        // below follows once it is reaped.
        auto& alive = r->actor_id >= 0 ? alive_by_actor : alive_by_pid;
        const auto seen = alive.find(r->actor_id >= 0 ? r->actor_id : r->proc->pid());
        if (rc.run.heartbeat_timeout_s > 0 && anyone_heard && seen != alive.end() &&
            seconds_since(seen->second) > rc.run.heartbeat_timeout_s) {
          out << (tty ? "\n" : "") << "auvrl train: " << r->name << " silent for "
              << std::lround(seconds_since(seen->second))
              << " s (no heartbeat; hung?); killing it\n";
          alive.erase(seen);
          r->proc->signal(SIGKILL);
        }
        continue;
      }
      const int status = r->proc->wait_for_exit(std::chrono::milliseconds(0));
      const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      if (r.get() == learner && clean) {
        learner_done = true;
        r->finished = true;
        continue;
      }
      if (r->actor_id >= 0 && clean) {
        // An actor ends by itself only when the learner's schedule has ended (training_done in
        // the weights) or its own episode budget is spent: restarting it would only run
        // episodes nobody learns from.
        r->finished = true;
        continue;
      }
      while (!r->restarts.empty() && seconds_since(r->restarts.front()) > rc.run.restart_window_s) {
        r->restarts.pop_front();
      }
      if (static_cast<int>(r->restarts.size()) >= rc.run.max_restarts) {
        stop_reason = r->name + " failed " + std::to_string(r->restarts.size() + 1) +
                      " times within " + format_duration(rc.run.restart_window_s) + " (see " +
                      r->log_path + ")";
        exit_code = 1;
        break;
      }
      const double backoff = std::min(30.0, 0.5 * std::pow(2.0, r->restarts.size()));
      out << (tty ? "\n" : "") << "auvrl train: " << r->name << " ended ("
          << (WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                  : "exit " + std::to_string(WEXITSTATUS(status)))
          << "); restarting in " << backoff << " s\n";
      r->restarts.push_back(Clock::now());
      r->waiting_restart = true;
      r->restart_due = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(backoff));
    }
    if (exit_code == 1) break;
    if (learner_done) {
      stop_reason = "the learner's schedule ended";
      break;
    }

    // Keep the best policy: evaluate the newest weights now and then.
    if (Clock::now() >= next_best_eval) {
      next_best_eval = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(rc.run.best_eval_period_s));
      if (auto w = weights.take(); w && w->version != best_version && w->version > 0) {
        try {
          nn::Mlp net = nn::network_from_bytes(
              reinterpret_cast<const std::uint8_t*>(w->network.data()), w->network.size(), 1);
          const eval::ValidationScore score = quick.evaluate(net);
          const bool keep = best_version < 0 || eval::ranks_above(score, best, {max_hold_m, true});
          if (keep) {
            best = score;
            best_version = w->version;
            nn::save_network_file((run_dir / "policy_best.nn").string(), net);
          }
          quick_eval_csv << std::fixed << std::setprecision(1) << wall() << ',' << w->version << ','
                         << score.reached << ',' << score.episodes << ',' << std::setprecision(2)
                         << (score.reached > 0 ? score.mean_time_s : 0.0) << ','
                         << std::setprecision(3) << (score.reached > 0 ? score.mean_hold_m : 0.0)
                         << ','
                         << (score.max_time_ratio < eval::ValidationScore::kNone
                                 ? score.max_time_ratio
                                 : 0.0)
                         << ',' << (keep ? 1 : 0) << '\n';
          quick_eval_csv.flush();
        } catch (const std::exception& e) {
          out << "auvrl train: quick evaluation failed: " << e.what() << "\n";
        }
      }
    }

    if (Clock::now() >= next_progress) {
      next_progress = Clock::now() + std::chrono::seconds(1);
      double steps_per_s = 0;
      for (const auto& [pid, s] : sim_steps) steps_per_s += s.first;
      int successes = 0;
      for (bool s : recent_success) successes += s ? 1 : 0;
      const double success_rate =
          recent_success.empty() ? 0.0 : static_cast<double>(successes) / recent_success.size();
      const double updates_per_s = last_stats ? last_stats->updates_per_s : 0.0;
      double eta = -1;
      if (rc.run.max_train_s > 0) {
        eta = rc.run.max_train_s - wall();
      } else if (rc.learner_max_episodes > 0 && learner_episodes > 0) {
        eta = (rc.learner_max_episodes - learner_episodes) * (seconds_since(start) / episodes_seen);
      }
      const std::string best_text =
          best_version < 0 ? "-"
                           : std::to_string(best.reached) + "/" + std::to_string(best.episodes);
      progress_csv << std::fixed << std::setprecision(1) << wall() << ',' << learner_episodes << ','
                   << std::setprecision(3) << success_rate << ',' << beta_m << ','
                   << std::setprecision(0) << steps_per_s << ',' << updates_per_s << ','
                   << (best_version < 0 ? 0.0 : static_cast<double>(best.reached) / best.episodes)
                   << '\n';
      errno = 0;
      progress_csv.flush();
      episodes_csv.flush();
      learner_csv.flush();
      // Disk full or run directory not writable: stop with the path named; the checkpoints
      // already written stay intact (the learner writes each to a new file and renames it).
      if (!progress_csv || !episodes_csv || !learner_csv || !quick_eval_csv) {
        const char* file = !progress_csv   ? "progress.csv"
                           : !episodes_csv ? "episodes.csv"
                           : !learner_csv  ? "learner.csv"
                                           : "quick_eval.csv";
        stop_reason = "cannot write " + (run_dir / file).string() + " (" +
                      (errno != 0 ? std::strerror(errno) : "write error") +
                      "): disk full or run directory not writable; the last checkpoint in " +
                      (run_dir / "checkpoints").string() + " is kept";
        exit_code = 1;
        break;
      }
      std::ostringstream line;
      line << std::fixed << "episodes " << learner_episodes << "  success(100) "
           << std::setprecision(0) << 100 * success_rate << "%  beta " << std::setprecision(2)
           << beta_m << " m  env " << std::setprecision(0) << steps_per_s << " steps/s  updates "
           << updates_per_s << "/s  best " << best_text << "  elapsed " << format_duration(wall())
           << "  left " << format_duration(eta);
      if (tty) {
        out << "\r" << line.str() << "   " << std::flush;
      } else if (wall() - last_print_s >= 5.0) {
        out << line.str() << "\n";
        last_print_s = wall();
      }
    }
  }
  if (tty) out << "\n";
  out << "auvrl train: " << stop_reason << "; stopping\n";

  // ---- Stop: actors first (no more experience), then the learner (final checkpoint and
  // policy), then the simulators and the logger (it flushes everything it received).
  for (Role* a : actor_roles) {
    if (a->proc) a->proc->terminate(std::chrono::seconds(5));
  }
  if (learner->proc) learner->proc->terminate(std::chrono::seconds(120));
  for (Role* s : sims) {
    if (s->proc) s->proc->terminate(std::chrono::seconds(5));
  }
  // Let the logger take in the last messages before it stops.
  transport->handle(200);
  if (logger->proc) logger->proc->terminate(std::chrono::seconds(10));
  episodes_csv.flush();
  learner_csv.flush();
  progress_csv.flush();

  out << "auvrl train: run directory " << run_dir.string() << "\n"
      << "  checkpoints  " << (run_dir / "checkpoints").string() << "\n"
      << "  policy       " << (run_dir / "policy.nn").string()
      << (best_version >= 0 ? "  (best so far: policy_best.nn, " +
                                  (best_version == 0 ? std::string("from before the resume")
                                                     : "version " + std::to_string(best_version)) +
                                  ")"
                            : "")
      << "\n  logs         " << (run_dir / "logs").string() << "\n";
  if (exit_code != 0) {
    out << "  continue it: auvrl train --resume " << run_dir.string() << "\n";
    return exit_code;
  }
  // ---- The trained policy: the last one or the best seen, by the quick evaluation. ----
  std::string policy_path = (run_dir / "policy.nn").string();
  if (fs::exists(run_dir / "policy_best.nn")) {
    // The last policy may be worse than the best seen: compare them on the quick evaluation.
    try {
      const nn::Mlp last = nn::network_from_bytes(nn::read_file(policy_path), 1);
      if (eval::ranks_above(best, quick.evaluate(last), {max_hold_m, true})) {
        policy_path = (run_dir / "policy_best.nn").string();
      }
    } catch (const std::exception&) {
      policy_path = (run_dir / "policy_best.nn").string();
    }
  }
  if (!fs::exists(policy_path)) {
    out << "auvrl train: no policy was written; nothing to fine-tune or evaluate\n";
    return 1;
  }

  // ---- Fine-tuning on the evaluation's criterion (tuning/policy_finetune.hpp). ----
  if (rc.finetune.iterations > 0) {
    const eval::QuickEvaluator finetune_quick(model, rc.task, rc.run.best_eval_suite,
                                              rc.run.best_eval_suite / 2);
    try {
      policy_path = finetune_stage(model, rc.task, rc.finetune, rc.run.seed, finetune_quick,
                                   max_hold_m, policy_path, run_dir, out);
    } catch (const std::exception& e) {
      // The trained policy stays: a failed fine-tuning (a full disk, say) loses nothing.
      out << "auvrl train: fine-tuning failed: " << e.what() << "; keeping " << policy_path << "\n";
    }
  }
  if (!options.evaluate) return 0;

  // ---- Evaluation of the learned policy and the PID baseline, plots, report. ----
  out << "auvrl train: evaluating " << policy_path << " and the PID baseline\n";
  eval::EvaluationConfig eval;
  eval.task = rc.task;
  const std::vector<eval::Scenario> all = eval::parse_scenarios("all");
  const nn::Mlp policy_net = nn::network_from_bytes(nn::read_file(policy_path), 1);
  agent::PolicyController policy(policy_net, rc.task.state_dim(), rc.task.num_thrusters);
  const auto policy_rows =
      eval::run_evaluation(model, eval, policy, all, (run_dir / "eval" / "policy").string());
  eval::EvalRequest pid_request;
  pid_request.controller = "pid";
  eval::EvaluationConfig pid_eval = eval;
  auto pid = eval::make_eval_controller(pid_request, model, pid_eval);
  const auto pid_rows =
      eval::run_evaluation(model, pid_eval, *pid, all, (run_dir / "eval" / "pid").string());
  std::ofstream(run_dir / "eval" / "selected_policy.txt") << policy_path << "\n";

  const std::string plot = options.source_dir + "/scripts/plot_run.py";
  if (fs::exists(plot) && fs::exists("/usr/bin/python3")) {
    process::ChildProcess plotter({"/usr/bin/python3", plot, run_dir.string()},
                                  (proc_dir / "plots.log").string());
    const int status = plotter.wait_for_exit(std::chrono::minutes(5));
    if (status != 0) out << "auvrl train: plotting failed (see " << plotter.log_path() << ")\n";
  }
  out << "\nlearned policy (" << policy_path << "):\n"
      << eval::format_summary_table(policy_rows) << "\nPID baseline:\n"
      << eval::format_summary_table(pid_rows) << "\nreport: " << (run_dir / "report.md").string()
      << "\n";
  return 0;
}

}  // namespace auvrl::launcher
