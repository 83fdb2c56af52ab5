// auvrl: the project's front command. Each subcommand parses its own options and calls the
// library that does the work (eval/evaluation.hpp for eval, tools/arrival_search.hpp for fastest,
// tuning/pid_tuning.hpp for tune-pid, tools/export/policy_export.hpp for export,
// launcher/mission_run.hpp for run, launcher/mission_replay.hpp for replay); adding one is adding
// a row to kSubcommands.
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "common/cli.hpp"
#include "common/dds_security.hpp"
#include "common/signature.hpp"
#include "common/task/task_yaml.hpp"
#include "common/transport_options.hpp"
#include "eval/evaluation.hpp"
#include "eval/mission_run.hpp"
#include "eval/robustness.hpp"
#include "launcher/config_doc.hpp"
#include "launcher/launcher.hpp"
#include "launcher/mission_replay.hpp"
#include "launcher/mission_run.hpp"
#include "launcher/refinetune.hpp"
#include "tools/arrival_search.hpp"
#include "tools/export/policy_export.hpp"
#include "tuning/pid_tuning.hpp"

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
      "suite (random way-points of the training region), all (those five).\n"
      "--scenario robustness runs the robustness suite instead (starts, far way-points, weak\n"
      "and dead thrusters, currents, sensor noise, a wrong model; --robustness-episodes per\n"
      "group, seed --seed) and writes DIR/robustness.csv and DIR/robustness_episodes.csv.\n"
      "With --mission FILE it runs that mission (config/missions/*.yaml, docs/missions.md)\n"
      "instead and writes DIR/mission.csv and DIR/trajectory.csv.");
  cli.option("policy", &request.policy_path, "policy network file (nn format)");
  cli.option("controller", &request.controller, "policy or pid");
  cli.option("scenario", &request.scenario, "test1|test2|fault|current|suite|all|robustness");
  cli.option("out", &request.out_dir, "output directory (created)");
  cli.custom_option(
      "vehicle",
      [&request](const std::string& path) {
        request.vehicle_path = path;
        request.vehicle_given = true;
      },
      request.vehicle_path, "vehicle file (with --mission: in place of the mission's vehicle:)",
      "FILE");
  cli.option("mission", &request.mission_path,
             "mission file: run it instead of the scenarios (docs/missions.md)");
  cli.option("layout", &request.layout,
             "paper|extended|extended_thrust (default: from the policy's inputs, 12+n / 17+n "
             "/ 17+2n)");
  auvrl::task::add_driving_aid_options(cli, request.driving);
  cli.option("seed", &seed, "seed of the suite's way-points and the vehicle resets");
  cli.check("seed", auvrl::cli::at_least(0));
  cli.option("suite-episodes", &request.suite_episodes, "way-points in the suite");
  cli.option("suite-trajectories", &request.suite_trajectories,
             "trajectory files for the first N suite episodes (-1: all)");
  cli.option("robustness-episodes", &request.robustness_episodes,
             "episodes per group of the robustness suite");
  cli.flag("with-pid", &request.robustness_with_pid,
           "robustness: also run the PID on the same episodes (DIR/pid/) and write "
           "DIR/robustness_comparison.md and .csv");
  cli.flag("facing-away-group", &request.robustness_facing_away,
           "robustness: add the group facing_away (way-points straight behind a start at rest; "
           "scored where the pipeline chooses among fine-tuning candidates, not one of the bar's)");
  if (!cli.parse(argc, argv)) return 0;
  request.seed = static_cast<std::uint64_t>(seed);
  if (!request.mission_path.empty()) {
    auvrl::eval::run_mission_request(request, std::cout);
  } else if (request.scenario == "robustness") {
    auvrl::eval::run_robustness_request(request, std::cout);
  } else {
    auvrl::eval::run_eval_request(request, std::cout);
  }
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
  cli.check("seed", auvrl::cli::at_least(0));
  if (!cli.parse(argc, argv)) return 0;
  request.search.seed = static_cast<std::uint64_t>(seed);
  auvrl::tools::run_arrival_search_request(request, std::cout);
  return 0;
}

