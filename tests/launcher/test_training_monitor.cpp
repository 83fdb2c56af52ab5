// The launcher's monitor of a training run: only its participants' messages count, a restarted
// simulator's former process drops out of the rates, and what it keeps stays bounded whatever
// arrives.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/task/task.hpp"
#include "launcher/training_monitor.hpp"
#include "tests/launcher/manual_clock.hpp"

namespace auvrl::launcher {
namespace {

auvrl_lcm::sim_heartbeat_t sim_heartbeat(int pid, double steps_per_s) {
  auvrl_lcm::sim_heartbeat_t h{};
  h.pid = pid;
  h.steps_per_s = steps_per_s;
  return h;
}

auvrl_lcm::episode_report_t episode(int actor_id, bool success, task::EndReason reason) {
  auvrl_lcm::episode_report_t e{};
  e.actor_id = actor_id;
  e.success = success;
  e.beta_m = 0.5;
  e.end_reason = static_cast<std::int8_t>(reason);
  return e;
}

/// A run of two actors: logger 10, learner 11, sim0 12, sim1 13, actor0 14, actor1 15.
class TrainingMonitorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    int pid = 10;
    for (const char* name : {"logger", "learner", "sim0", "sim1", "actor0", "actor1"}) {
      monitor.started(name, pid++);
    }
  }
  ManualClock clock;
  TrainingMonitor monitor{2, clock};
};

TEST_F(TrainingMonitorTest, RatesAreTheCurrentSimulatorsOnly) {
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(12, 100)), Heard::kTaken);
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(13, 200)), Heard::kTaken);
  EXPECT_DOUBLE_EQ(monitor.env_steps_per_s(), 300);
  monitor.started("sim0", 20);  // sim0 restarted
  EXPECT_DOUBLE_EQ(monitor.env_steps_per_s(), 200);
  // A late heartbeat of the former process: expected, not counted, not foreign.
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(12, 100)), Heard::kFormer);
  EXPECT_DOUBLE_EQ(monitor.env_steps_per_s(), 200);
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(20, 150)), Heard::kTaken);
  EXPECT_DOUBLE_EQ(monitor.env_steps_per_s(), 350);
  EXPECT_EQ(monitor.foreign(), 0);
}

TEST_F(TrainingMonitorTest, EachMessageIsTakenOnlyFromItsRole) {
  auvrl_lcm::learner_stats_t stats{};
  stats.pid = 12;  // sim0's process, not the learner's
  stats.updates_per_s = 50;
  EXPECT_EQ(monitor.take_learner_stats(stats), Heard::kForeign);
  EXPECT_FALSE(monitor.learner_stats());
  stats.pid = 11;
  EXPECT_EQ(monitor.take_learner_stats(stats), Heard::kTaken);
  ASSERT_TRUE(monitor.learner_stats());
  EXPECT_DOUBLE_EQ(monitor.learner_stats()->updates_per_s, 50);
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(11, 1e6)), Heard::kForeign);
  auvrl_lcm::logger_heartbeat_t logger{};
  logger.pid = 10;
  EXPECT_EQ(monitor.take_logger_heartbeat(logger), Heard::kTaken);
  logger.pid = 99;
  EXPECT_EQ(monitor.take_logger_heartbeat(logger), Heard::kForeign);
  EXPECT_EQ(monitor.foreign(), 3);
}

TEST_F(TrainingMonitorTest, AFloodFromOutsideChangesNothingAndGrowsNothing) {
  monitor.take_sim_heartbeat(sim_heartbeat(12, 100));
  monitor.take_episode(episode(0, true, task::EndReason::kReached));
  const std::size_t entries = monitor.entries();
  for (int i = 0; i < 100000; ++i) {
    EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(1000 + i, 1e9)), Heard::kForeign);
    EXPECT_EQ(monitor.take_episode(episode(2 + i, false, task::EndReason::kBlowUp)),
              Heard::kForeign);
  }
  EXPECT_EQ(monitor.take_episode(episode(-1, false, task::EndReason::kBlowUp)), Heard::kForeign);
  EXPECT_EQ(monitor.entries(), entries);
  EXPECT_EQ(monitor.foreign(), 200001);
  EXPECT_DOUBLE_EQ(monitor.env_steps_per_s(), 100);
  EXPECT_DOUBLE_EQ(monitor.success_rate(), 1.0);
  EXPECT_EQ(monitor.episodes_seen(), 1);
}

TEST_F(TrainingMonitorTest, FiguresThatAreNotFiniteAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(12, nan)), Heard::kMalformed);
  EXPECT_EQ(monitor.take_sim_heartbeat(sim_heartbeat(12, -5)), Heard::kMalformed);
  auto e = episode(0, true, task::EndReason::kReached);
  e.beta_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(monitor.take_episode(e), Heard::kMalformed);
  auvrl_lcm::learner_stats_t stats{};
  stats.pid = 11;
  stats.updates_per_s = nan;
  EXPECT_EQ(monitor.take_learner_stats(stats), Heard::kMalformed);
  EXPECT_EQ(monitor.malformed(), 4);
  EXPECT_DOUBLE_EQ(monitor.env_steps_per_s(), 0);
  EXPECT_EQ(monitor.episodes_seen(), 0);
  EXPECT_FALSE(monitor.learner_stats());
}

TEST_F(TrainingMonitorTest, SuccessRateIsOverTheLastHundredEpisodes) {
  for (int i = 0; i < 100; ++i)
    monitor.take_episode(episode(i % 2, false, task::EndReason::kTimeLimit));
  for (int i = 0; i < 25; ++i) monitor.take_episode(episode(0, true, task::EndReason::kReached));
  EXPECT_DOUBLE_EQ(monitor.success_rate(), 0.25);
  EXPECT_EQ(monitor.episodes_seen(), 125);
}

TEST_F(TrainingMonitorTest, AnActorDiscardingEveryEpisodeWhileItsSimulatorAnswers) {
  monitor.take_episode(episode(1, false, task::EndReason::kBlowUp));
  clock.t_s = 31;
  monitor.take_episode(episode(1, false, task::EndReason::kSimTimeout));
  // Its simulator not heard: a hung simulator is the supervisor's, not this.
  EXPECT_FALSE(monitor.discarding_actor(30));
  monitor.take_sim_heartbeat(sim_heartbeat(13, 10));
  const auto run = monitor.discarding_actor(30);
  ASSERT_TRUE(run);
  EXPECT_EQ(run->actor_id, 1);
  EXPECT_DOUBLE_EQ(run->for_s, 31);
  EXPECT_EQ(run->episodes, 2);
  EXPECT_EQ(run->last_end_reason, static_cast<int>(task::EndReason::kSimTimeout));
  EXPECT_FALSE(monitor.discarding_actor(40));  // not yet for 40 s
  // The simulator silent for more than 3 s.
  clock.t_s = 35;
  EXPECT_FALSE(monitor.discarding_actor(30));
  // One episode that is not discarded ends the run of them.
  monitor.take_sim_heartbeat(sim_heartbeat(13, 10));
  EXPECT_TRUE(monitor.discarding_actor(30));
  monitor.take_episode(episode(1, false, task::EndReason::kTimeLimit));
  EXPECT_FALSE(monitor.discarding_actor(30));
}

}  // namespace
}  // namespace auvrl::launcher
