// The stages that run in process: the run directory, the processes' command lines, and the
// evaluation stage (the scenarios and the robustness suite of the policy and the PID).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "common/listening_lines.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "launcher/launcher.hpp"
#include "launcher/pipeline.hpp"
#include "launcher/refinetune.hpp"
#include "launcher/run_directory.hpp"
#include "launcher/training.hpp"
#include "roles_fixture.hpp"
#include "run_files.hpp"
#include "tuning/candidate_selection.hpp"

namespace auvrl::launcher {
namespace {

namespace fs = std::filesystem;

bool has(const std::vector<std::string>& argv, const std::vector<std::string>& run) {
  return std::search(argv.begin(), argv.end(), run.begin(), run.end()) != argv.end();
}

/// A new run directory tmp/name for the fast preset, as `auvrl train` prepares it; a seed >= 0
/// as if the command line gave it (command_line.yaml).
TrainOptions fast_run_directory(const fs::path& tmp, const std::string& name = "run",
                                std::int64_t seed = -1) {
  TrainOptions options;
  options.config_path = std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml";
  options.run_dir = (tmp / name).string();
  options.seed = seed;
  prepare_run_directory(options);
  return options;
}

/// A fast-preset run directory of seed 4 whose policy.nn is the committed policy (what
/// `auvrl finetune` starts from): the run's options.
TrainOptions run_with_committed_policy(const fs::path& tmp) {
  const TrainOptions options = fast_run_directory(tmp, "run", 4);
  fs::copy_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn",
                fs::path(options.run_dir) / "policy.nn");
  return options;
}

/// `auvrl finetune` of a run_with_committed_policy run in tmp into tmp/again: `candidates`
/// searches of `iterations` each.
RefinetuneOptions refinetune_committed_policy(const fs::path& tmp, int iterations, int candidates) {
  RefinetuneOptions o;
  o.run_dir = run_with_committed_policy(tmp).run_dir;
  o.out_dir = (tmp / "again").string();
  o.iterations = iterations;
  o.candidates = candidates;
  return o;
}

/// Writes the fast preset to `path` (test_support::write_preset_copy) with the first line of
/// finetune key `key` set to `value`; false when the preset has no such line.
bool write_fast_preset_with(const fs::path& path, const std::string& key,
                            const std::string& value) {
  const std::string prefix = "  " + key + ": ";
  bool edited = false;
  test_support::write_preset_copy(AUVRL_CONFIG_DIR, "fast", path.string(), [&](std::string& line) {
    if (edited || line.rfind(prefix, 0) != 0) return;
    line = prefix + value;
    edited = true;
  });
  return edited;
}

/// What the choice knows of each row of a candidates.csv.
std::vector<tuning::CandidateScore> candidate_scores(
    const std::vector<std::map<std::string, std::string>>& rows) {
  std::vector<tuning::CandidateScore> scores;
  for (const auto& row : rows) {
    scores.push_back({std::stoi(row.at("groups_passing")), std::stoi(row.at("behind_late")),
                      std::stoi(row.at("behind_episodes"))});
  }
  return scores;
}

/// The row the pipeline must choose among two searches (rows 0 and 1) and, when there is a
/// third row, their mean: tuning::choose_candidate, then tuning::keep_mean.
std::size_t expected_choice(const std::vector<tuning::CandidateScore>& scores) {
  const std::size_t search = tuning::choose_candidate({scores[0], scores[1]});
  return scores.size() == 3u && tuning::keep_mean(scores[2], scores[search]) ? 2 : search;
}

/// The policy an output directory's evaluation names (eval/selected_policy.txt).
std::string evaluated_policy(const fs::path& out_dir) {
  std::ifstream selected(out_dir / "eval" / "selected_policy.txt");
  std::string evaluated;
  std::getline(selected, evaluated);
  return evaluated;
}

TEST(RunDirectoryTest, ANewRunGetsItsFoldersAndAConfigCopyWithAnAbsoluteVehicle) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_rundir_");
  TrainOptions options;
  options.config_path = std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml";
  options.run_dir = (tmp / "run").string();
  const std::string config = prepare_run_directory(options);
  EXPECT_EQ(config, (tmp / "run" / "config.yaml").string());
  for (const char* sub : {"logs", "checkpoints", "eval", "plots", "processes"}) {
    EXPECT_TRUE(fs::is_directory(tmp / "run" / sub)) << sub;
  }
  EXPECT_TRUE(fs::exists(tmp / "run" / "README.txt"));
  std::ifstream in(config);
  std::string line;
  bool vehicle_absolute = false;
  while (std::getline(in, line)) {
    if (line.rfind("vehicle: ", 0) == 0) vehicle_absolute = line.substr(9, 1) == "/";
  }
  EXPECT_TRUE(vehicle_absolute);
  read_run_config(config);  // the copy reads
  // A second new run there is refused; --resume takes it.
  EXPECT_THROW(prepare_run_directory(options), std::runtime_error);
  options.resume = true;
  EXPECT_EQ(prepare_run_directory(options), config);
  options.run_dir = (tmp / "none").string();
  EXPECT_THROW(prepare_run_directory(options), std::runtime_error);
}