/// `auvrl export`: a policy as a C99 header or an ONNX model.
int run_export(int argc, const char* const* argv) {
  auvrl::tools::ExportRequest request;
  request.vehicle_path = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
  request.onnx.script = std::string(AUVRL_SOURCE_DIR) + "/scripts/export_onnx.py";
  auvrl::cli::CommandLine cli(
      "auvrl export",
      "Writes a trained policy for use outside auvrl (docs/export.md): --format c, one\n"
      "self-contained C99 header (weights, auvrl_policy_act, auvrl_policy_build_state; needs\n"
      "only <math.h>); --format onnx, an ONNX model (input \"state\", output \"action\"),\n"
      "written by scripts/export_onnx.py with python3-onnx. Both document the state layout,\n"
      "every input's scale and every action's thruster.");
  cli.option("policy", &request.policy_path, "policy network file (nn format)");
  cli.option("format", &request.format, "c or onnx");
  cli.choices("format", {"c", "onnx"});
  cli.option("out", &request.out_path, "the header or model to write");
  cli.option("vehicle", &request.vehicle_path,
             "vehicle file: thruster names and count, maximum thrust");
  cli.option("layout", &request.layout,
             "paper|extended|extended_thrust (default: from the policy's inputs, 12+n / 17+n "
             "/ 17+2n)");
  auvrl::task::add_driving_aid_options(cli, request.driving);
  if (!cli.parse(argc, argv)) return 0;
  auvrl::tools::run_export_request(request, std::cout);
  return 0;
}

/// `auvrl tune-pid`: the PID baseline's gains for one vehicle, into the file beside it.
int run_tune_pid(int argc, const char* const* argv) {
  auvrl::tuning::PidTuningRequest request;
  auvrl::tuning::PidTuningConfig& c = request.config;
  std::int64_t seed = 1;
  auvrl::cli::CommandLine cli(
      "auvrl tune-pid",
      "Tunes the PID baseline's gains for a vehicle: a seeded random local search from the\n"
      "compiled defaults on validation way-points of its own (some with T1 at 10 %, some in a\n"
      "0.3 m/s current), scored as the evaluation scores: mean time to reach + 20 x mean hold\n"
      "error + 500 x missed fraction + 0.02 x mean energy. Writes the gains beside the vehicle\n"
      "file (X.yaml -> X.pid.yaml), which every PID for that vehicle then uses.");
  cli.option("vehicle", &request.vehicle_path, "vehicle file (required)");
  cli.option("seed", &seed, "seed of the validation way-points and the search");
  cli.check("seed", auvrl::cli::at_least(0));
  cli.option("iterations", &c.iterations, "perturbations tried");
  cli.option("episodes", &c.episodes, "validation way-points");
  cli.option("threads", &c.threads, "episodes run at once (0: one per CPU)");
  cli.option("out", &request.out_path, "gains file (default: beside the vehicle file)");
  if (!cli.parse(argc, argv)) return 0;
  request.seed = static_cast<std::uint64_t>(seed);
  request.command_line = "auvrl tune-pid";
  for (int i = 1; i < argc; ++i) request.command_line += std::string(" ") + argv[i];
  auvrl::tuning::run_pid_tuning_request(request, std::cout);
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
  cli.option("preset", &preset, "config/presets/NAME.yaml (paper, fast or robust)");
  cli.option("config", &options.config_path, "a configuration file instead of a preset");
  cli.option("vehicle", &options.vehicle_path,
             "vehicle file (default: the configuration's vehicle:); every process, the PID, "
             "the evaluation and the report take the vehicle's facts from it");
  cli.option("run-dir", &options.run_dir, "run directory (default runs/<preset>-<time>)");
  cli.option("resume", &resume_dir, "continue the stopped run in this directory");
  cli.option("actors", &options.actors,
             "exploration actors (default: run.actors, 0 = one per CPU)");
  cli.option("max-seconds", &options.max_train_s, "training budget, s (default: run.max_train_s)");
  cli.option("seed", &options.seed, "seed of the run (default: run.seed)");
  cli.flag("reproducible", &options.reproducible,
           "reproducible mode (run.reproducible): the same seed, configuration and build give "
           "byte-identical checkpoints, policies and evaluation; the budget counts updates "
           "(learner.max_updates or --max-updates), --max-seconds is not used");
  cli.option("max-updates", &options.max_updates,
             "end of training after this many updates (default: learner.max_updates, 0 = "
             "never)");
  cli.check("max-updates", auvrl::cli::at_least(0));
  cli.option("finetune-iterations", &options.finetune_iterations,
             "fine-tuning iterations after training (default: finetune.iterations, 0 = none)");
  cli.flag("no-eval", &no_eval, "skip evaluation, plots and report");
  cli.option("bin-dir", &options.bin_dir,
             "where auv_sim, auv_actor, auv_learner and auv_logger are (default: beside auvrl)");
  cli.option("network", &network,
             "private (default: own network namespace) or host (LCM on the host's network)");
  cli.choices("network", {"private", "host"});
  // Over the configuration's transport: section; recorded and passed to every process.
  auvrl::transport::TransportConfig cli_transport;
  auvrl::transport::add_transport_options(cli, cli_transport, &options.transport_args);
  if (!cli.parse(argc, argv)) return 0;
  options.evaluate = !no_eval;
  if (!resume_dir.empty() && !options.vehicle_path.empty()) {
    throw auvrl::cli::UsageError("--vehicle names a new run's vehicle; --resume " + resume_dir +
                                 " continues with the vehicle of its config.yaml");
  }
  if (!resume_dir.empty()) {
    options.resume = true;
    options.run_dir = resume_dir;
  } else if (options.config_path.empty()) {
    options.config_path = std::string(AUVRL_CONFIG_DIR) + "/presets/" + preset + ".yaml";
  }
  return auvrl::launcher::start_training(options, network == "host", std::cout);
}

