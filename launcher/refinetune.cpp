#include "launcher/refinetune.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "launcher/pipeline.hpp"
#include "launcher/run_config.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

/// The policy the run's evaluation named (eval/selected_policy.txt), else RUN/policy.nn.
std::string run_policy(const std::string& run_dir) {
  std::ifstream named(fs::path(run_dir) / "eval" / "selected_policy.txt");
  std::string path;
  if (named && std::getline(named, path) && fs::exists(path)) return path;
  return (fs::path(run_dir) / "policy.nn").string();
}

}  // namespace

int refinetune(const RefinetuneOptions& o, std::ostream& out) {
  const fs::path run_config = fs::path(o.run_dir) / "config.yaml";
  if (!fs::exists(run_config)) {
    throw std::invalid_argument(o.run_dir + " has no config.yaml: not an `auvrl train` run");
  }
  const std::string policy = o.policy_path.empty() ? run_policy(o.run_dir) : o.policy_path;
  if (!fs::exists(policy)) throw std::invalid_argument(policy + " not found");
  std::error_code ec;
  if (fs::exists(o.out_dir) && !fs::is_empty(o.out_dir, ec)) {
    throw std::invalid_argument(o.out_dir + " already exists and is not empty");
  }
  RunContext ctx;
  ctx.options.source_dir = o.source_dir;
  ctx.run_dir = o.out_dir;
  ctx.rc = read_run_config(run_config.string());
  if (!o.config_path.empty()) ctx.rc.finetune = read_run_config(o.config_path).finetune;
  if (o.iterations >= 0) ctx.rc.finetune.iterations = o.iterations;
  if (o.seed >= 0) ctx.rc.run.seed = static_cast<std::uint64_t>(o.seed);
  ctx.model = sim::load_vehicle_file(ctx.rc.vehicle_path);
  task::apply_vehicle(ctx.model.facts(), ctx.rc.task);
  fs::create_directories(fs::path(o.out_dir) / "processes");
  ctx.config_path = (fs::path(o.out_dir) / "config.yaml").string();
  fs::copy_file(run_config, ctx.config_path);
  if (!o.config_path.empty()) {
    fs::copy_file(o.config_path, fs::path(o.out_dir) / "finetune_config.yaml");
  }
  out << "auvrl finetune: " << policy << " (run " << o.run_dir << ") into " << o.out_dir << "\n";
  const std::string kept = finetune_if_configured(ctx, policy, out);
  const EvaluationResult evaluation = evaluate_stage(ctx, kept, out);
  report_stage(ctx, kept, evaluation, out);
  return 0;
}

}  // namespace auvrl::launcher