TEST(RunDirectoryTest, TheSeedTheCommandLineGaveIsKept) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_rundir_");
  EXPECT_EQ(command_line_seed(fast_run_directory(tmp).run_dir), std::nullopt);
  const TrainOptions seeded = fast_run_directory(tmp, "seeded", 4);
  EXPECT_EQ(command_line_seed(seeded.run_dir), std::optional<std::int64_t>(4));
  std::ofstream(tmp / "seeded" / "command_line.yaml") << "seed: [";
  try {
    command_line_seed(seeded.run_dir);
    FAIL() << "a broken command_line.yaml read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("command_line.yaml"), std::string::npos) << e.what();
  }
}

TEST(RunDirectoryTest, OnlyFinishedCheckpointsCount) {
  const fs::path dir = test_support::make_temp_dir("auvrl_ckpt_");
  EXPECT_FALSE(has_checkpoint_file(dir.string()));
  std::ofstream(dir / "checkpoint-100.ckpt.tmp") << "x";
  EXPECT_FALSE(has_checkpoint_file(dir.string()));
  std::ofstream(dir / "checkpoint-100.ckpt") << "x";
  EXPECT_TRUE(has_checkpoint_file(dir.string()));
  EXPECT_FALSE(has_checkpoint_file((dir / "missing").string()));
}

// The evaluation stage of `auvrl train` on the committed policy: the scenarios and the
// robustness suite for both controllers, and the comparison table the report includes.
TEST(EvaluateStageTest, ThePolicyAndThePidOnTheScenariosAndTheRobustnessSuite) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_evalstage_");
  const TrainOptions options = fast_run_directory(tmp);
  const RunContext ctx = load_run_context(options);
  std::ostringstream out;
  const EvaluationResult result =
      evaluate_stage(ctx, std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn", out);
  EXPECT_EQ(result.policy_rows.size(), 104u);  // four tests and the 100-way-point suite
  EXPECT_EQ(result.pid_rows.size(), 104u);
  ASSERT_EQ(result.robustness.size(), 25u) << out.str();
  EXPECT_EQ(result.robustness[0].policy.controller, "policy");
  EXPECT_EQ(result.robustness[0].reference.controller, "pid");
  EXPECT_EQ(result.robustness[0].policy.episodes, 20);
  EXPECT_GT(result.robustness_policy_s, 0.0);
  EXPECT_GT(result.robustness_pid_s, 0.0);
  for (const char* file : {"eval/policy/summary.csv", "eval/policy/robustness.csv",
                           "eval/policy/robustness_episodes.csv", "eval/pid/robustness.csv",
                           "eval/pid/robustness_episodes.csv", "eval/robustness_comparison.md",
                           "eval/robustness_comparison.csv"}) {
    EXPECT_TRUE(fs::exists(tmp / "run" / file)) << file;
  }
  // The comparison, then the margins with their intervals.
  std::ifstream comparison(tmp / "run" / "eval/robustness_comparison.md");
  const std::string text((std::istreambuf_iterator<char>(comparison)),
                         std::istreambuf_iterator<char>());
  EXPECT_LT(text.find("groups pass every criterion"), text.find("How sure each criterion is"))
      << text;
  EXPECT_NE(text.find("How sure each criterion is"), std::string::npos) << text;
  EXPECT_NE(out.str().find("robustness suite: 500 episodes each"), std::string::npos) << out.str();
}

