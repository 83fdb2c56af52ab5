#include "launcher/telemetry.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

/// A number with `decimals` digits after the point (the files' fixed-point columns).
csv::Fixed fixed(double value, int decimals) { return {value, decimals}; }

const std::vector<std::string> kQuickEvalHeader = {"wall_s",
                                                   "policy_version",
                                                   "reached",
                                                   "episodes",
                                                   "mean_time_to_reach_s",
                                                   "mean_error_after_reach_m",
                                                   "max_time_ratio_to_pid",
                                                   "kept"};

/// Moves an existing quick_eval.csv whose header differs aside (quick_eval.old.csv).
const std::string& set_aside_old_quick_eval(const std::string& path) {
  if (!fs::exists(path)) return path;
  std::ifstream existing(path);
  std::string header;
  std::getline(existing, header);
  std::string expected;
  for (const auto& column : kQuickEvalHeader) expected += (expected.empty() ? "" : ",") + column;
  if (header != expected) {
    fs::rename(path, (fs::path(path).parent_path() / "quick_eval.old.csv").string());
  }
  return path;
}

}  // namespace

EpisodeSink::EpisodeSink(const std::string& path)
    : writer_(path,
              {"wall_s", "actor_id", "episode_id", "policy_version", "return", "length_steps",
               "success", "final_distance_m", "min_distance_m", "beta_m", "end_reason",
               "thrust_energy"},
              csv::Mode::kAppend) {}

void EpisodeSink::add(double wall_s, const auvrl_lcm::episode_report_t& e) {
  writer_.row(fixed(wall_s, 3), e.actor_id, e.episode_id, e.policy_version,
              fixed(e.episode_return, 4), e.length_steps, static_cast<int>(e.success),
              fixed(e.final_distance_m, 4), fixed(e.min_distance_m, 4), fixed(e.beta_m, 4),
              static_cast<int>(e.end_reason), fixed(e.thrust_energy, 4));
}

LearnerSink::LearnerSink(const std::string& path)
    : writer_(path,
              {"wall_s", "updates", "updates_per_s", "transitions_received", "transitions_per_s",
               "buffer_size", "critic_loss", "actor_loss", "mean_q", "episodes", "beta_m",
               "weights_published", "expert_share"},
              csv::Mode::kAppend) {}

void LearnerSink::add(double wall_s, const auvrl_lcm::learner_stats_t& s) {
  writer_.row(fixed(wall_s, 3), s.updates, fixed(s.updates_per_s, 1), s.transitions_received,
              fixed(s.transitions_per_s, 1), s.buffer_size, fixed(s.critic_loss, 6),
              fixed(s.actor_loss, 6), fixed(s.mean_q, 6), s.episodes, fixed(s.beta_m, 6),
              s.weights_published, fixed(s.expert_share, 6));
}

ProgressSink::ProgressSink(const std::string& path)
    : writer_(path,
              {"wall_s", "episodes", "success_rate", "beta_m", "env_steps_per_s", "updates_per_s",
               "best_suite_success"},
              csv::Mode::kAppend) {}

void ProgressSink::add(const ProgressRow& r) {
  writer_.row(fixed(r.wall_s, 1), r.episodes, fixed(r.success_rate, 3), fixed(r.beta_m, 3),
              fixed(r.env_steps_per_s, 0), fixed(r.updates_per_s, 0),
              fixed(r.best_suite_success, 0));
}

QuickEvalSink::QuickEvalSink(const std::string& path)
    : writer_(set_aside_old_quick_eval(path), kQuickEvalHeader, csv::Mode::kAppend) {}

