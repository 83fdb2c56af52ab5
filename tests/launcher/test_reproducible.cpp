// Reproducible mode in the launcher (auvrl train --reproducible): the run: keys, the budget in
// updates, the processes' command lines, and the best policy chosen from the learner's
// snapshots in update order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "common/config/yaml_config.hpp"
#include "common/nn/serialize.hpp"
#include "launcher/best_policy.hpp"
#include "launcher/launcher.hpp"
#include "launcher/run_config.hpp"
#include "launcher/run_directory.hpp"
#include "launcher/training.hpp"
#include "roles_fixture.hpp"
#include "run_files.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {
namespace {

namespace fs = std::filesystem;

bool has(const std::vector<std::string>& argv, const std::vector<std::string>& run) {
  return std::search(argv.begin(), argv.end(), run.begin(), run.end()) != argv.end();
}

/// A copy of the fast preset without its budget in updates (learner.max_updates), with
/// `run_lines` added to its run: section and `learner_lines` to its learner: section (each line
/// indented, ending in "\n").
std::string preset_with(const fs::path& dir, const std::string& run_lines,
                        const std::string& learner_lines = "") {
  return test_support::write_preset_copy(AUVRL_CONFIG_DIR, "fast", (dir / "run.yaml").string(),
                                         [&](std::string& line) {
                                           if (line.rfind("  max_updates:", 0) == 0) line.clear();
                                           if (line == "run:") line += "\n" + run_lines;
                                           if (line == "learner:") line += "\n" + learner_lines;
                                         });
}

/// The dotted key a configuration error names ("" when it reads).
std::string config_error_key(const std::string& path) {
  try {
    read_run_config(path);
  } catch (const config::ConfigError& e) {
    return e.key();
  }
  return "";
}

TEST(ReproducibleConfigTest, TheRunKeysDefaultsAndRanges) {
  const fs::path dir = test_support::make_temp_dir("auvrl_repro_config_");
  const RunConfig fast = read_run_config(std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml");
  EXPECT_FALSE(fast.run.reproducible);
  EXPECT_EQ(fast.run.round_weights_every_steps, 100);
  EXPECT_EQ(fast.run.best_eval_every_updates, 40000);
  EXPECT_EQ(fast.learner_max_updates, 300000);  // the TD3 phase's end, or run.max_train_s
  EXPECT_EQ(read_run_config(preset_with(dir, "")).learner_max_updates, 0);

  const RunConfig set = read_run_config(preset_with(
      dir,
      "  reproducible: true\n  round_weights_every_steps: 50\n  best_eval_every_updates: 1000\n",
      "  max_updates: 5000\n"));
  EXPECT_TRUE(set.run.reproducible);
  EXPECT_EQ(set.run.round_weights_every_steps, 50);
  EXPECT_EQ(set.run.best_eval_every_updates, 1000);
  EXPECT_EQ(set.learner_max_updates, 5000);

  EXPECT_EQ(config_error_key(preset_with(dir, "  round_weights_every_steps: 0\n")),
            "run.round_weights_every_steps");
  EXPECT_EQ(config_error_key(preset_with(dir, "  best_eval_every_updates: 0\n")),
            "run.best_eval_every_updates");
  EXPECT_EQ(config_error_key(preset_with(dir, "  reproducible: 3\n")), "run.reproducible");
}

class ReproducibleRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp = test_support::make_temp_dir("auvrl_repro_run_");
    options.config_path = preset_with(tmp, "");  // no budget in updates
    options.run_dir = (tmp / "run").string();
  }
  fs::path tmp;
  TrainOptions options;
};