// auvrl finetune: a trained run's policy fine-tuned again into a directory of its own and
// evaluated there; an output directory in use is refused.
TEST(RefinetuneTest, FineTunesARunsPolicyAgainAndEvaluatesIt) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_refinetune_");
  const TrainOptions options = fast_run_directory(tmp);
  fs::copy_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn", tmp / "run" / "policy.nn");
  RefinetuneOptions o;
  o.run_dir = options.run_dir;
  o.out_dir = (tmp / "again").string();
  o.iterations = 2;
  o.keep_iterates = true;
  std::ostringstream out;
  ASSERT_EQ(refinetune(o, out), 0) << out.str();
  // The last iteration is validated, so kept: the committed policy's shape, other weights.
  const fs::path iterate = tmp / "again" / "iterates" / "iteration_002.nn";
  ASSERT_TRUE(fs::exists(iterate));
  EXPECT_FALSE(fs::exists(tmp / "again" / "iterates" / "iteration_001.nn"));
  const nn::Mlp start =
      nn::network_from_bytes(nn::read_file((tmp / "run" / "policy.nn").string()), 1);
  const nn::Mlp second = nn::network_from_bytes(nn::read_file(iterate.string()), 1);
  EXPECT_EQ(second.params().size(), start.params().size());
  EXPECT_NE(second.params(), start.params());
  EXPECT_NE(out.str().find("fine-tuning " + options.run_dir + "/policy.nn"), std::string::npos)
      << out.str();
  for (const char* file : {"config.yaml", "finetune.csv", "eval/selected_policy.txt",
                           "eval/robustness_comparison.md", "objective_terms.csv"}) {
    EXPECT_TRUE(fs::exists(tmp / "again" / file)) << file;
  }
  // The objective by price: the PID's, the trained policy's and, when kept, the fine-tuned
  // weights' (two iterations do not beat the committed policy on the validation way-points).
  std::ifstream terms(tmp / "again" / "objective_terms.csv");
  std::vector<std::string> controllers;
  for (std::string line; std::getline(terms, line);) {
    controllers.push_back(line.substr(0, line.find(',')));
  }
  std::vector<std::string> expected{"controller", "pid", "start"};
  if (out.str().find("  kept: ") != std::string::npos) expected.push_back("finetuned");
  EXPECT_EQ(controllers, expected) << out.str();
  EXPECT_NE(out.str().find("objective by price on its way-points"), std::string::npos) << out.str();
  std::ostringstream again;
  EXPECT_THROW(refinetune(o, again), std::invalid_argument);
  o.out_dir = (tmp / "other").string();
  o.run_dir = (tmp / "none").string();
  EXPECT_THROW(refinetune(o, again), std::invalid_argument);
}

