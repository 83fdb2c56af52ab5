// The run's CSV files as the launcher writes them: columns, number formats, appending over
// --resume, and the stop message when a file cannot be written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "child_process.hpp"
#include "launcher/format.hpp"
#include "launcher/telemetry.hpp"

namespace auvrl::launcher {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(TelemetryTest, EpisodesHaveTheirColumnsAndFixedDecimals) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  auvrl_lcm::episode_report_t e{};
  e.actor_id = 2;
  e.episode_id = 17;
  e.policy_version = 340;
  e.episode_return = -123.456789;
  e.length_steps = 700;
  e.success = 1;
  e.final_distance_m = 0.25;
  e.min_distance_m = 0.123456;
  e.beta_m = 1.5;
  e.end_reason = 1;
  e.thrust_energy = 12345.6;
  {
    EpisodeSink sink((dir / "episodes.csv").string());
    sink.add(1234.56789, e);
    sink.writer().flush();
  }
  EXPECT_EQ(slurp(dir / "episodes.csv"),
            "wall_s,actor_id,episode_id,policy_version,return,length_steps,success,"
            "final_distance_m,min_distance_m,beta_m,end_reason,thrust_energy\n"
            "1234.568,2,17,340,-123.4568,700,1,0.2500,0.1235,1.5000,1,12345.6000\n");
  // Resumed: rows appended under the one header.
  {
    EpisodeSink sink((dir / "episodes.csv").string());
    sink.add(2000, e);
  }
  const std::string text = slurp(dir / "episodes.csv");
  EXPECT_EQ(text.find("wall_s", 1), std::string::npos);
  EXPECT_NE(text.find("\n2000.000,2,17,"), std::string::npos);
}

TEST(TelemetryTest, LearnerFiguresHaveTheirColumnsAndDecimals) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  auvrl_lcm::learner_stats_t s{};
  s.updates = 5000;
  s.updates_per_s = 212.345;
  s.transitions_received = 80000;
  s.transitions_per_s = 1500.04;
  s.buffer_size = 70000;
  s.critic_loss = 0.0123456789;
  s.actor_loss = -3.5;
  s.mean_q = 4.25;
  s.episodes = 90;
  s.beta_m = 0.5;
  s.weights_published = 50;
  s.expert_share = 0.1;
  {
    LearnerSink sink((dir / "learner.csv").string());
    sink.add(10.5, s);
  }
  EXPECT_EQ(slurp(dir / "learner.csv"),
            "wall_s,updates,updates_per_s,transitions_received,transitions_per_s,buffer_size,"
            "critic_loss,actor_loss,mean_q,episodes,beta_m,weights_published,expert_share\n"
            "10.500,5000,212.3,80000,1500.0,70000,0.012346,-3.500000,4.250000,90,0.500000,50,"
            "0.100000\n");
}

TEST(TelemetryTest, ProgressRowsAndTheTrainedTimeOfAResume) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  EXPECT_EQ(trained_before_s(dir.string()), 0.0);
  {
    ProgressSink sink((dir / "progress.csv").string());
    sink.add({12.34, 40, 0.4567, 1.5, 2345.6, 99.5, 0.0});
    sink.add({13.36, 41, 0.5, 0.5, 2000, 100, 1.0});
  }
  EXPECT_EQ(slurp(dir / "progress.csv"),
            "wall_s,episodes,success_rate,beta_m,env_steps_per_s,updates_per_s,"
            "best_suite_success\n"
            "12.3,40,0.457,1.500,2346,100,0\n"
            "13.4,41,0.500,0.500,2000,100,1\n");
  EXPECT_DOUBLE_EQ(trained_before_s(dir.string()), 13.4);
}

TEST(TelemetryTest, QuickEvaluationsWriteZerosForMissingFiguresAndSetOldFilesAside) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  std::ofstream(dir / "quick_eval.csv") << "wall_s,policy_version,reached\n1,2,3\n";
  {
    QuickEvalSink sink((dir / "quick_eval.csv").string());
    eval::ValidationScore none;
    none.episodes = 40;
    sink.add(5.04, 12, none, true);
    eval::ValidationScore some{30, 40, 21.456, 0.1234, 1.2346};
    sink.add(10, 13, some, false);
  }
  EXPECT_EQ(slurp(dir / "quick_eval.old.csv"), "wall_s,policy_version,reached\n1,2,3\n");
  EXPECT_EQ(slurp(dir / "quick_eval.csv"),
            "wall_s,policy_version,reached,episodes,mean_time_to_reach_s,"
            "mean_error_after_reach_m,max_time_ratio_to_pid,kept\n"
            "5.0,12,0,40,0.00,0.000,0.000,1\n"
            "10.0,13,30,40,21.46,0.123,1.235,0\n");
  // The same columns: appended to.
  { QuickEvalSink sink((dir / "quick_eval.csv").string()); }
  EXPECT_NE(slurp(dir / "quick_eval.csv").find("10.0,13,"), std::string::npos);
}

