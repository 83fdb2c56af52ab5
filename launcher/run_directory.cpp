#include "launcher/run_directory.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "launcher/launcher.hpp"
#include "launcher/run_config.hpp"
#include "launcher/training.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

std::string absolute_path(const std::string& path) {
  return path.empty() ? path : fs::absolute(path).lexically_normal().string();
}

bool directory_in_use(const std::string& dir) {
  std::error_code ec;
  return fs::exists(dir) && !fs::is_empty(dir, ec);
}

std::string run_timestamp() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%d-%H%M%S", std::localtime(&now));
  return text;
}

namespace {

/// Copies the configuration into the run directory with its vehicle made absolute (the one
/// given by --vehicle, else the file's own), so that every process reads the same vehicle
/// from the copy.
void copy_config(const std::string& config_path, const std::string& vehicle_override,
                 const fs::path& run_dir) {
  std::ifstream in(config_path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const RunConfig parsed = read_run_config(config_path);
  const std::string vehicle =
      fs::absolute(vehicle_override.empty() ? parsed.vehicle_path : vehicle_override)
          .lexically_normal()
          .string();
  std::ofstream out(run_dir / "config.yaml");
  out << "# Copied from " << fs::absolute(config_path).string() << " by auvrl train"
      << (vehicle_override.empty() ? "" : " --vehicle " + vehicle_override) << ".\n";
  const bool names_vehicle = std::any_of(
      lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("vehicle:", 0) == 0; });
  if (!names_vehicle) out << "vehicle: " << vehicle << "\n";
  for (const std::string& line : lines) {
    out << (line.rfind("vehicle:", 0) == 0 ? "vehicle: " + vehicle : line) << "\n";
  }
  if (!out) throw std::runtime_error("cannot write " + run_dir.string() + "/config.yaml");
}

/// README.txt: what each file of the run directory holds.
void write_readme(const std::string& run_dir) {
  std::ofstream howto(fs::path(run_dir) / "README.txt");
  howto << "auvrl run directory\n"
        << "  config.yaml       the configuration of this run\n"
        << "  command_line.yaml the settings the command line gave it (--resume keeps them)\n"
        << "  progress.csv      training progress (also on the terminal)\n"
        << "  episodes.csv      one row per episode; learner.csv: the learner's figures\n"
        << "  logs/             LCM event logs of all traffic (auv_log list logs/*.lcmlog)\n"
        << "  checkpoints/      learner checkpoints (auvrl train --resume " << run_dir << ")\n"
        << "  policy.nn         the last policy; policy_best.nn: the best by quick evaluation\n"
        << "  policy_average.nn the mean of the last learner.average_window_updates' actors\n"
           "                    (when set: the policy that goes on unless it flips more)\n"
        << "  policy_finetuned.nn, finetune.csv   the fine-tuned policy and its progress\n"
        << "  finetune_start.txt   the policy the fine-tuning started from (auvrl finetune\n"
           "                    --run-dir starts there again)\n"
        << "  objective_terms.csv   the fine-tuning's objective by price: PID, trained, kept\n"
        << "  candidates.csv, finetune_candidateK.csv   with finetune.candidates > 1: each\n"
           "                    search's (and their mean's) robustness groups, the one kept,\n"
           "                    and each search's progress\n"
        << "  quick_eval.csv    every quick evaluation (reached, mean time, hold error, worst\n"
           "                    time ratio to the PID's on the same way-points, kept)\n"
        << "  eval/, plots/, report.md   evaluation of the policy and the PID baseline\n"
        << "  processes/        each process's output\n"
        << "  snapshots/        reproducible runs: the learner's networks awaiting the quick\n"
           "                    evaluation (each is deleted once evaluated)\n"
        << "Watch the running system with lcm-spy: scripts/spy.sh " << run_dir << "\n";
}

}  // namespace