// The run's fine-tuning records the policy it started from, relative to the run directory (so
// the run can be moved), and `auvrl finetune` without --policy starts from it, not from the
// fine-tuned policy the evaluation used: with the run's settings and seed the search repeats
// the run's own. A record naming no file is passed over.
TEST(RefinetuneTest, StartsFromThePolicyTheRunsFineTuningStartedFrom) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_refinetune_");
  const TrainOptions options = fast_run_directory(tmp);
  const std::string start = (tmp / "run" / "policy_best.nn").string();
  fs::copy_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn", start);
  RunContext ctx = load_run_context(options, ContextUse::kAfterTraining);
  ctx.rc.finetune.iterations = 2;
  std::ostringstream trained;
  finetune_if_configured(ctx, start, trained, false);
  EXPECT_EQ(test_support::read_text(tmp / "run" / kFinetuneStartFile), "policy_best.nn\n");
  fs::rename(tmp / "run", tmp / "moved");
  // The evaluation named another policy (other weights), as a run's does after its fine-tuning.
  const std::string evaluated = (tmp / "moved" / "policy_finetuned_elsewhere.nn").string();
  nn::Mlp other =
      nn::network_from_bytes(nn::read_file((tmp / "moved" / "policy_best.nn").string()), 1);
  other.params() *= 0.9f;
  nn::save_network_file(evaluated, other);
  std::ofstream(tmp / "moved" / "eval" / "selected_policy.txt") << evaluated << "\n";
  ASSERT_EQ(finetune_start((tmp / "moved").string()), (tmp / "moved" / "policy_best.nn").string());

  RefinetuneOptions o;
  o.run_dir = (tmp / "moved").string();
  o.out_dir = (tmp / "again").string();
  o.iterations = 2;
  std::ostringstream out;
  ASSERT_EQ(refinetune(o, out), 0) << out.str();
  EXPECT_NE(out.str().find("auvrl finetune: " + (tmp / "moved" / "policy_best.nn").string()),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("the policy the run's fine-tuning started from"), std::string::npos);
  // Each iteration's objective (the second column), the same in both searches.
  const auto objectives = [](const fs::path& csv) {
    std::vector<std::string> column;
    std::ifstream in(csv);
    for (std::string line; std::getline(in, line);) {
      const std::size_t from = line.find(',') + 1;
      column.push_back(line.substr(from, line.find(',', from) - from));
    }
    return column;
  };
  const std::vector<std::string> first = objectives(tmp / "moved" / "finetune.csv");
  ASSERT_EQ(first.size(), 3u);  // the header and two iterations
  EXPECT_EQ(objectives(tmp / "again" / "finetune.csv"), first);
  // Outside the new directory, its record is absolute.
  EXPECT_EQ(test_support::read_text(tmp / "again" / kFinetuneStartFile),
            (tmp / "moved" / "policy_best.nn").string() + "\n");

  // Without the file it names, the evaluation's policy.
  fs::remove(tmp / "moved" / "policy_best.nn");
  EXPECT_EQ(finetune_start((tmp / "moved").string()), std::nullopt);
  o.out_dir = (tmp / "third").string();
  std::ostringstream third;
  ASSERT_EQ(refinetune(o, third), 0) << third.str();
  EXPECT_NE(third.str().find("the policy the run's evaluation used"), std::string::npos)
      << third.str();
  EXPECT_NE(third.str().find("auvrl finetune: " + evaluated), std::string::npos) << third.str();
}

// objective_terms.csv is a report: when it cannot be written the stage says so and goes on,
// the fine-tuning's result as it would be otherwise.
TEST(RefinetuneTest, AnObjectiveTableThatCannotBeWrittenLosesNothing) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_refinetune_");
  const TrainOptions options = fast_run_directory(tmp);
  const std::string policy = (tmp / "run" / "policy.nn").string();
  fs::copy_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn", policy);
  RunContext ctx = load_run_context(options, ContextUse::kAfterTraining);
  ctx.rc.finetune.iterations = 2;
  ctx.run_dir = (tmp / "stage").string();
  fs::create_directories(tmp / "stage" / "objective_terms.csv");  // a folder: not writable
  std::ostringstream out;
  const std::string kept = finetune_if_configured(ctx, policy, out, false);
  EXPECT_NE(out.str().find("could not write " + ctx.run_dir + "/objective_terms.csv"),
            std::string::npos)
      << out.str();
  EXPECT_EQ(out.str().find("fine-tuning failed"), std::string::npos) << out.str();
  EXPECT_TRUE(kept == policy || kept == ctx.run_dir + "/policy_finetuned.nn") << kept;
  EXPECT_TRUE(fs::exists(kept));
  EXPECT_TRUE(fs::exists(tmp / "stage" / "finetune.csv"));
}

