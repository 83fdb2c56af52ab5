#include "launcher/pipeline.hpp"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "agent/controller.hpp"
#include "agent/pid_controller.hpp"
#include "agent/pid_gains.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "common/process.hpp"
#include "common/signals.hpp"
#include "eval/ranking.hpp"
#include "launcher/format.hpp"
#include "tuning/candidate_selection.hpp"
#include "tuning/policy_finetune.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

/// The policy of the two with fewer failures on the selection draw; `preferred` on a tie or
/// when they cannot be counted.
std::string fewer_failures(const std::string& preferred, const std::string& other,
                           const SelectionDraw& draw, std::ostream& out) {
  try {
    const std::vector<std::uint8_t> preferred_bytes = nn::read_file(preferred);
    const std::vector<std::uint8_t> other_bytes = nn::read_file(other);
    if (preferred_bytes == other_bytes) return preferred;  // the same weights
    const nn::Mlp preferred_net = nn::network_from_bytes(preferred_bytes, 1);
    const nn::Mlp other_net = nn::network_from_bytes(other_bytes, 1);
    // The two counts at once: training has ended, and the CPUs are free.
    auto other_count = std::async(std::launch::async, [&] {
      return tuning::suite_failures(draw.model, draw.task, draw.seed, other_net);
    });
    const int preferred_failures =
        tuning::suite_failures(draw.model, draw.task, draw.seed, preferred_net);
    const int other_failures = other_count.get();
    const bool switch_over = other_failures < preferred_failures;
    out << fmt::format(
        "auvrl train: selected {}: flips and blow-ups in the robustness suite at seed {}: {} {}, "
        "{} {}\n",
        fs::path(switch_over ? other : preferred).filename().string(), draw.seed,
        fs::path(preferred).filename().string(), preferred_failures,
        fs::path(other).filename().string(), other_failures);
    return switch_over ? other : preferred;
  } catch (const std::exception& e) {
    out << "auvrl train: failures not counted (" << e.what() << "); selected " << preferred << "\n";
    return preferred;
  }
}

}  // namespace

namespace {

/// policy.nn or policy_best.nn, as select_policy says without the average.
std::optional<std::string> select_trained(const std::string& run_dir, const BestPolicyKeeper& best,
                                          const SelectionDraw& draw, std::ostream& out) {
  const std::string last = (fs::path(run_dir) / "policy.nn").string();
  if (!fs::exists(best.best_path())) {
    if (!fs::exists(last)) return std::nullopt;
    return last;
  }
  // The last policy may be worse than the best seen: compare them on the quick evaluation.
  bool best_above = true;
  try {
    best_above = best.best_ranks_above(last);
  } catch (const std::exception&) {
    return best.best_path();  // the last one cannot be read
  }
  const std::string preferred = best_above ? best.best_path() : last;
  return fewer_failures(preferred, best_above ? last : best.best_path(), draw, out);
}

}  // namespace

std::optional<std::string> select_policy(const std::string& run_dir, const BestPolicyKeeper& best,
                                         const SelectionDraw& draw, bool average,
                                         std::ostream& out) {
  const std::optional<std::string> trained = select_trained(run_dir, best, draw, out);
  const fs::path mean = fs::path(run_dir) / kAveragePolicyFile;
  if (!average || !fs::is_regular_file(mean)) return trained;
  if (!trained) return mean.string();
  return fewer_failures(mean.string(), *trained, draw, out);
}