void QuickEvalSink::add(double wall_s, std::int64_t version, const eval::ValidationScore& score,
                        bool kept) {
  const bool reached = score.reached > 0;
  const bool has_ratio = score.max_time_ratio < eval::ValidationScore::kNone;
  writer_.row(fixed(wall_s, 1), version, score.reached, score.episodes,
              fixed(reached ? score.mean_time_s : 0.0, 2),
              fixed(reached ? score.mean_hold_m : 0.0, 3),
              fixed(has_ratio ? score.max_time_ratio : 0.0, 3), kept);
  try {
    writer_.flush();
  } catch (const std::exception&) {
    // Reported by TrainingTelemetry::flush with the system's reason.
  }
}

FinetuneSink::FinetuneSink(const std::string& path)
    : writer_(path,
              {"iteration", "objective_s", "elapsed_s", "validation_reached",
               "validation_mean_time_s", "validation_hold_m", "validation_worst_time_ratio"}) {}

void FinetuneSink::add(int iteration, double objective_s, double elapsed_s,
                       const eval::ValidationScore* v) {
  writer_.cell(iteration).cell(objective_s).cell(elapsed_s);
  if (v != nullptr) {
    writer_.cell(v->reached).cell(v->mean_time_s).cell(v->mean_hold_m).cell(v->max_time_ratio);
  } else {
    writer_.empty().empty().empty().empty();
  }
  writer_.end_row();
}

void write_objective_terms(const std::string& path, const std::vector<ObjectiveTermsRow>& rows) {
  csv::Writer writer(path, {"controller", "objective_s", "arrival_s", "hold_s", "turn_s", "flip_s",
                            "energy_s", "smoothness_s", "lag_s"});
  for (const ObjectiveTermsRow& r : rows) {
    const tuning::ObjectiveTerms& t = r.terms;
    writer.row(r.controller, t.objective_s, t.arrival_s, t.hold_s, t.turn_s, t.flip_s, t.energy_s,
               t.smoothness_s, t.lag_s);
  }
  writer.flush();
}

void write_candidates(const std::string& path, const std::vector<CandidatesRow>& rows) {
  csv::Writer writer(
      path, {"candidate", "weights", "seed", "kept_iteration", "objective_s", "groups_passing",
             "groups", "behind_late", "behind_episodes", "chosen"});
  for (const CandidatesRow& r : rows) {
    writer.cell(r.candidate).cell(r.mean ? "mean" : "search");
    if (r.mean) {
      writer.empty().empty();
    } else {
      writer.cell(r.seed).cell(r.kept_iteration);
    }
    writer.row(r.objective_s, r.groups_passing, r.groups, r.behind_late, r.behind_episodes,
               r.chosen ? 1 : 0);
  }
  writer.flush();
}

TrainingTelemetry::TrainingTelemetry(const std::string& run_dir)
    : episodes((fs::path(run_dir) / "episodes.csv").string()),
      learner((fs::path(run_dir) / "learner.csv").string()),
      progress((fs::path(run_dir) / "progress.csv").string()),
      quick_eval((fs::path(run_dir) / "quick_eval.csv").string()),
      run_dir_(run_dir) {}

std::optional<std::string> TrainingTelemetry::flush() {
  // Disk full or run directory not writable: the run stops with the path named; the
  // checkpoints already written stay intact (the learner writes each to a new file and renames
  // it).
  for (csv::Writer* writer :
       {&progress.writer(), &episodes.writer(), &learner.writer(), &quick_eval.writer()}) {
    errno = 0;
    try {
      writer->flush();
    } catch (const std::exception&) {
      const int error = errno;
      return fmt::format(
          "cannot write {} ({}): disk full or run directory not writable; the last checkpoint in "
          "{} is kept",
          writer->path(), error != 0 ? std::strerror(error) : "write error",
          (fs::path(run_dir_) / "checkpoints").string());
    }
  }
  return std::nullopt;
}

double trained_before_s(const std::string& run_dir) {
  std::ifstream progress(fs::path(run_dir) / "progress.csv");
  std::string line, last;
  while (std::getline(progress, line)) {
    if (!line.empty() && line[0] != 'w') last = line;
  }
  return last.empty() ? 0.0 : std::atof(last.c_str());
}

}  // namespace auvrl::launcher