// An asynchronous run starts a further candidate only when, at the pace of those done, it ends
// within finetune.candidates_within_s of training; a reproducible run, or no limit, runs them all.
TEST(CandidatesWithinTest, AFurtherSearchOnlyWhenItEndsWithinTheLimit) {
  tuning::FinetuneConfig config;
  config.candidates = 3;
  config.candidates_within_s = 58;
  // 30 s of training, one search of 16 s: the next would end at 46 s.
  EXPECT_FALSE(no_further_candidate(config, false, 30, 16, 1));
  // 47 s, one search of 17 s: 64 s.
  const auto why = no_further_candidate(config, false, 47, 17, 1);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("1 of 3 candidates"), std::string::npos) << *why;
  EXPECT_NE(why->find("finetune.candidates_within_s (58 s)"), std::string::npos) << *why;
  // The pace is the mean of the searches done: two in 30 s, 40 s so far, the third at 55 s.
  EXPECT_FALSE(no_further_candidate(config, false, 40, 30, 2));
  EXPECT_TRUE(no_further_candidate(config, false, 44, 30, 2));
  // The first always runs; all done: nothing to skip. Reproducible, or no limit: never skipped.
  EXPECT_FALSE(no_further_candidate(config, false, 100, 0, 0));
  EXPECT_FALSE(no_further_candidate(config, false, 100, 50, 3));
  EXPECT_FALSE(no_further_candidate(config, true, 47, 17, 1));
  config.candidates_within_s = 0;
  EXPECT_FALSE(no_further_candidate(config, false, 470, 170, 1));
  // The searches' cap is each search's own (search_past_cap): it stops none from starting.
  config.max_search_s = 20;
  EXPECT_FALSE(no_further_candidate(config, false, 30, 15, 1));
}

// With finetune.candidate_min_fraction below 1, a further candidate starts when that share of
// it ends within finetune.candidates_within_s, and the log says which share.
TEST(CandidatesWithinTest, APartOfAFurtherSearchIsEnoughWithAMinimumFraction) {
  tuning::FinetuneConfig config;
  config.candidates = 2;
  config.candidates_within_s = 55;
  // 47 s of training, one search of 14 s: a whole one would end at 61 s.
  EXPECT_TRUE(no_further_candidate(config, false, 47, 14, 1));
  config.candidate_min_fraction = 0.5;
  // Half of it ends at 54 s: it starts.
  EXPECT_FALSE(no_further_candidate(config, false, 47, 14, 1));
  // 50 s: half would end at 57 s.
  const auto why = no_further_candidate(config, false, 50, 14, 1);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("finetune.candidate_min_fraction (0.5) of another would end at about 57.0 s"),
            std::string::npos)
      << *why;
  EXPECT_FALSE(no_further_candidate(config, true, 50, 14, 1));
}

// A further candidate started on a share of it (finetune.candidate_min_fraction below 1) ends
// once its next iteration would end past finetune.candidates_within_s of training; the first
// search is never cut there (a longer TD3 phase asked for keeps its search), nor any search with
// the fraction at 1, nor a reproducible run's.
TEST(MaxSearchTest, AFurtherCandidateEndsByTheCandidatesLimit) {
  tuning::FinetuneConfig config;
  config.iterations = 72;
  config.candidates_within_s = 55;
  config.candidate_min_fraction = 0.5;
  // 40 iterations in 7.6 s, at 54.7 s of training: the next would end at 54.89 s.
  EXPECT_FALSE(search_past_cap(config, false, 7.6, 40, 54.7, true));
  // 41 in 7.8 s at 54.9 s: 55.09 s.
  const auto why = search_past_cap(config, false, 7.8, 41, 54.9, true);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("ended after iteration 41 of 72 at 7.8 s of searching"), std::string::npos)
      << *why;
  EXPECT_NE(why->find("past finetune.candidates_within_s (55 s)"), std::string::npos) << *why;
  EXPECT_FALSE(search_past_cap(config, false, 7.8, 41, 54.9, false));
  EXPECT_FALSE(search_past_cap(config, true, 7.8, 41, 54.9, true));
  config.candidate_min_fraction = 1;
  EXPECT_FALSE(search_past_cap(config, false, 7.8, 41, 54.9, true));
}

// An asynchronous run's search ends once its next iteration, at the mean pace of those done,
// would end past finetune.max_search_s of that search; never a reproducible run's, nor after its
// last iteration, nor without a cap.
TEST(MaxSearchTest, ASearchEndsWhenItsNextIterationWouldEndPastTheCap) {
  tuning::FinetuneConfig config;
  config.iterations = 72;
  config.max_search_s = 20;
  // 40 iterations in 10 s: the next would end at 10.25 s.
  EXPECT_FALSE(search_past_cap(config, false, 10, 40));
  // 60 iterations in 19.8 s: 20.13 s.
  const auto why = search_past_cap(config, false, 19.8, 60);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("ended after iteration 60 of 72 at 19.8 s"), std::string::npos) << *why;
  EXPECT_NE(why->find("finetune.max_search_s (20 s)"), std::string::npos) << *why;
  EXPECT_FALSE(search_past_cap(config, true, 19.8, 60));
  EXPECT_FALSE(search_past_cap(config, false, 100, 72));
  EXPECT_FALSE(search_past_cap(config, false, 100, 0));
  config.max_search_s = 0;
  EXPECT_FALSE(search_past_cap(config, false, 560, 60));
}

