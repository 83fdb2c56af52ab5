// auv_learner's process logic in process: finish_learner_config's hidden sizes and refused
// option combinations, and which command lines make `--bench` measure one case.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "common/cli.hpp"
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

}  // namespace
}  // namespace auvrl::learner
