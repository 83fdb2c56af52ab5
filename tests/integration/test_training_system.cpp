// The training system as real processes in a private network namespace: auv_sim serving two
// vehicles, auv_learner, two auv_actor processes and auv_logger, once over LCM and once over
// Cyclone DDS (the same checks). Both actors report episodes, the learner's buffer fills, both
// actors act with rising policy versions, and the logger writes the system's channels.
#include <gtest/gtest.h>

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <map>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;

/// The transport every process of a run uses.
class TrainingSystem : public ::testing::TestWithParam<transport::TransportKind> {};

/// Actor `id` reported 30 episodes or more, none lost, with policy versions that rose and never
/// went back.
void expect_actor_learning(int id, const std::vector<auvrl_lcm::episode_report_t>& list,
                           const std::string& logs) {
  ASSERT_GE(list.size(), 30u) << "actor " << id << " reported too few episodes\n" << logs;
  EXPECT_GT(list.back().policy_version, list.front().policy_version)
      << "actor " << id << " did not pick up new weights";
  EXPECT_GT(list.back().policy_version, 0);
  for (std::size_t i = 1; i < list.size(); ++i) {
    EXPECT_EQ(list[i].episode_id, list[i - 1].episode_id + 1) << "an episode report was lost";
    EXPECT_GE(list[i].policy_version, list[i - 1].policy_version) << "policy went backwards";
  }
}

/// The messages the logger's heartbeat says it wrote on `channel` (0 without a heartbeat).
std::int64_t written_on(const std::optional<auvrl_lcm::logger_heartbeat_t>& heartbeat,
                        const std::string& channel) {
  if (!heartbeat) return 0;
  for (int i = 0; i < heartbeat->num_channels; ++i) {
    if (heartbeat->channel[static_cast<std::size_t>(i)] == channel) {
      return heartbeat->written[static_cast<std::size_t>(i)];
    }
  }
  return 0;
}

