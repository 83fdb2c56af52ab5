// auvrl: the project's front command. Each subcommand parses its own options and calls the
// library that does the work (eval/evaluation.hpp for eval, tools/arrival_search.hpp for fastest);
// adding one is adding a row to kSubcommands.
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "agent/actor_node.hpp"
#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/task/goal_schedule.hpp"
#include "common/task/task.hpp"
#include "common/transport_options.hpp"
#include "eval/evaluation.hpp"
#include "launcher/launcher.hpp"
#include "launcher/run_config.hpp"
#include "learner/learner_node.hpp"
#include "sim/vehicle_model.hpp"
#include "tools/arrival_search.hpp"

namespace {

#ifndef AUVRL_CONFIG_DIR
#error "AUVRL_CONFIG_DIR must be defined (agent/CMakeLists.txt sets it)"
#endif

/// `auvrl eval`: a policy file or the PID baseline on the evaluation scenarios.
int run_eval(int argc, const char* const* argv) {
  auvrl::eval::EvalRequest request;
  request.vehicle_path = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
  std::int64_t seed = 1;
  auvrl::cli::CommandLine cli(
      "auvrl eval",
      "Runs a controller on the evaluation scenarios in process (no noise, the full 70 s each)\n"
      "and writes DIR/summary.csv and DIR/trajectories/<scenario>_<episode>.csv.\n"
      "Scenarios: test1, test2 (facing away), fault (T1 at 10 %), current (0.3 m/s across),\n"
      "suite (random way-points of the training region), all.");
  cli.option("policy", &request.policy_path, "policy network file (nn format)");
  cli.option("controller", &request.controller, "policy or pid");
  cli.option("scenario", &request.scenario, "test1|test2|fault|current|suite|all");
  cli.option("out", &request.out_dir, "output directory (created)");
  cli.option("vehicle", &request.vehicle_path, "vehicle file");
  cli.option("layout", &request.layout,
             "paper|extended|extended_thrust (default: from the policy's inputs, 12+n / 17+n "
             "/ 17+2n)");
  cli.option("seed", &seed, "seed of the suite's way-points and the vehicle resets");
  cli.option("suite-episodes", &request.suite_episodes, "way-points in the suite");
  cli.option("suite-trajectories", &request.suite_trajectories,
             "trajectory files for the first N suite episodes (-1: all)");
  if (!cli.parse(argc, argv)) return 0;
  if (seed < 0) throw auvrl::cli::UsageError("option --seed: expected a value >= 0");
  request.seed = static_cast<std::uint64_t>(seed);
  auvrl::eval::run_eval_request(request, std::cout);
  return 0;
}

/// `auvrl fastest`: how soon the vehicle could reach a scenario's way-point at all.
int run_fastest(int argc, const char* const* argv) {
  auvrl::tools::ArrivalSearchRequest request;
  request.vehicle_path = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
  std::int64_t seed = 1;
  auvrl::cli::CommandLine cli(
      "auvrl fastest",
      "Searches open-loop thrust commands (cross-entropy method, started from the PID\n"
      "baseline's) for the soonest arrival within 0.5 m of a scenario's way-point: what the\n"
      "plant allows, to compare the learned policy and the PID with. Writes DIR/commands.csv\n"
      "(auv_sim --open-loop format), summary.csv (the PID, and the commands with the PID\n"
      "holding after them, as the evaluation measures them), search.csv and trajectories/.");
  cli.option("scenario", &request.scenario, "test1|test2|fault|current");
  cli.option("out", &request.out_dir, "output directory (created)");
  cli.option("vehicle", &request.vehicle_path, "vehicle file");
  cli.option("iterations", &request.search.iterations, "search iterations");
  cli.option("population", &request.search.population, "samples per iteration");
  cli.option("elites", &request.search.elites, "best samples kept per iteration");
  cli.option("steps-per-segment", &request.search.steps_per_segment,
             "control steps each searched command holds");
  cli.option("stay-within", &request.search.stay_within_m,
             "count an arrival only if the vehicle then stays within this many metres for 3 s "
             "(default: arriving is enough)");
  cli.option("seed", &seed, "seed of the search's draws");
  if (!cli.parse(argc, argv)) return 0;
  if (seed < 0) throw auvrl::cli::UsageError("option --seed: expected a value >= 0");
  request.search.seed = static_cast<std::uint64_t>(seed);
  auvrl::tools::run_arrival_search_request(request, std::cout);
  return 0;
}

/// This executable's directory (where the other processes are built too).
std::string own_bin_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : exe.parent_path().string();
}