// A search cut short by finetune.max_search_s validates the iteration it ends at and keeps the
// best validated weights, as at its last iteration; the cap is each search's, and the next
// candidate is cut short the same way.
TEST(RefinetuneTest, ASearchPastTheCapEndsValidatedAndKeepsItsBest) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_refinetune_");
  RefinetuneOptions o = refinetune_committed_policy(tmp, 5, 2);
  const std::string policy = (tmp / "run" / "policy.nn").string();
  // The preset's cap replaced by one that the first iteration already passes.
  const fs::path config = tmp / "capped.yaml";
  ASSERT_TRUE(write_fast_preset_with(config, "max_search_s", "0.001"));
  o.config_path = config.string();
  std::ostringstream out;
  ASSERT_EQ(refinetune(o, out), 0) << out.str();
  EXPECT_NE(out.str().find("candidate 1/2: ended after iteration 1 of 5"), std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("candidate 2/2: ended after iteration 1 of 5"), std::string::npos)
      << out.str();
  for (const char* file : {"finetune.csv", "finetune_candidate2.csv"}) {
    const auto rows = test_support::read_csv(tmp / "again" / file);
    ASSERT_EQ(rows.size(), 1u) << file << "\n" << out.str();
    EXPECT_EQ(rows[0].at("iteration"), "1");
    EXPECT_FALSE(rows[0].at("validation_reached").empty());
  }
  const std::string evaluated = evaluated_policy(tmp / "again");
  EXPECT_TRUE(evaluated == policy || evaluated == o.out_dir + "/policy_finetuned.nn") << evaluated;
}

// The searches' mean (finetune.average_candidates): with thrust priced far above the preset
// (energy_weight 5), two iterations of each search already rank above the committed policy on
// the validation way-points, so both keep weights and their mean is a third choice, scored
// like them; the choice follows tuning::keep_mean, and a mean kept is the mean of the weights
// the two searches kept, to the bit.
TEST(RefinetuneTest, TheSearchesMeanIsAChoiceScoredLikeThemAndKeptUnlessASearchPassesMore) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_refinetune_");
  RefinetuneOptions o = refinetune_committed_policy(tmp, 2, 2);
  o.seed = 5;
  o.keep_iterates = true;
  o.config_path = (tmp / "priced.yaml").string();
  ASSERT_TRUE(write_fast_preset_with(o.config_path, "energy_weight", "5"));
  ASSERT_NE(test_support::read_text(o.config_path).find("\n  average_candidates: true"),
            std::string::npos);
  std::ostringstream out;
  ASSERT_EQ(refinetune(o, out), 0) << out.str();
  const auto rows = test_support::read_csv(tmp / "again" / "candidates.csv");
  ASSERT_EQ(rows.size(), 3u) << out.str();
  EXPECT_EQ(rows[0].at("kept_iteration"), "2");
  EXPECT_EQ(rows[1].at("kept_iteration"), "2");
  EXPECT_EQ(rows[2].at("weights"), "mean");
  EXPECT_EQ(rows[2].at("seed"), "");
  EXPECT_EQ(rows[2].at("kept_iteration"), "");
  EXPECT_NE(out.str().find("fine-tuning the mean of candidates 1-2: objective "), std::string::npos)
      << out.str();
  const std::size_t chosen = expected_choice(candidate_scores(rows));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].at("chosen"), i == chosen ? "1" : "0") << i;
  }
  if (chosen != 2) return;  // a search passed more criteria: its weights are kept
  EXPECT_NE(out.str().find("the searches' mean chosen"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("(the searches' mean)"), std::string::npos) << out.str();
  const nn::Mlp first = nn::network_from_bytes(
      nn::read_file((tmp / "again" / "iterates" / "iteration_002.nn").string()), 1);
  const nn::Mlp second = nn::network_from_bytes(
      nn::read_file((tmp / "again" / "iterates_candidate2" / "iteration_002.nn").string()), 1);
  EXPECT_EQ(nn::read_file(evaluated_policy(tmp / "again")),
            nn::network_to_bytes(nn::mean_of({&first, &second})));
}