/// `auvrl run`: a mission flown by auv_controller on the real-time simulator.
int run_mission_command(int argc, const char* const* argv) {
  auvrl::launcher::MissionRunOptions options;
  options.source_dir = AUVRL_SOURCE_DIR;
  options.bin_dir = own_bin_dir();
  std::string network = "private";
  auvrl::cli::CommandLine cli(
      "auvrl run",
      "Flies a mission with auv_controller (a policy or the PID) on auv_sim --realtime, with\n"
      "auv_logger, in a private network namespace: shows its progress, injects its timed\n"
      "thruster faults live, stops when the controller exits, the time limit passes or on\n"
      "Ctrl-C, then writes RUN/trajectory.csv, waypoints.csv, vehicle.csv, plots/ and report.md.\n"
      "Exit: 0 complete, 1 error, 2 refused at start, 3 aborted by the supervisor, 4 time limit,\n"
      "130 stopped.");
  cli.option("mission", &options.mission_path, "mission file (config/missions/*.yaml)");
  cli.require("mission");
  cli.option("policy", &options.policy_path, "policy network file (the nn format)");
  cli.option("controller", &options.controller, "policy (with --policy) or pid");
  cli.option("trust-key", &options.trust_key,
             "Ed25519 public key: fly only a mission and policy signed by its private key "
             "(auv_controller --trust-key; auvrl sign)");
  cli.choices("controller", {"policy", "pid"});
  cli.option("vehicle", &options.vehicle_path,
             "vehicle file (default: the mission's vehicle:, else config/vehicles/nessie7.yaml)");
  cli.option("speed", &options.speed, "the vehicle runs this many times faster than real time");
  cli.option("run-dir", &options.run_dir, "run directory (default runs/mission-<name>-<time>)");
  cli.option("network", &network,
             "private (default: own network namespace) or host (LCM on the host's network)");
  cli.choices("network", {"private", "host"});
  cli.option("bin-dir", &options.bin_dir,
             "where auv_sim, auv_controller and auv_logger are (default: beside auvrl)");
  // Set by auvrl run itself when it runs again inside the network namespace.
  cli.flag("prepared", &options.prepared, "the run directory is prepared already (internal)");
  cli.app().get_option("--prepared")->group("");
  if (!cli.parse(argc, argv)) return 0;
  return auvrl::launcher::start_mission_run(options, network == "host", std::cout);
}