/// `auvrl train`: the whole training system, then evaluation, plots and report.
int run_train(int argc, const char* const* argv) {
  auvrl::launcher::TrainOptions options;
  options.source_dir = AUVRL_SOURCE_DIR;
  options.bin_dir = own_bin_dir();
  std::string preset = "fast", network = "private", resume_dir;
  bool no_eval = false;
  auvrl::cli::CommandLine cli(
      "auvrl train",
      "Trains a policy with the whole system (auv_sim per actor, N auv_actor, auv_learner,\n"
      "auv_logger; over LCM or DDS: transport: in the configuration, or --transport) in a\n"
      "private network namespace, shows progress, restarts crashed processes,\n"
      "stops cleanly on Ctrl-C, then fine-tunes the policy (finetune: in the configuration),\n"
      "evaluates it and the PID baseline, draws the plots and writes RUN/report.md.");
  cli.option("preset", &preset, "config/presets/NAME.yaml (paper or fast)");
  cli.option("config", &options.config_path, "a configuration file instead of a preset");
  cli.option("run-dir", &options.run_dir, "run directory (default runs/<preset>-<time>)");
  cli.option("resume", &resume_dir, "continue the stopped run in this directory");
  cli.option("actors", &options.actors,
             "exploration actors (default: run.actors, 0 = one per CPU)");
  cli.option("max-seconds", &options.max_train_s, "training budget, s (default: run.max_train_s)");
  cli.option("seed", &options.seed, "seed of the run (default: run.seed)");
  cli.option("finetune-iterations", &options.finetune_iterations,
             "fine-tuning iterations after training (default: finetune.iterations, 0 = none)");
  cli.flag("no-eval", &no_eval, "skip evaluation, plots and report");
  cli.option("network", &network,
             "private (default: own network namespace) or host (LCM on the host's network)");
  // Over the configuration's transport: section; recorded and passed to every process.
  auvrl::transport::TransportConfig cli_transport;
  auvrl::transport::add_transport_options(cli, cli_transport, &options.transport_args);
  if (!cli.parse(argc, argv)) return 0;
  if (network != "private" && network != "host") {
    throw auvrl::cli::UsageError("option --network: expected private or host");
  }
  options.evaluate = !no_eval;
  if (!resume_dir.empty()) {
    options.resume = true;
    options.run_dir = resume_dir;
  } else if (options.config_path.empty()) {
    options.config_path = std::string(AUVRL_CONFIG_DIR) + "/presets/" + preset + ".yaml";
  }
  const char* inside = std::getenv("AUVRL_IN_NETNS");
  if (network == "host" || (inside != nullptr && std::string(inside) == "1")) {
    if (inside == nullptr) auvrl::launcher::prepare_run_directory(options);
    return auvrl::launcher::run_training(options, std::cout);
  }
  // Prepare the run directory here, then run again inside a private network namespace whose
  // PID file the run directory keeps (lcm-spy and the log tools join it).
  auvrl::launcher::prepare_run_directory(options);
  const std::string netns = std::string(AUVRL_SOURCE_DIR) + "/scripts/netns.sh";
  std::vector<std::string> args = {
      netns,      "--pidfile",    options.run_dir + "/netns.pid", own_bin_dir() + "/auvrl", "train",
      "--resume", options.run_dir};
  if (options.actors >= 0) args.insert(args.end(), {"--actors", std::to_string(options.actors)});
  if (options.max_train_s >= 0) {
    args.insert(args.end(), {"--max-seconds", std::to_string(options.max_train_s)});
  }
  if (options.seed >= 0) args.insert(args.end(), {"--seed", std::to_string(options.seed)});
  if (options.finetune_iterations >= 0) {
    args.insert(args.end(), {"--finetune-iterations", std::to_string(options.finetune_iterations)});
  }
  if (no_eval) args.push_back("--no-eval");
  args.insert(args.end(), options.transport_args.begin(), options.transport_args.end());
  setenv("AUVRL_IN_NETNS", "1", 1);
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  execv(netns.c_str(), cargs.data());
  throw std::runtime_error("cannot run " + netns);
}