// With candidates, each search keeps its own progress file, the seeds follow the run's (the
// one its command line gave), and the one passing the most criteria at the selection seed
// (robustness groups, way-points straight behind) is kept, or the searches' mean where the
// preset's finetune.average_candidates forms it and tuning::keep_mean keeps it (two iterations
// each: the choice, not the search, is under test).
TEST(RefinetuneTest, CandidatesSearchFromTheRunsSeedAndTheMostGroupsAreKept) {
  const fs::path tmp = test_support::make_temp_dir("auvrl_refinetune_");
  const RefinetuneOptions o = refinetune_committed_policy(tmp, 2, 2);
  const std::string policy = (tmp / "run" / "policy.nn").string();
  std::ostringstream out;
  ASSERT_EQ(refinetune(o, out), 0) << out.str();
  EXPECT_TRUE(fs::exists(tmp / "again" / "finetune.csv"));
  EXPECT_TRUE(fs::exists(tmp / "again" / "finetune_candidate2.csv"));
  const auto rows = test_support::read_csv(tmp / "again" / "candidates.csv");
  ASSERT_TRUE(rows.size() == 2u || rows.size() == 3u) << out.str();
  ASSERT_EQ(rows[0].count("groups_passing"), 1u);
  EXPECT_EQ(rows[0].at("seed"), "4");
  EXPECT_EQ(rows[1].at("seed"), "5");
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("behind_episodes"), std::to_string(tuning::kBehindEpisodes));
  }
  const std::size_t chosen = expected_choice(candidate_scores(rows));
  EXPECT_EQ(rows[0].at("weights"), "search");
  EXPECT_EQ(rows[1].at("weights"), "search");
  if (rows.size() == 3u) {  // both searches kept weights, and their mean validated above the start
    EXPECT_EQ(rows[2].at("weights"), "mean");
    EXPECT_EQ(rows[2].at("seed"), "");
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].at("chosen"), i == chosen ? "1" : "0") << i;
  }
  const std::string said = chosen == 2 ? std::string("the searches' mean chosen")
                                       : fmt::format("candidate {} chosen", chosen + 1);
  EXPECT_NE(out.str().find(said), std::string::npos) << out.str();
  // Settings out of range are refused before anything is written.
  RefinetuneOptions too_many = o;
  too_many.out_dir = (tmp / "too_many").string();
  too_many.candidates = 65;
  std::ostringstream refused;
  EXPECT_THROW(refinetune(too_many, refused), std::invalid_argument);
  EXPECT_FALSE(fs::exists(too_many.out_dir));
  // The chosen weights are the ones evaluated (the trained policy where a search kept none).
  EXPECT_EQ(evaluated_policy(tmp / "again"),
            rows[chosen].at("kept_iteration") == "0" ? policy : o.out_dir + "/policy_finetuned.nn")
      << out.str();
}

using RolesTest = test_support::RolesFixture;

TEST_F(RolesTest, StartOrderKindsAndLogs) {
  const auto roles = make_roles(ctx, {"--transport", "lcm"});
  std::vector<std::string> names;
  for (const auto& r : roles) names.push_back(r.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"logger", "sim0", "sim1", "learner", "actor0", "actor1"}));
  EXPECT_EQ(find(roles, "actor1").kind, RoleKind::kActor);
  EXPECT_EQ(find(roles, "actor1").actor_id, 1);
  EXPECT_EQ(find(roles, "learner").kind, RoleKind::kLearner);
  EXPECT_EQ(find(roles, "sim0").log_path, ctx.run_dir + "/processes/sim0.log");
  for (const auto& r : roles) {
    const auto argv = r.argv(0);
    EXPECT_EQ(argv[argv.size() - 2], "--transport") << r.name;
    // Only the actors wait, and only for the learner and the logger.
    EXPECT_EQ(r.starts_after_listeners, r.kind == RoleKind::kActor) << r.name;
    const bool listens = r.kind == RoleKind::kLearner || r.kind == RoleKind::kLogger;
    EXPECT_EQ(r.listening_text.empty(), !listens) << r.name;
  }
  EXPECT_EQ(find(roles, "learner").listening_text, listening::kLearner);
  EXPECT_EQ(find(roles, "logger").listening_text, listening::kLogger);
}