/// `auvrl replay`: a mission run's log played back by lcm-logplayer and recorded again.
int run_replay_command(int argc, const char* const* argv) {
  auvrl::launcher::MissionReplayOptions options;
  options.source_dir = AUVRL_SOURCE_DIR;
  options.bin_dir = own_bin_dir();
  std::string network = "private";
  auvrl::cli::CommandLine cli(
      "auvrl replay",
      "Plays an `auvrl run` directory's LCM log back with lcm-logplayer in a private network\n"
      "namespace, records it as auvrl run does live, and writes OUT/trajectory.csv,\n"
      "waypoints.csv, vehicle.csv, events.csv, plots/ and report.md, each CSV compared with the\n"
      "run's. Exit: 0 written, 1 error, 2 refused at start, 130 stopped.");
  cli.option("run-dir", &options.run_dir, "the auvrl run directory to replay");
  cli.require("run-dir");
  cli.option("out", &options.out_dir, "output directory (default RUN/replay-<time>)");
  cli.option("speed", &options.speed, "playback speed multiplier (lcm-logplayer --speed)");
  cli.option("mission", &options.mission_path, "the run's mission (default RUN/mission.yaml)");
  cli.option("vehicle", &options.vehicle_path, "the run's vehicle (default RUN/vehicle.yaml)");
  cli.option("player", &options.player, "the log player");
  cli.option("network", &network,
             "private (default: own network namespace) or host (LCM on the host's network)");
  cli.choices("network", {"private", "host"});
  // Set by auvrl replay itself when it runs again inside the network namespace.
  cli.flag("prepared", &options.prepared, "the output directory is prepared already (internal)");
  cli.app().get_option("--prepared")->group("");
  if (!cli.parse(argc, argv)) return 0;
  return auvrl::launcher::start_mission_replay(options, network == "host", std::cout);
}

/// `auvrl finetune`: a trained run's policy fine-tuned again and evaluated.
int run_finetune_command(int argc, const char* const* argv) {
  auvrl::launcher::RefinetuneOptions options;
  options.source_dir = AUVRL_SOURCE_DIR;
  auvrl::cli::CommandLine cli(
      "auvrl finetune",
      "Fine-tunes a trained run's policy again (evolution strategies, the finetune: section of\n"
      "the run's configuration or of --config), then evaluates the kept policy and the PID on\n"
      "the scenarios and the robustness suite, into OUT (finetune.csv, policy_finetuned.nn,\n"
      "eval/, report.md). Runs in this process: no transport.");
  cli.option("run-dir", &options.run_dir, "the trained run (its config.yaml and policy)");
  cli.require("run-dir");
  cli.option("out", &options.out_dir, "output directory (created)");
  cli.require("out");
  cli.option("config", &options.config_path, "take the finetune: section from this file");
  cli.option("policy", &options.policy_path,
             "the policy to fine-tune (default: the one the run's fine-tuning started from, "
             "else the one its evaluation used)");
  cli.option("iterations", &options.iterations, "fine-tuning iterations (default: the config's)");
  cli.option("seed", &options.seed, "seed of the fine-tuning's way-points (default: the run's)");
  cli.option("candidates", &options.candidates,
             "searches, each with its own seed; the one passing the most robustness groups at\n"
             "finetune.selection_seed is kept (default: the config's)");
  cli.check("candidates", auvrl::cli::at_least(1));
  cli.flag("keep-iterates", &options.keep_iterates,
           "also write the weights validated every 10 iterations (and the last) to\n"
           "OUT/iterates/iteration_NNN.nn (candidate K's to OUT/iterates_candidateK/), to\n"
           "evaluate the fine-tuning's course");
  if (!cli.parse(argc, argv)) return 0;
  return auvrl::launcher::refinetune(options, std::cout);
}