namespace {

std::string describe(const eval::ValidationScore& v) {
  return fmt::format(
      "{}/{} reached, mean {:.2f} s, hold {:.2f} m, worst time ratio to the PID {:.2f}, energy "
      "{:.1f}, smoothness {:.4f}",
      v.reached, v.episodes, v.mean_time_s, v.mean_hold_m, v.max_time_ratio, v.mean_energy,
      v.mean_smoothness);
}

/// How the fine-tuning keeps its weights: by its own prices when it prices thrust, else by
/// reach, hold and mean time (eval::Ranking).
eval::Ranking finetune_ranking(const tuning::FinetuneConfig& config, double max_hold_m) {
  eval::Ranking ranking{max_hold_m, false, std::nullopt};
  if (config.energy_weight > 0.0 || config.smoothness_weight > 0.0) {
    ranking.prices =
        eval::Ranking::Prices{config.hold_weight, config.energy_weight, config.smoothness_weight};
  }
  return ranking;
}

/// The best validated weights of a fine-tuning so far.
struct FinetuneBest {
  eval::ValidationScore score;
  std::optional<nn::Mlp> net;
  int iteration = 0;
};

/// The objective by price, on the fine-tuning's own way-points (episodes), of the PID baseline,
/// the trained policy and the kept weights (when kept).
std::vector<ObjectiveTermsRow> objective_terms_rows(
    const FinetuneStageInput& in, const std::vector<tuning::FinetuneEpisode>& episodes,
    const nn::Mlp& start, const std::optional<nn::Mlp>& kept) {
  agent::PidController pid(in.model, agent::pid_gains_for(in.model).gains);
  std::vector<ObjectiveTermsRow> rows;
  rows.push_back(
      {"pid", tuning::mean_objective_terms(in.model, in.task, pid, episodes, in.config)});
  for (const auto& [name, net] : {std::pair<const char*, const nn::Mlp*>{"start", &start},
                                  {"finetuned", kept ? &*kept : nullptr}}) {
    if (net == nullptr) continue;
    agent::PolicyController policy(*net, tuning::finetune_driving_task(in.task));  // as searched
    rows.push_back(
        {name, tuning::mean_objective_terms(in.model, in.task, policy, episodes, in.config)});
  }
  return rows;
}

/// objective_terms.csv in the run directory (objective_terms_rows) and the same as a table to
/// out: why a search keeps what it keeps, what each price weighs. A report only: a failure is
/// said and the stage's policy stays.
void report_objective_terms(const FinetuneStageInput& in,
                            const std::vector<tuning::FinetuneEpisode>& episodes,
                            const nn::Mlp& start, const std::optional<nn::Mlp>& kept,
                            std::ostream& out) {
  const std::string path = (fs::path(in.run_dir) / "objective_terms.csv").string();
  std::vector<ObjectiveTermsRow> rows;
  try {
    rows = objective_terms_rows(in, episodes, start, kept);
    write_objective_terms(path, rows);
  } catch (const std::exception& e) {
    out << "auvrl train: could not write " << path << ": " << e.what() << "\n";
    if (rows.empty()) return;
  }
  out << "  objective by price on its way-points [s]: arrival + hold + turn + flip + energy + "
         "smoothness + lag = objective\n";
  for (const ObjectiveTermsRow& r : rows) {
    const tuning::ObjectiveTerms& t = r.terms;
    out << fmt::format(
        "    {:<9} {:.2f} + {:.2f} + {:.2f} + {:.2f} + {:.2f} + {:.2f} + {:.2f} = {:.2f}\n",
        r.controller, t.arrival_s, t.hold_s, t.turn_s, t.flip_s, t.energy_s, t.smoothness_s,
        t.lag_s, t.objective_s);
  }
}

/// One search of the fine-tuning: its seed, the best validated weights (none: not kept) and
/// what the search did; or the searches' mean (finetune.average_candidates), with the first
/// search's way-points and its own objective there.
struct CandidateSearch {
  std::uint64_t seed = 0;
  FinetuneBest best;
  tuning::FinetuneResult result;
  bool mean = false;  ///< the mean of the searches' kept weights, not a search
};

/// A file of candidate `index` (from 0) in the run directory: the first candidate's under the
/// name itself (as with one search), candidate i + 1's with "_candidate<i + 1>" before the
/// extension.
fs::path candidate_path(const FinetuneStageInput& in, const std::string& stem,
                        const std::string& extension, int index) {
  const std::string suffix = index == 0 ? "" : fmt::format("_candidate{}", index + 1);
  return fs::path(in.run_dir) / (stem + suffix + extension);
}

/// Seconds from `since` to now.
double seconds_since(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

/// Runs candidate `index`'s search from `start` (validated as `before`), its progress to its
/// finetune.csv, validating every validate_every iterations and at the end, or where
/// search_past_cap ends it.
CandidateSearch search_candidate(const FinetuneStageInput& in, const nn::Mlp& start,
                                 const eval::ValidationScore& before, int index,
                                 std::ostream& out) {
  constexpr int validate_every = 10;
  const eval::Ranking ranking = finetune_ranking(in.config, in.max_hold_m);
  const std::uint64_t seed = tuning::candidate_seed(in.seed, index);
  FinetuneBest best{before, std::nullopt, 0};
  FinetuneSink csv(candidate_path(in, "finetune", ".csv", index).string());
  // Made once, before the search: a folder that cannot be made fails before its work.
  const fs::path iterates = candidate_path(in, "iterates", "", index);
  if (in.keep_iterates) fs::create_directories(iterates);
  const std::string label = in.config.candidates == 1
                                ? std::string()
                                : fmt::format(" candidate {}/{}", index + 1, in.config.candidates);
  bool past_cap = false;  // the search ends after this iteration (search_past_cap)
  const auto progress = [&](const tuning::FinetuneIteration& it, const nn::Mlp& weights) {
    if (const auto why = search_past_cap(in.config, in.reproducible, it.elapsed_s, it.iteration,
                                         seconds_since(in.training_start), index > 0)) {
      out << "auvrl train: fine-tuning" << label << ": " << *why << "\n";
      past_cap = true;
    }
    if (it.iteration % validate_every != 0 && it.iteration != in.config.iterations && !past_cap) {
      csv.add(it.iteration, it.objective, it.elapsed_s, nullptr);
      return;
    }
    if (in.keep_iterates) {
      nn::save_network_file((iterates / fmt::format("iteration_{:03d}.nn", it.iteration)).string(),
                            weights);
    }
    const eval::ValidationScore score =
        in.validation.evaluate(weights, tuning::search_threads(in.config));
    csv.add(it.iteration, it.objective, it.elapsed_s, &score);
    if (eval::ranks_above(score, best.score, ranking)) best = {score, weights, it.iteration};
    out << fmt::format(
        "auvrl train: fine-tuning{} {}/{}  objective {:.3f} s  validation {}/{} mean {:.2f} s  "
        "elapsed {}\n",
        label, it.iteration, in.config.iterations, it.objective, score.reached, score.episodes,
        score.mean_time_s, format_duration(it.elapsed_s));
  };
  tuning::FinetuneResult result =
      tuning::finetune_policy(in.model, in.task, start, in.config, seed, progress,
                              [&] { return past_cap || signals::stop_requested(); });
  try {
    csv.writer().flush();
  } catch (const std::exception&) {
    out << "auvrl train: could not write " << csv.writer().path() << "\n";
  }
  return CandidateSearch{seed, std::move(best), std::move(result)};
}

/// The candidates' searches, one after another, until all are done, Ctrl-C, a search that fails
/// after the first (said; the choice is made among those done) or no_further_candidate.
std::vector<CandidateSearch> run_candidate_searches(const FinetuneStageInput& in,
                                                    const nn::Mlp& start,
                                                    const eval::ValidationScore& before,
                                                    std::ostream& out) {
  const auto searches_start = std::chrono::steady_clock::now();
  std::vector<CandidateSearch> searches;
  for (int index = 0; index < in.config.candidates; ++index) {
    if (index > 0 && signals::stop_requested()) break;
    if (const auto why =
            no_further_candidate(in.config, in.reproducible, seconds_since(in.training_start),
                                 seconds_since(searches_start), index)) {
      out << "auvrl train: fine-tuning: " << *why << "\n";
      break;
    }
    try {
      searches.push_back(search_candidate(in, start, before, index, out));
    } catch (const std::exception& e) {
      if (searches.empty()) throw;
      out << "auvrl train: fine-tuning candidate " << index + 1 << " failed: " << e.what()
          << "; choosing among the first " << searches.size() << "\n";
      break;
    }
  }
  return searches;
}

/// The searches' mean as a further choice (finetune.average_candidates): the mean of the
/// weights the searches kept, validated as they were. None unless every search kept weights,
/// or where the mean does not rank above the trained policy (`before`) on the validation
/// way-points, as a search's weights must to be kept.
std::optional<CandidateSearch> mean_of_searches(const FinetuneStageInput& in,
                                                const std::vector<CandidateSearch>& searches,
                                                const eval::ValidationScore& before,
                                                std::ostream& out) {
  std::vector<const nn::Mlp*> kept;
  for (const CandidateSearch& c : searches) {
    if (!c.best.net) return std::nullopt;  // the trained policy: nothing of its own to average
    kept.push_back(&*c.best.net);
  }
  nn::Mlp mean = nn::mean_of(kept);
  const eval::ValidationScore score =
      in.validation.evaluate(mean, tuning::search_threads(in.config));
  if (!eval::ranks_above(score, before, finetune_ranking(in.config, in.max_hold_m))) {
    out << "auvrl train: fine-tuning: the searches' mean scores no better than the trained "
           "policy on the validation way-points: not a choice\n";
    return std::nullopt;
  }
  CandidateSearch c{0, {score, std::move(mean), 0}, searches.front().result, true};
  agent::PolicyController policy(*c.best.net, tuning::finetune_driving_task(in.task));
  c.result.best_objective =
      tuning::mean_objective_terms(in.model, in.task, policy, c.result.episodes, in.config)
          .objective_s;
  return c;
}

/// Scores each choice at the selection seed (tuning::SuiteSelector), says each, and returns the
/// scores with their candidates.csv rows.
std::vector<tuning::CandidateScore> score_candidates(const FinetuneStageInput& in,
                                                     const std::vector<CandidateSearch>& choices,
                                                     const nn::Mlp& start,
                                                     std::vector<CandidatesRow>& rows,
                                                     std::ostream& out) {
  const tuning::SuiteSelector selector(in.model, in.task, in.config.selection_seed,
                                       eval::kRobustnessEpisodesPerGroup,
                                       tuning::search_threads(in.config));
  std::vector<tuning::CandidateScore> scores;
  for (const CandidateSearch& c : choices) {
    const tuning::CandidateScore score = selector.score(c.best.net ? *c.best.net : start);
    scores.push_back(score);
    const int number = static_cast<int>(rows.size()) + 1;
    rows.push_back({number, c.seed, c.best.iteration, c.result.best_objective, score.groups_passing,
                    selector.groups(), score.behind_late, score.behind_episodes, false, c.mean});
    const std::string who =
        c.mean ? fmt::format("the mean of candidates 1-{}", number - 1)
               : fmt::format("candidate {}/{} (seed {})", number, in.config.candidates, c.seed);
    out << fmt::format(
        "auvrl train: fine-tuning {}: objective {:.3f} s, {} of {} robustness groups at seed {}, "
        "late on {} of {} way-points straight behind\n",
        who, c.result.best_objective, score.groups_passing, selector.groups(),
        in.config.selection_seed, score.behind_late, score.behind_episodes);
  }
  return scores;
}

/// Runs the candidates' searches and returns the one to keep: with one searched, it; with more,
/// the one whose kept weights (or the start, where a search kept none) pass the most criteria at
/// the selection seed (tuning::choose_candidate; candidates.csv has each), or their mean where
/// finetune.average_candidates asks for it and tuning::keep_mean keeps it. Scored after the
/// searches, so that a run that searches one spends nothing on the choice.
CandidateSearch search_candidates(const FinetuneStageInput& in, const nn::Mlp& start,
                                  const eval::ValidationScore& before, std::ostream& out) {
  std::vector<CandidateSearch> choices = run_candidate_searches(in, start, before, out);
  if (choices.size() == 1) return std::move(choices.front());  // nothing to choose between
  const std::size_t searches = choices.size();
  if (in.config.average_candidates) {
    if (auto mean = mean_of_searches(in, choices, before, out)) choices.push_back(std::move(*mean));
  }
  std::vector<CandidatesRow> rows;
  const std::vector<tuning::CandidateScore> scores =
      score_candidates(in, choices, start, rows, out);
  std::size_t chosen = tuning::choose_candidate(
      std::vector<tuning::CandidateScore>(scores.begin(), scores.begin() + searches));
  if (choices.size() > searches && tuning::keep_mean(scores.back(), scores[chosen])) {
    chosen = searches;
  }
  rows[chosen].chosen = true;
  const std::string path = (fs::path(in.run_dir) / "candidates.csv").string();
  try {
    write_candidates(path, rows);
  } catch (const std::exception& e) {
    out << "auvrl train: could not write " << path << ": " << e.what() << "\n";
  }
  out << "auvrl train: fine-tuning: "
      << (choices[chosen].mean ? std::string("the searches' mean")
                               : fmt::format("candidate {}", chosen + 1))
      << " chosen\n";
  return std::move(choices[chosen]);
}

}  // namespace

std::string finetune_stage(const FinetuneStageInput& in, const std::string& start_path,
                           std::ostream& out) {
  const nn::Mlp start = nn::network_from_bytes(nn::read_file(start_path), 1);
  out << fmt::format(
      "auvrl train: fine-tuning {} (evolution strategies, {} iterations of {} policies on {} "
      "way-points{})\n",
      start_path, in.config.iterations, 2 * in.config.pairs, in.config.episodes,
      in.config.candidates == 1 ? "" : fmt::format("; {} candidates", in.config.candidates));
  const eval::ValidationScore before =
      in.validation.evaluate(start, tuning::search_threads(in.config));
  const CandidateSearch search = search_candidates(in, start, before, out);
  const FinetuneBest& best = search.best;
  out << fmt::format("auvrl train: fine-tuned: objective {:.3f} -> {:.3f} s\n",
                     search.result.start_objective, search.result.best_objective)
      << "  validation before: " << describe(before) << "\n";
  if (!best.net) {
    out << "  not kept: no fine-tuned weights scored better on the validation way-points\n";
    report_objective_terms(in, search.result.episodes, start, best.net, out);
    return start_path;
  }
  const std::string tuned_path = (fs::path(in.run_dir) / "policy_finetuned.nn").string();
  nn::save_network_file(tuned_path, *best.net);
  out << "  validation after:  " << describe(best.score)
      << (search.mean ? std::string(" (the searches' mean)")
                      : fmt::format(" (iteration {})", best.iteration))
      << "\n"
      << "  kept: " << tuned_path << "\n";
  report_objective_terms(in, search.result.episodes, start, best.net, out);
  return tuned_path;
}

namespace {

/// Writes RUN/finetune_start.txt naming start_path (relative when inside the run directory).
void record_finetune_start(const std::string& run_dir, const std::string& start_path,
                           std::ostream& out) {
  const fs::path path = fs::path(run_dir) / kFinetuneStartFile;
  const fs::path start = fs::absolute(start_path).lexically_normal();
  const fs::path relative = start.lexically_relative(fs::absolute(run_dir).lexically_normal());
  const bool inside = !relative.empty() && *relative.begin() != "..";
  std::ofstream file(path);
  file << (inside ? relative : start).string() << "\n";
  file.flush();
  if (!file) out << "auvrl train: could not write " << path.string() << "\n";
}

/// Whether the next of `done` equal pieces of work (done_s for them) ends past limit_s (when > 0)
/// on a clock now at elapsed_s: the projection both time limits of the fine-tuning make.
bool next_ends_past(double limit_s, double elapsed_s, double done_s, int done) {
  return limit_s > 0 && elapsed_s + done_s / done > limit_s;
}

}  // namespace

std::optional<std::string> no_further_candidate(const tuning::FinetuneConfig& config,
                                                bool reproducible, double training_s,
                                                double searches_s, int done) {
  if (done < 1 || done >= config.candidates || reproducible) return std::nullopt;
  // The share of a search that must fit, projected as the search caps project their iterations.
  const double fraction = config.candidate_min_fraction;
  if (!next_ends_past(config.candidates_within_s, training_s, fraction * searches_s, done)) {
    return std::nullopt;
  }
  const double pace_s = searches_s / done;
  const std::string searched =
      fmt::format("{} of {} candidates searched after {:.1f} s of training", done,
                  config.candidates, training_s);
  if (fraction >= 1.0) {
    return fmt::format(
        "{}; another would end at about {:.1f} s, past finetune.candidates_within_s ({:g} s): "
        "choosing among these",
        searched, training_s + pace_s, config.candidates_within_s);
  }
  return fmt::format(
      "{}; finetune.candidate_min_fraction ({:g}) of another would end at about {:.1f} s, past "
      "finetune.candidates_within_s ({:g} s): choosing among these",
      searched, fraction, training_s + fraction * pace_s, config.candidates_within_s);
}

std::optional<std::string> search_past_cap(const tuning::FinetuneConfig& config, bool reproducible,
                                           double search_s, int done, double training_s,
                                           bool further_candidate) {
  if (reproducible || done < 1 || done >= config.iterations) return std::nullopt;
  const bool past_search_cap = next_ends_past(config.max_search_s, search_s, search_s, done);
  const bool past_candidates_limit =
      further_candidate && config.candidate_min_fraction < 1.0 &&
      next_ends_past(config.candidates_within_s, training_s, search_s, done);
  if (!past_search_cap && !past_candidates_limit) return std::nullopt;  // the usual case
  const std::string ended = fmt::format("ended after iteration {} of {} at {:.1f} s of searching",
                                        done, config.iterations, search_s);
  if (past_search_cap) {
    return fmt::format(
        "{}; the next would end at about {:.1f} s, past finetune.max_search_s ({:g} s)", ended,
        search_s + search_s / done, config.max_search_s);
  }
  return fmt::format(
      "{}; the next would end at about {:.1f} s of training, past "
      "finetune.candidates_within_s ({:g} s)",
      ended, training_s + search_s / done, config.candidates_within_s);
}

std::optional<std::string> policy_named_in(const std::string& run_dir, const std::string& record) {
  std::ifstream file(fs::path(run_dir) / record);
  std::string named;
  if (!file || !std::getline(file, named) || named.empty()) return std::nullopt;
  const fs::path path = fs::path(named).is_absolute() ? fs::path(named) : fs::path(run_dir) / named;
  if (!fs::is_regular_file(path)) return std::nullopt;
  return path.string();
}

std::optional<std::string> finetune_start(const std::string& run_dir) {
  return policy_named_in(run_dir, kFinetuneStartFile);
}

std::string finetune_if_configured(const RunContext& ctx, const std::string& policy_path,
                                   std::ostream& out, bool keep_iterates,
                                   std::chrono::steady_clock::time_point training_start) {
  if (ctx.rc.finetune.iterations <= 0) return policy_path;
  record_finetune_start(ctx.run_dir, policy_path, out);
  // The quick evaluation's way-points, and half as many again facing a random heading.
  const eval::QuickEvaluator validation(ctx.model, ctx.rc.task, ctx.rc.run.best_eval_suite,
                                        ctx.rc.run.best_eval_suite / 2);
  try {
    return finetune_stage({ctx.model, ctx.rc.task, ctx.rc.finetune, ctx.rc.run.seed, validation,
                           ctx.rc.run.best_eval_max_hold_m, ctx.run_dir, keep_iterates,
                           ctx.rc.run.reproducible, training_start},
                          policy_path, out);
  } catch (const std::exception& e) {
    // The trained policy stays: a failed fine-tuning (a full disk, say) loses nothing.
    out << "auvrl train: fine-tuning failed: " << e.what() << "; keeping " << policy_path << "\n";
    return policy_path;
  }
}

EvaluationResult evaluate_stage(const RunContext& ctx, const std::string& policy_path,
                                std::ostream& out) {
  out << "auvrl train: evaluating " << policy_path << " and the PID baseline\n";
  const fs::path eval_dir = fs::path(ctx.run_dir) / "eval";
  eval::EvaluationConfig config;
  config.task = ctx.rc.task;
  const std::vector<eval::Scenario> all = eval::parse_scenarios("all");
  const nn::Mlp policy_net = nn::network_from_bytes(nn::read_file(policy_path), 1);
  agent::PolicyController policy(policy_net, ctx.rc.task);
  EvaluationResult result;
  result.policy_rows =
      eval::run_evaluation(ctx.model, config, policy, all, (eval_dir / "policy").string());
  eval::EvalRequest pid_request;
  pid_request.controller = "pid";
  eval::EvaluationConfig pid_config = config;
  auto pid = eval::make_eval_controller(pid_request, ctx.model, pid_config);
  result.pid_rows =
      eval::run_evaluation(ctx.model, pid_config, *pid, all, (eval_dir / "pid").string());
  std::ofstream(fs::path(ctx.run_dir) / kSelectedPolicyFile) << policy_path << "\n";
  try {
    const eval::RobustnessResult p =
        eval::run_robustness(ctx.model, config, policy, eval::kRobustnessEpisodesPerGroup,
                             config.seed, (eval_dir / "policy").string());
    const eval::RobustnessResult r =
        eval::run_robustness(ctx.model, pid_config, *pid, eval::kRobustnessEpisodesPerGroup,
                             config.seed, (eval_dir / "pid").string());
    result.robustness = eval::compare_robustness(p.groups, r.groups);
    result.robustness_policy_s = p.elapsed_s;
    result.robustness_pid_s = r.elapsed_s;
    eval::write_robustness_comparison(
        eval_dir.string(), result.robustness,
        eval::paired_margins(p.rows, r.rows, config.seed, config.reach_radius_m));
    out << fmt::format(
        "auvrl train: robustness suite: {} episodes each, policy {:.1f} s, PID {:.1f} s\n",
        p.rows.size(), p.elapsed_s, r.elapsed_s);
  } catch (const std::exception& e) {
    // The scenarios' evaluation stands: the report names the missing robustness files.
    out << "auvrl train: robustness suite failed: " << e.what() << "\n";
    result.robustness.clear();
  }
  return result;
}

void report_stage(const RunContext& ctx, const std::string& policy_path,
                  const EvaluationResult& result, std::ostream& out) {
  const std::string plot = ctx.options.source_dir + "/scripts/plot_run.py";
  if (fs::exists(plot) && fs::exists("/usr/bin/python3")) {
    process::ChildProcess plotter({"/usr/bin/python3", plot, ctx.run_dir},
                                  (fs::path(ctx.run_dir) / "processes" / "plots.log").string());
    const int status = plotter.wait_for_exit(std::chrono::minutes(5));
    if (status != 0) out << "auvrl train: plotting failed (see " << plotter.log_path() << ")\n";
  }
  out << "\nlearned policy (" << policy_path << "):\n"
      << eval::format_summary_table(result.policy_rows) << "\nPID baseline:\n"
      << eval::format_summary_table(result.pid_rows);
  if (!result.robustness.empty()) {
    std::string failing;
    int passing = 0;
    for (const eval::GroupComparison& c : result.robustness) {
      if (c.passes()) {
        ++passing;
      } else {
        failing += (failing.empty() ? "" : ", ") + c.policy.group;
      }
    }
    out << fmt::format("\nrobustness suite against the PID: {} of {} groups pass the bar{}{}\n",
                       passing, result.robustness.size(), failing.empty() ? "" : "; not: ", failing)
        << "  (table: " << (fs::path(ctx.run_dir) / "eval" / "robustness_comparison.md").string()
        << ")\n";
  }
  out << "\nreport: " << (fs::path(ctx.run_dir) / "report.md").string() << "\n";
}

}  // namespace auvrl::launcher