TEST_P(TrainingSystem, SimTwoActorsLearnerAndLoggerTrainTogether) {
  const std::string dir = test_support::make_temp_dir("auvrl_training_system_");
  transport::TransportConfig config;
  config.kind = GetParam();
  const std::vector<std::string> transport_args = transport::transport_arguments(config);
  const auto with_transport = [&](std::vector<std::string> argv) {
    argv.insert(argv.end(), transport_args.begin(), transport_args.end());
    return argv;
  };
  auto monitor = transport::make_transport(config);
  std::map<int, std::vector<auvrl_lcm::episode_report_t>> episodes;
  transport::subscribe<auvrl_lcm::episode_report_t>(
      *monitor, channels::kEpisode, [&](const std::string&, const auvrl_lcm::episode_report_t& r) {
        episodes[r.actor_id].push_back(r);
      });
  std::vector<auvrl_lcm::learner_stats_t> stats;
  transport::subscribe<auvrl_lcm::learner_stats_t>(
      *monitor, channels::kLearnerStats,
      [&](const std::string&, const auvrl_lcm::learner_stats_t& s) { stats.push_back(s); });
  std::optional<auvrl_lcm::logger_heartbeat_t> logged;
  transport::subscribe<auvrl_lcm::logger_heartbeat_t>(
      *monitor, channels::kLoggerHeartbeat,
      [&](const std::string&, const auvrl_lcm::logger_heartbeat_t& h) { logged = h; });

  // Everything but the lockstep loop (the launcher gives each pair a bus of its own).
  ChildProcess logger(with_transport({test_support::bin_path("auv_logger"), "--dir", dir + "/logs",
                                      "--heartbeat-period", "0.5", "--channels",
                                      "EXPERIENCE|EPISODE|POLICY_.*|LEARNER_STATS|SIM_HEARTBEAT"}),
                      dir + "/logger.log");
  ChildProcess sim(with_transport({test_support::bin_path("auv_sim"), "--vehicles", "2"}),
                   dir + "/sim.log");
  ChildProcess learner(
      with_transport({test_support::bin_path("auv_learner"), "--algo", "td3", "--hidden", "32-32",
                      "--batch-size", "64", "--layout", "extended", "--replay-capacity", "100000",
                      "--updates-per-transition", "0.25", "--warmup-transitions", "500"}),
      dir + "/learner.log");
  std::vector<std::unique_ptr<ChildProcess>> actors;
  for (int id = 0; id < 2; ++id) {
    actors.push_back(std::make_unique<ChildProcess>(
        with_transport({test_support::bin_path("auv_actor"), "--actor-id", std::to_string(id),
                        "--seed", std::to_string(10 + id), "--layout", "extended", "--reward",
                        "shaped", "--max-steps", "100", "--noise", "gaussian"}),
        dir + "/actor" + std::to_string(id) + ".log"));
  }

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(40);
  const auto enough = [&] {
    // The learner's own episode count too: its stats come once a second and, over DDS, the
    // first reports can precede discovery, so its count trails the actors' reports.
    if (stats.empty() || stats.back().buffer_size < 5000 || stats.back().updates < 500 ||
        stats.back().episodes < 60) {
      return false;
    }
    for (int id = 0; id < 2; ++id) {
      const auto& list = episodes[id];
      if (list.size() < 30 || list.back().policy_version <= list.front().policy_version) {
        return false;
      }
    }
    return true;
  };
  while (std::chrono::steady_clock::now() < deadline && !enough()) monitor->handle(100);

  const std::string logs = "learner:\n" + learner.log() + "actor 0:\n" + actors[0]->log() +
                           "actor 1:\n" + actors[1]->log() + "sim:\n" + sim.log() + "logger:\n" +
                           logger.log();
  ASSERT_FALSE(stats.empty()) << logs;
  const auvrl_lcm::learner_stats_t& last = stats.back();
  EXPECT_GE(last.buffer_size, 5000) << logs;
  EXPECT_GE(last.updates, 500);
  EXPECT_EQ(last.batches_dropped, 0);
  EXPECT_EQ(last.batches_lost, 0);
  EXPECT_GE(last.episodes, 60);
  for (int id = 0; id < 2; ++id) expect_actor_learning(id, episodes[id], logs);
  for (auto& actor : actors) {
    const int status = actor->terminate();
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << actor->log();
  }
  EXPECT_EQ(learner.terminate(), 0) << learner.log();
  EXPECT_EQ(sim.terminate(), 0) << sim.log();

  // The logger received the system's channels through the same transport and wrote them.
  const auto heartbeat_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  const auto written = [&](const std::string& channel) { return written_on(logged, channel); };
  const auto episodes_seen = static_cast<std::int64_t>(episodes[0].size() + episodes[1].size());
  // A heartbeat after everything else stopped counts everything the monitor saw.
  const auto logged_all = [&] {
    return written(channels::kEpisode) >= episodes_seen && written(channels::kExperience) > 0 &&
           written(channels::kPolicySummary) > 0 && written(channels::kLearnerStats) > 0;
  };
  while (std::chrono::steady_clock::now() < heartbeat_deadline && !logged_all()) {
    monitor->handle(100);
  }
  ASSERT_TRUE(logged.has_value()) << logger.log();
  EXPECT_EQ(logged->write_errors, 0);
  EXPECT_GE(written(channels::kEpisode), episodes_seen) << "the logger missed episode reports";
  EXPECT_GT(written(channels::kExperience), 0);
  EXPECT_GT(written(channels::kPolicySummary), 0);
  EXPECT_GT(written(channels::kLearnerStats), 0);
  EXPECT_EQ(written(channels::sim_state(0)), 0) << "the logger's channel filter";
  EXPECT_EQ(logger.terminate(), 0) << logger.log();
}

INSTANTIATE_TEST_SUITE_P(Transports, TrainingSystem,
                         ::testing::Values(transport::TransportKind::kLcm,
                                           transport::TransportKind::kDds),
                         [](const ::testing::TestParamInfo<transport::TransportKind>& info) {
                           return transport::to_string(info.param);
                         });

}  // namespace