/// The first lines of docs/configuration.md.
constexpr const char* kConfigDocPreamble =
    "# Configuration reference\n\n"
    "Generated by `auvrl config-doc > docs/configuration.md` from the tables next to each\n"
    "configuration struct (common/config/table.hpp); the test `config_doc_current` fails when\n"
    "this file is stale. Each section is a top-level map of a run configuration\n"
    "(config/presets/*.yaml); unknown keys are errors. The keys of `learner:` are also\n"
    "auv_learner's flags, those of `task:` and `actor:` auv_actor's (`replay_capacity` is\n"
    "`--replay-capacity`, `scales.depth_m` is `--scales-depth-m`; a bool `key` has `--key`\n"
    "and `--no-key`). The last section is a vehicle file (config/vehicles/).\n";

/// `auvrl config-doc`: prints docs/configuration.md.
int run_config_doc(int argc, const char* const* argv) {
  auvrl::cli::CommandLine cli("auvrl config-doc",
                              "Prints the configuration reference (docs/configuration.md): "
                              "every section's keys, types, defaults, units and docs.");
  if (!cli.parse(argc, argv)) return 0;
  namespace config = auvrl::config;
  const std::vector<config::SectionDoc> sections = {
      config::section_doc(auvrl::task::task_table()),
      config::section_doc(auvrl::task::goal_schedule_table()),
      config::section_doc(auvrl::learner::learner_table()),
      config::section_doc(auvrl::agent::actor_table()),
      config::section_doc(auvrl::launcher::run_table()),
      config::section_doc(auvrl::launcher::finetune_table()),
      config::section_doc(auvrl::transport::transport_table()),
      auvrl::sim::vehicle_file_doc()};
  std::cout << config::render_markdown(sections, kConfigDocPreamble);
  return 0;
}

struct Subcommand {
  const char* name;
  const char* summary;
  int (*run)(int argc, const char* const* argv);
};

const Subcommand kSubcommands[] = {
    {"train", "train a policy with the whole system, then evaluate it (see --help)", run_train},
    {"eval", "evaluate a policy or the PID baseline on test1/test2/fault/current/suite", run_eval},
    {"fastest", "search open-loop commands for the soonest arrival the vehicle allows",
     run_fastest},
    {"config-doc", "print the configuration reference (docs/configuration.md)", run_config_doc},
};

void print_usage(std::ostream& out) {
  out << "usage: auvrl <command> [options]   (auvrl <command> --help for its options)\n\n"
         "commands:\n";
  for (const Subcommand& c : kSubcommands) {
    out << "  " << c.name << std::string(12 - std::string(c.name).size(), ' ') << c.summary << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(std::cerr);
    return 2;
  }
  const std::string command = argv[1];
  if (command == "--help" || command == "-h" || command == "help") {
    print_usage(std::cout);
    return 0;
  }
  for (const Subcommand& c : kSubcommands) {
    if (command != c.name) continue;
    try {
      // The subcommand sees its options with argv[0] = the command's name.
      return c.run(argc - 1, argv + 1);
    } catch (const auvrl::cli::UsageError& e) {
      std::cerr << "auvrl " << command << ": " << e.what() << '\n';
      return 2;
    } catch (const std::invalid_argument& e) {  // a bad request (missing or wrong option)
      std::cerr << "auvrl " << command << ": " << e.what() << '\n';
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "auvrl " << command << ": error: " << e.what() << '\n';
      return 1;
    }
  }
  std::cerr << "auvrl: unknown command '" << command << "'\n";
  print_usage(std::cerr);
  return 2;
}
