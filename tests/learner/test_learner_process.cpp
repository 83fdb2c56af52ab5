// auv_learner's process logic in process: finish_learner_config's hidden sizes and refused
// option combinations, which command lines make `--bench` measure one case, and a `learner:`
// section's smoothness keys (a negative weight is refused naming the key).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "common/cli.hpp"
#include "common/config/yaml_config.hpp"
#include "learner/learner_config.hpp"
#include "learner/learner_process.hpp"

namespace auvrl::learner {
namespace {

TEST(FinishLearnerConfig, HiddenSetsBothNetworks) {
  LearnerNodeConfig config;
  LearnerProcessOptions options;
  options.hidden = "64-32";
  finish_learner_config(options, config);
  EXPECT_EQ(config.ddpg.actor_hidden, (std::vector<int>{64, 32}));
  EXPECT_EQ(config.ddpg.critic_hidden, (std::vector<int>{64, 32}));
}

TEST(FinishLearnerConfig, NoHiddenKeepsTheConfiguredSizes) {
  LearnerNodeConfig config;
  config.ddpg.actor_hidden = {7};
  finish_learner_config(LearnerProcessOptions{}, config);
  EXPECT_EQ(config.ddpg.actor_hidden, (std::vector<int>{7}));
}

TEST(FinishLearnerConfig, ResumeNeedsACheckpointDirectory) {
  LearnerNodeConfig config;
  LearnerProcessOptions options;
  options.resume = true;
  EXPECT_THROW(finish_learner_config(options, config), cli::UsageError);
  config.checkpoint_dir = "/tmp/checkpoints";
  EXPECT_NO_THROW(finish_learner_config(options, config));
}

TEST(NamesOneBenchCase, HiddenOrBatchSizeInEitherForm) {
  const char* plain[] = {"auv_learner", "--bench", "--threads", "2"};
  EXPECT_FALSE(names_one_bench_case(4, plain));
  const char* hidden[] = {"auv_learner", "--bench", "--hidden", "64-64"};
  EXPECT_TRUE(names_one_bench_case(4, hidden));
  const char* batch[] = {"auv_learner", "--bench", "--batch-size=32"};
  EXPECT_TRUE(names_one_bench_case(3, batch));
  // The program name is not an option.
  const char* name[] = {"--hidden"};
  EXPECT_FALSE(names_one_bench_case(1, name));
}

TEST(LearnerSection, ReadsTheSmoothnessTermsAndRefusesNegativeWeightsNamingTheKey) {
  LearnerNodeConfig config;
  config.ddpg.state_dim = 29;
  config.ddpg.action_dim = 6;
  read_learner_section(config::Section("run.yaml", "learner",
                                       YAML::Load("smooth_temporal_weight: 0.2\n"
                                                  "smooth_spatial_weight: 0.1\n"
                                                  "smooth_spatial_sigma: 0.02\n")),
                       config);
  EXPECT_FLOAT_EQ(config.ddpg.smooth_temporal_weight, 0.2f);
  EXPECT_FLOAT_EQ(config.ddpg.smooth_spatial_weight, 0.1f);
  EXPECT_FLOAT_EQ(config.ddpg.smooth_spatial_sigma, 0.02f);
  for (const std::string key :
       {"smooth_temporal_weight", "smooth_spatial_weight", "smooth_spatial_sigma"}) {
    try {
      read_learner_section(config::Section("run.yaml", "learner", YAML::Load(key + ": -0.5\n")),
                           config);
      ADD_FAILURE() << key << ": -0.5 was accepted";
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("learner." + key), std::string::npos) << e.what();
    }
  }
}

// The smoothness terms are off in the paper, fast and smooth presets, on in robust.yaml.
TEST(LearnerSection, OnlyTheRobustPresetSmoothsTheCommands) {
  for (const std::string preset : {"paper", "fast", "robust"}) {
    LearnerNodeConfig config;
    read_learner_config_file(std::string(AUVRL_CONFIG_DIR) + "/presets/" + preset + ".yaml",
                             config);
    const bool on =
        config.ddpg.smooth_temporal_weight > 0.0f && config.ddpg.smooth_spatial_weight > 0.0f;
    EXPECT_EQ(on, preset == "robust") << preset;
    if (preset != "robust") {
      EXPECT_EQ(config.ddpg.smooth_temporal_weight + config.ddpg.smooth_spatial_weight, 0.0f);
    }
  }
}

}  // namespace
}  // namespace auvrl::learner