namespace {

constexpr const char* kCommandLineFile = "command_line.yaml";

/// The settings the command line gave a new run, so that --resume continues it the same way.
void write_command_line(const TrainOptions& o) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  if (o.actors >= 0) out << YAML::Key << "actors" << YAML::Value << o.actors;
  if (o.max_train_s >= 0) out << YAML::Key << "max_seconds" << YAML::Value << o.max_train_s;
  if (o.seed >= 0) out << YAML::Key << "seed" << YAML::Value << o.seed;
  if (o.reproducible) out << YAML::Key << "reproducible" << YAML::Value << true;
  if (o.max_updates >= 0) out << YAML::Key << "max_updates" << YAML::Value << o.max_updates;
  if (o.finetune_iterations >= 0) {
    out << YAML::Key << "finetune_iterations" << YAML::Value << o.finetune_iterations;
  }
  if (!o.transport_args.empty()) {
    out << YAML::Key << "transport_args" << YAML::Value << YAML::Flow << o.transport_args;
  }
  out << YAML::EndMap;
  std::ofstream file(fs::path(o.run_dir) / kCommandLineFile);
  file << "# The settings auvrl train's command line gave this run; --resume applies them again\n"
          "# unless it is given others.\n"
       << out.c_str() << "\n";
  if (!file) throw std::runtime_error("cannot write " + o.run_dir + "/" + kCommandLineFile);
}

/// --resume: the run's own command-line settings, where this command line gives none.
void restore_command_line(TrainOptions& o) {
  const fs::path path = fs::path(o.run_dir) / kCommandLineFile;
  if (!fs::exists(path)) return;  // a run from before this file, or given no settings
  try {
    const YAML::Node saved = YAML::LoadFile(path.string());
    if (!saved.IsMap()) throw std::runtime_error("not a map");
    if (o.actors < 0 && saved["actors"]) o.actors = saved["actors"].as<int>();
    if (o.max_train_s < 0 && saved["max_seconds"]) {
      o.max_train_s = saved["max_seconds"].as<double>();
    }
    if (o.seed < 0 && saved["seed"]) o.seed = saved["seed"].as<std::int64_t>();
    if (saved["reproducible"]) o.reproducible = o.reproducible || saved["reproducible"].as<bool>();
    if (o.max_updates < 0 && saved["max_updates"]) {
      o.max_updates = saved["max_updates"].as<std::int64_t>();
    }
    if (o.finetune_iterations < 0 && saved["finetune_iterations"]) {
      o.finetune_iterations = saved["finetune_iterations"].as<int>();
    }
    if (o.transport_args.empty() && saved["transport_args"]) {
      o.transport_args = saved["transport_args"].as<std::vector<std::string>>();
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what() +
                             " (the settings auvrl train's command line gave this run)");
  }
}

}  // namespace

std::optional<std::int64_t> command_line_seed(const std::string& run_dir) {
  TrainOptions saved;
  saved.run_dir = run_dir;
  restore_command_line(saved);
  if (saved.seed < 0) return std::nullopt;
  return saved.seed;
}

std::string prepare_run_directory(TrainOptions& o) {
  const std::string config_copy = (fs::path(o.run_dir) / "config.yaml").string();
  if (o.resume) {
    if (!fs::is_regular_file(config_copy)) {
      throw std::runtime_error("--resume " + o.run_dir + ": no config.yaml there (not a run)");
    }
    restore_command_line(o);
    return config_copy;
  }
  if (o.config_path.empty() || !fs::is_regular_file(o.config_path)) {
    throw std::runtime_error("configuration '" + o.config_path + "' not found");
  }
  // A broken configuration, or a reproducible run without a budget in updates, fails here,
  // before anything starts.
  RunConfig parsed = read_run_config(o.config_path);
  apply_train_options(o, parsed);
  check_reproducible_budget(parsed);
  if (o.run_dir.empty()) {
    o.run_dir = (fs::path(o.source_dir) / "runs" /
                 (fs::path(o.config_path).stem().string() + "-" + run_timestamp()))
                    .string();
  }
  if (fs::exists(fs::path(o.run_dir) / "config.yaml")) {
    throw std::runtime_error(o.run_dir + " already holds a run (use --resume to continue it)");
  }
  for (const char* sub : {"logs", "checkpoints", "eval", "plots", "processes"}) {
    fs::create_directories(fs::path(o.run_dir) / sub);
  }
  if (!o.vehicle_path.empty()) sim::load_vehicle_file(o.vehicle_path);  // fails here, early
  copy_config(o.config_path, o.vehicle_path, o.run_dir);
  write_command_line(o);
  write_readme(o.run_dir);
  return (fs::path(o.run_dir) / "config.yaml").string();
}

bool has_checkpoint_file(const std::string& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("checkpoint-", 0) == 0 && entry.path().extension() == ".ckpt") return true;
  }
  return false;
}

}  // namespace auvrl::launcher