TEST_F(ReproducibleRunTest, ANewRunWithoutABudgetInUpdatesIsRefusedBeforeItsDirectoryIsMade) {
  options.reproducible = true;
  try {
    prepare_run_directory(options);
    FAIL() << "expected the budget error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("learner.max_updates"), std::string::npos) << what;
    EXPECT_NE(what.find("--max-updates N"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(options.run_dir));
  options.max_updates = 2000;
  EXPECT_NO_THROW(prepare_run_directory(options));
}

TEST_F(ReproducibleRunTest, TheBudgetIsCheckedForTrainingOnly) {
  prepare_run_directory(options);  // an asynchronous run (the fast preset, no budget in updates)
  options.resume = true;
  EXPECT_FALSE(load_run_context(options).rc.run.reproducible);
  options.reproducible = true;  // --resume RUN --reproducible
  EXPECT_THROW(load_run_context(options), std::runtime_error);
  // auvrl finetune loads a trained run's context: no budget needed there.
  EXPECT_NO_THROW(load_run_context(options, ContextUse::kAfterTraining));
  options.max_updates = 3000;
  const RunContext ctx = load_run_context(options);
  EXPECT_TRUE(ctx.rc.run.reproducible);
  EXPECT_EQ(ctx.rc.learner_max_updates, 3000);
  EXPECT_DOUBLE_EQ(ctx.rc.run.max_train_s, 35.0);  // the preset's, kept, not used

  // learner.max_episodes is a budget too.
  RunConfig episodes;
  episodes.run.reproducible = true;
  EXPECT_THROW(check_reproducible_budget(episodes), std::runtime_error);
  episodes.learner_max_episodes = 100;
  EXPECT_NO_THROW(check_reproducible_budget(episodes));
}

TEST_F(ReproducibleRunTest, ResumeKeepsTheSettingsTheCommandLineGaveTheRun) {
  options.reproducible = true;
  options.max_updates = 5000;
  options.seed = 7;
  options.actors = 2;
  options.transport_args = {"--transport", "dds"};
  prepare_run_directory(options);
  TrainOptions resume;
  resume.run_dir = options.run_dir;
  resume.resume = true;
  resume.seed = 9;  // given again: this one counts
  prepare_run_directory(resume);
  EXPECT_TRUE(resume.reproducible);
  EXPECT_EQ(resume.max_updates, 5000);
  EXPECT_EQ(resume.seed, 9);
  EXPECT_EQ(resume.actors, 2);
  EXPECT_EQ(resume.transport_args, (std::vector<std::string>{"--transport", "dds"}));
  EXPECT_EQ(resume.max_train_s, -1);  // never given

  std::ofstream(fs::path(options.run_dir) / "command_line.yaml") << "seed: [1, 2]\n";
  TrainOptions broken;
  broken.run_dir = options.run_dir;
  broken.resume = true;
  try {
    prepare_run_directory(broken);
    FAIL() << "expected an error naming command_line.yaml";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("command_line.yaml"), std::string::npos) << e.what();
  }
}

TEST_F(ReproducibleRunTest, TheInnerCommandPassesTheModeAndTheBudgetOn) {
  options.source_dir = "/src";
  options.bin_dir = "/bin";
  std::vector<std::string> command = namespace_command(options);
  EXPECT_EQ(std::count(command.begin(), command.end(), "--reproducible"), 0);
  EXPECT_EQ(std::count(command.begin(), command.end(), "--max-updates"), 0);
  options.reproducible = true;
  options.max_updates = 0;
  command = namespace_command(options);
  EXPECT_TRUE(has(command, {"--resume", options.run_dir}));
  EXPECT_EQ(std::count(command.begin(), command.end(), "--reproducible"), 1);
  EXPECT_TRUE(has(command, {"--max-updates", "0"}));
}

class ReproducibleRolesTest : public test_support::RolesFixture {
 protected:
  void SetUp() override {
    RolesFixture::SetUp();
    ctx.rc.run.reproducible = true;
    ctx.rc.run.round_weights_every_steps = 50;
    ctx.rc.run.best_eval_every_updates = 1000;
    ctx.rc.learner_max_updates = 9000;
  }
};

TEST_F(ReproducibleRolesTest, TheLearnerGetsTheModeTheSnapshotsAndTheOverride) {
  auto roles = make_roles(ctx, {"--transport", "lcm"});
  auto argv = find(roles, "learner").argv(0);
  EXPECT_TRUE(has(argv, {"--reproducible", "--round-weights-every-steps", "50"}));
  EXPECT_TRUE(has(
      argv, {"--snapshot-dir", ctx.run_dir + "/snapshots", "--snapshot-every-updates", "1000"}));
  EXPECT_TRUE(has(argv, {"--config", ctx.config_path}));  // learner.max_updates from there
  EXPECT_EQ(std::count(argv.begin(), argv.end(), "--max-updates"), 0);
  EXPECT_EQ(argv[argv.size() - 2], "--transport");
  // --max-updates N on the command line reaches the learner as its flag.
  ctx.options.max_updates = 7000;
  roles = make_roles(ctx, {"--transport", "lcm"});
  std::ofstream(ctx.run_dir + "/checkpoints/checkpoint-7.ckpt") << "x";
  argv = find(roles, "learner").argv(1);
  EXPECT_TRUE(has(argv, {"--max-updates", "7000"}));
  EXPECT_EQ(argv.back(), "--resume");  // resumes as ever
}

TEST_F(ReproducibleRolesTest, ARestartedActorIsTheSameActor) {
  const auto roles = make_roles(ctx, {});
  const RoleSpec& actor = find(roles, "actor1");
  const auto first = actor.argv(0);
  EXPECT_TRUE(has(first, {"--seed", "3001"}));
  EXPECT_TRUE(has(first, {"--reproducible", "--round-weights-every-steps", "50"}));
  EXPECT_EQ(actor.argv(1), first);
  EXPECT_EQ(actor.argv(4), first);
  for (const char* learner_only : {"--snapshot-dir", "--max-updates"}) {
    EXPECT_EQ(std::count(first.begin(), first.end(), learner_only), 0) << learner_only;
  }
}

TEST_F(ReproducibleRolesTest, TheAsynchronousModeGetsNoneOfItsFlags) {
  ctx.rc.run.reproducible = false;
  ctx.options.max_updates = 7000;
  const auto roles = make_roles(ctx, {});
  for (const auto& role : roles) {
    const auto argv = role.argv(0);
    for (const char* flag : {"--reproducible", "--round-weights-every-steps", "--snapshot-dir"}) {
      EXPECT_EQ(std::count(argv.begin(), argv.end(), flag), 0) << role.name << " " << flag;
    }
  }
  EXPECT_TRUE(has(find(roles, "learner").argv(0), {"--max-updates", "7000"}));
  EXPECT_NE(find(roles, "actor1").argv(1), find(roles, "actor1").argv(0));  // a new seed
}

/// A snapshot file name as the learner writes it.
std::string snapshot_name(std::int64_t updates) {
  char name[64];
  std::snprintf(name, sizeof name, "policy-%012lld.nn", static_cast<long long>(updates));
  return name;
}

TEST(SnapshotTest, ListedInUpdateOrderWithoutTemporaryOrForeignFiles) {
  const fs::path dir = test_support::make_temp_dir("auvrl_snapshots_");
  EXPECT_TRUE(list_snapshots((dir / "missing").string()).empty());
  for (std::int64_t updates : std::vector<std::int64_t>{300, 20, 1000000000000}) {
    std::ofstream(dir / snapshot_name(updates));
  }
  for (const char* other : {"policy-000000000050.nn.tmp", "policy-.nn", "policy-12a.nn",
                            "policy_best.nn", "policy-000000000070.nnx", "notes.txt"}) {
    std::ofstream(dir / other);
  }
  fs::create_directories(dir / snapshot_name(40));  // not a file
  const std::vector<PolicySnapshot> listed = list_snapshots(dir.string());
  ASSERT_EQ(listed.size(), 3u);
  EXPECT_EQ(listed[0].updates, 20);
  EXPECT_EQ(listed[0].path, (dir / snapshot_name(20)).string());
  EXPECT_EQ(listed[1].updates, 300);
  EXPECT_EQ(listed[2].updates, 1000000000000);
}

/// A small actor for the run's task (its state and thrusters), seeded.
nn::Mlp small_actor(const task::TaskConfig& task, std::uint64_t seed) {
  nn::Mlp net(nn::MlpSpec::actor(task.state_dim(), {8}, task.num_thrusters), 1);
  nn::Rng rng(seed);
  net.init_lillicrap(rng);
  return net;
}

TEST(SnapshotTest, EachIsConsideredOnceInUpdateOrderAndDeleted) {
  const fs::path run = test_support::make_temp_dir("auvrl_snapshot_review_");
  const fs::path dir = run / "snapshots";
  fs::create_directories(dir);
  RunConfig rc = read_run_config(std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml");
  const sim::VehicleModel model =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
  task::apply_vehicle(model.facts(), rc.task);
  BestPolicyKeeper keeper(model, rc.task, 2, 0.15, run.string());
  for (std::int64_t updates : {3000, 1000, 2000}) {
    nn::save_network_file((dir / snapshot_name(updates)).string(),
                          small_actor(rc.task, static_cast<std::uint64_t>(updates)));
  }
  std::ofstream(dir / snapshot_name(1500)) << "not a network";  // damage
  std::ofstream(dir / "policy-000000004000.nn.tmp") << "being written";
  std::ostringstream out;
  SnapshotReviewer reviewer(dir.string());
  {
    QuickEvalSink sink((run / "quick_eval.csv").string());
    EXPECT_EQ(reviewer.review(keeper, 1.0, sink, out, 1), 1u);  // the oldest alone
    EXPECT_EQ(reviewer.last_updates(), 1000);
    EXPECT_FALSE(fs::exists(dir / snapshot_name(1000)));
    EXPECT_TRUE(fs::exists(dir / snapshot_name(2000)));
    EXPECT_EQ(reviewer.review(keeper, 2.0, sink, out, 100), 3u);
    // Written again by a learner restarted from an older checkpoint: deleted unread.
    nn::save_network_file((dir / snapshot_name(2000)).string(), small_actor(rc.task, 2000));
    EXPECT_EQ(reviewer.review(keeper, 3.0, sink, out, 100), 1u);
    EXPECT_EQ(reviewer.review(keeper, 3.0, sink, out, 100), 0u);
  }
  EXPECT_TRUE(keeper.has_best());
  EXPECT_TRUE(fs::exists(run / "policy_best.nn"));
  EXPECT_NE(out.str().find(snapshot_name(1500) + " is damaged"), std::string::npos) << out.str();
  std::vector<std::string> versions;
  for (const auto& row : test_support::read_csv(run / "quick_eval.csv")) {
    versions.push_back(row.at("policy_version"));
  }
  EXPECT_EQ(versions, (std::vector<std::string>{"1000", "2000", "3000"}));
  const std::vector<PolicySnapshot> left = list_snapshots(dir.string());
  EXPECT_TRUE(left.empty());
  EXPECT_TRUE(fs::exists(dir / "policy-000000004000.nn.tmp"));  // not the reviewer's
}

}  // namespace
}  // namespace auvrl::launcher