TEST(TelemetryTest, FinetuneRowsLeaveTheValidationEmptyWhereNotValidated) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  {
    FinetuneSink sink((dir / "finetune.csv").string());
    sink.add(1, 31.123456789, 2.5, nullptr);
    const eval::ValidationScore score{38, 40, 25.25, 0.08, 1.125};
    sink.add(10, 30.5, 25, &score);
  }
  EXPECT_EQ(slurp(dir / "finetune.csv"),
            "iteration,objective_s,elapsed_s,validation_reached,validation_mean_time_s,"
            "validation_hold_m,validation_worst_time_ratio\n"
            "1,31.1235,2.5,,,,\n"
            "10,30.5,25,38,25.25,0.08,1.125\n");
}

TEST(TelemetryTest, ObjectiveTermsARowPerControllerEveryPriceInSeconds) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  tuning::ObjectiveTerms pid;
  pid.arrival_s = 14.25;
  pid.hold_s = 1.5;
  pid.turn_s = 0.125;
  pid.energy_s = 6.5;
  pid.smoothness_s = 2.375;
  pid.lag_s = 1.2;
  pid.objective_s = 25.95;
  tuning::ObjectiveTerms policy;
  policy.arrival_s = 11.125;
  policy.flip_s = 0.04;
  policy.objective_s = 11.165;
  write_objective_terms((dir / "objective_terms.csv").string(),
                        {{"pid", pid}, {"finetuned", policy}});
  EXPECT_EQ(slurp(dir / "objective_terms.csv"),
            "controller,objective_s,arrival_s,hold_s,turn_s,flip_s,energy_s,smoothness_s,lag_s\n"
            "pid,25.95,14.25,1.5,0.125,0,6.5,2.375,1.2\n"
            "finetuned,11.165,11.125,0,0,0.04,0,0,0\n");
  EXPECT_THROW(write_objective_terms((dir / "none" / "objective_terms.csv").string(), {}),
               std::runtime_error);
}

TEST(TelemetryTest, CandidatesARowPerSearchAndTheirMeanTheChosenMarked) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  write_candidates((dir / "candidates.csv").string(),
                   {{1, 3, 80, 18.75, 21, 25, 15, 100, false},
                    {2, 4, 0, 19.5, 25, 25, 4, 100, false},
                    {3, 0, 0, 18.5, 25, 25, 3, 100, true, true}});
  EXPECT_EQ(slurp(dir / "candidates.csv"),
            "candidate,weights,seed,kept_iteration,objective_s,groups_passing,groups,behind_late,"
            "behind_episodes,chosen\n"
            "1,search,3,80,18.75,21,25,15,100,0\n"
            "2,search,4,0,19.5,25,25,4,100,0\n"
            "3,mean,,,18.5,25,25,3,100,1\n");
  EXPECT_THROW(write_candidates((dir / "none" / "candidates.csv").string(), {}),
               std::runtime_error);
}

TEST(TelemetryTest, AFileThatCannotBeWrittenStopsWithItsPathAndTheReason) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  fs::create_symlink("/dev/full", dir / "learner.csv");
  TrainingTelemetry telemetry(dir.string());
  const auto error = telemetry.flush();
  ASSERT_TRUE(error.has_value());
  EXPECT_EQ(*error, "cannot write " + (dir / "learner.csv").string() +
                        " (No space left on device): disk full or run directory not writable; "
                        "the last checkpoint in " +
                        (dir / "checkpoints").string() + " is kept");
}

TEST(TelemetryTest, WritableFilesFlushWithoutError) {
  const fs::path dir = test_support::make_temp_dir("auvrl_telemetry_");
  TrainingTelemetry telemetry(dir.string());
  EXPECT_FALSE(telemetry.flush().has_value());
  for (const char* name : {"episodes.csv", "learner.csv", "progress.csv", "quick_eval.csv"}) {
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  }
}

TEST(FormatTest, DurationsAsTheStatusLineShowsThem) {
  EXPECT_EQ(format_duration(5), "0m05s");
  EXPECT_EQ(format_duration(125.4), "2m05s");
  EXPECT_EQ(format_duration(3600 + 62), "1h01m02s");
  EXPECT_EQ(format_duration(-1), "?");
  EXPECT_EQ(format_duration(1.0 / 0.0), "?");
}

}  // namespace
}  // namespace auvrl::launcher