/// `auvrl config-doc`: prints docs/configuration.md.
int run_config_doc(int argc, const char* const* argv) {
  auvrl::cli::CommandLine cli("auvrl config-doc",
                              "Prints the configuration reference (docs/configuration.md): "
                              "every section's keys, types, defaults, units and docs.");
  if (!cli.parse(argc, argv)) return 0;
  std::cout << auvrl::launcher::configuration_reference();
  return 0;
}

int run_keygen(int argc, const char* const* argv) {
  std::string prefix;
  auvrl::cli::CommandLine cli("auvrl keygen",
                              "Writes a new Ed25519 key pair: PREFIX.key (private, mode 0600) and "
                              "PREFIX.pub (public: give it to auv_controller --trust-key).");
  cli.option("out", &prefix, "PREFIX of the two files");
  cli.require("out");
  if (!cli.parse(argc, argv)) return 0;
  auvrl::signature::generate_key_pair(prefix + ".key", prefix + ".pub");
  std::cout << "auvrl keygen: " << prefix << ".key (keep it private), " << prefix << ".pub\n";
  return 0;
}

/// auvrl sign and auvrl verify: a key (--key_option) and files; `action` handles each file and
/// says what it did.
int run_key_and_files(
    int argc, const char* const* argv, const char* program, const char* summary,
    const char* key_option, const char* key_help,
    const std::function<std::string(const std::string& file, const std::string& key)>& action) {
  std::string key;
  std::vector<std::string> files;
  auvrl::cli::CommandLine cli(program, summary);
  cli.option(key_option, &key, key_help);
  cli.require(key_option);
  cli.positionals("files", &files, "the files");
  if (!cli.parse(argc, argv)) return 0;
  for (const std::string& f : files) std::cout << program << ": " << action(f, key) << "\n";
  return 0;
}

int run_sign(int argc, const char* const* argv) {
  return run_key_and_files(argc, argv, "auvrl sign",
                           "Signs policy or mission files with an Ed25519 private key: FILE.sig "
                           "beside each (docs/deployment.md).",
                           "key", "the private key (PEM; auvrl keygen)",
                           [](const std::string& file, const std::string& key) {
                             return auvrl::signature::sign_file(file, key);
                           });
}

int run_verify(int argc, const char* const* argv) {
  return run_key_and_files(argc, argv, "auvrl verify",
                           "Checks files against their FILE.sig with an Ed25519 public key, as "
                           "auv_controller --trust-key does; exit 1 at the first that fails.",
                           "trust-key", "the public key (PEM)",
                           [](const std::string& file, const std::string& key) {
                             auvrl::signature::verify_file(file, key);
                             return file + ": signed by " + key;
                           });
}