TEST_F(RolesTest, SecuredRunsGiveEachProcessItsIdentity) {
  ctx.rc.transport.kind = transport::TransportKind::kDds;
  ctx.rc.transport.dds.security_dir = "/pki";
  const auto roles = make_roles(ctx, {"--transport", "dds", "--dds-security", "/pki"});
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"logger", "logger"},   {"sim0", "sim-0"},     {"sim1", "sim-1"},
      {"learner", "learner"}, {"actor0", "actor-0"}, {"actor1", "actor-1"}};
  for (const auto& [role, identity] : expected) {
    EXPECT_TRUE(has(find(roles, role).argv(0), {"--dds-identity", identity})) << role;
  }
  EXPECT_TRUE(has(find(roles, "actor0").argv(0), {"--wait-for-readers", "learner,logger"}));
  // Unsecured, no identity.
  ctx.rc.transport.dds.security_dir.clear();
  for (const auto& r : make_roles(ctx, {"--transport", "dds"})) {
    const auto argv = r.argv(0);
    EXPECT_EQ(std::find(argv.begin(), argv.end(), "--dds-identity"), argv.end()) << r.name;
  }
}

TEST_F(RolesTest, SimulatorsAndActorsShareACpuAndAPrivateBus) {
  ctx.rc.run.learner_cpu = 0;
  const auto roles = make_roles(ctx, {});
  const auto sim1 = find(roles, "sim1").argv(0);
  EXPECT_EQ(sim1[0], "/usr/bin/taskset");
  EXPECT_EQ(sim1[2], "2");  // CPUs 1, 2, 3 left to the actors
  EXPECT_TRUE(has(sim1, {"/bin/auv_sim", "--vehicle", "/v.yaml", "--vehicles", "1",
                         "--first-vehicle-id", "1"}));
  EXPECT_TRUE(
      has(sim1, {"--lockstep-lcm-url", "udpm://239.255.76.67:7669?ttl=0&recv_buf_size=1048576"}));
  const auto actor1 = find(roles, "actor1").argv(0);
  EXPECT_TRUE(has(actor1, {"--pin-cpu", "2"}));
  EXPECT_TRUE(
      has(actor1, {"--lockstep-lcm-url", "udpm://239.255.76.67:7669?ttl=0&recv_buf_size=1048576"}));
  const auto learner = find(roles, "learner").argv(0);
  EXPECT_TRUE(has(learner, {"/usr/bin/taskset", "-c", "0", "/bin/auv_learner"}));
}

TEST_F(RolesTest, ARestartedActorGetsAnotherSeed) {
  const auto roles = make_roles(ctx, {});
  const RoleSpec& actor = find(roles, "actor1");
  EXPECT_TRUE(has(actor.argv(0), {"--seed", "3001"}));
  EXPECT_TRUE(has(actor.argv(2), {"--seed", std::to_string(3001 + 2 * 7919)}));
  EXPECT_TRUE(has(actor.argv(0), {"/bin/auv_actor", "--config", ctx.config_path, "--actor-id", "1",
                                  "--vehicle-id", "1"}));
}

TEST_F(RolesTest, TheLearnerResumesOnlyFromAFinishedCheckpoint) {
  const auto roles = make_roles(ctx, {"--transport", "lcm"});
  const RoleSpec& learner = find(roles, "learner");
  auto argv = learner.argv(0);
  EXPECT_EQ(std::count(argv.begin(), argv.end(), "--resume"), 0);
  EXPECT_TRUE(has(argv, {"--seed", "3", "--transport", "lcm"}));
  std::ofstream(ctx.run_dir + "/checkpoints/checkpoint-7.ckpt") << "x";
  argv = learner.argv(1);
  EXPECT_EQ(argv.back(), "--resume");
  EXPECT_TRUE(has(argv, {"--max-actors", "2"}));
}

}  // namespace
}  // namespace auvrl::launcher