int run_dds_policy(int argc, const char* const* argv) {
  std::string role, not_before = "2026-01-01T00:00:00", not_after;
  int system_domain = 0;
  std::vector<std::string> subjects, documents;
  auvrl::cli::CommandLine cli(
      "auvrl dds-policy",
      "Prints a DDS Security document, unsigned (scripts/pki.sh signs it): `governance`, or "
      "`permissions --role ROLE --subject S...` (one grant per subject) or `roles`.");
  cli.positionals("document", &documents, "governance, permissions or roles");
  cli.option("role", &role,
             "permissions: the role (learner, actor, simulator, controller, "
             "logger, operator, observer)");
  cli.repeatable("subject", &subjects,
                 "permissions: a participant's certificate subject, e.g. CN=actor-0,O=auvrl "
                 "(repeat the flag for each)");
  cli.option("system-domain", &system_domain,
             "governance: the system's DDS domain (the lockstep pairs' are the others)");
  cli.option("not-before", &not_before, "permissions: valid from (YYYY-MM-DDTHH:MM:SS)");
  cli.option("not-after", &not_after, "permissions: valid until (YYYY-MM-DDTHH:MM:SS)");
  if (!cli.parse(argc, argv)) return 0;
  const std::string document = documents.size() == 1 ? documents[0] : "";
  if (document == "governance") {
    std::cout << auvrl::transport::dds_governance_xml(system_domain);
  } else if (document == "roles") {
    for (const auto& r : auvrl::transport::dds_roles()) {
      std::cout << r.name << "\t" << r.description << "\n";
    }
  } else if (document == "permissions") {
    if (role.empty() || subjects.empty() || not_after.empty()) {
      throw auvrl::cli::UsageError("permissions needs --role, --subject and --not-after");
    }
    std::cout << auvrl::transport::dds_permissions_xml(auvrl::transport::dds_role(role), subjects,
                                                       not_before, not_after);
  } else {
    throw auvrl::cli::UsageError("expected governance, permissions or roles, got '" + document +
                                 "'");
  }
  return 0;
}

struct Subcommand {
  const char* name;
  const char* summary;
  int (*run)(int argc, const char* const* argv);
};

const Subcommand kSubcommands[] = {
    {"train", "train a policy with the whole system, then evaluate it (see --help)", run_train},
    {"run", "fly a mission with auv_controller on the real-time simulator (see --help)",
     run_mission_command},
    {"replay", "play a mission run's log back and write its files and plots again (see --help)",
     run_replay_command},
    {"eval",
     "evaluate a policy or the PID baseline on test1/test2/fault/current/suite or a mission",
     run_eval},
    {"finetune", "fine-tune a trained run's policy again and evaluate it (see --help)",
     run_finetune_command},
    {"fastest", "search open-loop commands for the soonest arrival the vehicle allows",
     run_fastest},
    {"export", "write a policy as a C99 header or an ONNX model (docs/export.md)", run_export},
    {"tune-pid", "tune the PID baseline's gains for a vehicle (X.yaml -> X.pid.yaml)",
     run_tune_pid},
    {"config-doc", "print the configuration reference (docs/configuration.md)", run_config_doc},
    {"keygen", "write an Ed25519 key pair for signing policies and missions", run_keygen},
    {"dds-policy", "print a DDS Security governance or permissions document (scripts/pki.sh)",
     run_dds_policy},
    {"sign", "sign policy or mission files (FILE.sig) for auv_controller --trust-key", run_sign},
    {"verify", "check files against their signatures with a public key", run_verify},
};

}  // namespace

int main(int argc, char** argv) {
  auvrl::cli::CommandLine cli("auvrl", "The project's front command (auvrl COMMAND --help).");
  for (const Subcommand& c : kSubcommands) cli.subcommand(c.name, c.summary).pass_on_rest();
  cli.require_subcommand();
  std::string command = "auvrl";
  try {
    if (!cli.parse(argc, argv)) return 0;
    command += " " + cli.chosen();
    const auto rest = cli.subcommand(cli.chosen()).rest();  // argv[0] = "auvrl <command>"
    for (const Subcommand& c : kSubcommands) {
      if (cli.chosen() == c.name) return c.run(rest.argc(), rest.argv());
    }
  } catch (const auvrl::cli::UsageError& e) {
    std::cerr << command << ": " << e.what() << '\n';
    return 2;
  } catch (const std::invalid_argument& e) {  // a bad request (missing or wrong option)
    std::cerr << command << ": " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << command << ": error: " << e.what() << '\n';
    return 1;
  }
  return 2;
}
