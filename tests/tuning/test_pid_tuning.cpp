// Tuning of the PID's gains (tuning/pid_tuning.hpp): its validation draws (seeded, in the goal
// box, the fault and current shares, not the evaluation's suite), its objective against the
// evaluation's own rows, that a tiny search is deterministic for a seed whatever the threads and
// never ends worse than it started, that `auvrl tune-pid`'s request writes a gains file that
// pid_gains_for then reads, and that the committed gains files (config/vehicles/*.pid.yaml)
// also reach way-points near the vertical of the start, which the uniform draws hold few of.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "agent/pid_controller.hpp"
#include "agent_test_util.hpp"
#include "common/config/table.hpp"
#include "tuning/pid_tuning.hpp"

namespace auvrl::tuning {
namespace {

using test_support::nessie;

task::TaskConfig nessie_task() {
  task::TaskConfig t;
  task::apply_vehicle(nessie().facts(), t);
  return t;
}

/// A budget of a few hundred milliseconds: 4 way-points of 20 s, 2 threads.
PidTuningConfig tiny() {
  PidTuningConfig c;
  c.episodes = 4;
  c.episode_steps = 200;
  c.iterations = 6;
  c.threads = 2;
  return c;
}

TEST(PidValidationEpisodes, AreSeededInTheBoxWithTheirFaultsAndCurrents) {
  PidTuningConfig c;
  c.episodes = 20;
  const task::TaskConfig t = nessie_task();
  const auto a = pid_validation_episodes(t, c, 3);
  const auto b = pid_validation_episodes(t, c, 3);
  const auto other = pid_validation_episodes(t, c, 4);
  const auto held_out = pid_validation_episodes(t, c, 3, 1);
  ASSERT_EQ(a.size(), 20u);
  int faults = 0, currents = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].goal_ned_m, b[i].goal_ned_m);
    EXPECT_NE(a[i].goal_ned_m, other[i].goal_ned_m);
    EXPECT_NE(a[i].goal_ned_m, held_out[i].goal_ned_m);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(a[i].goal_ned_m[k], t.goal_min_ned_m[k]);
      EXPECT_LE(a[i].goal_ned_m[k], t.goal_max_ned_m[k]);
    }
    EXPECT_EQ(a[i].start.position_ned_m, t.start_position_ned_m);
    EXPECT_EQ(a[i].start.euler_rpy_rad, Eigen::Vector3d(0.0, 0.0, t.start_yaw_rad));
    if (!a[i].start.thruster_efficiency.empty()) {
      ++faults;
      EXPECT_EQ(a[i].start.thruster_efficiency[0], 0.1);
    }
    if (a[i].start.current_ned_mps.norm() > 0) {
      ++currents;
      EXPECT_NEAR(a[i].start.current_ned_mps.norm(), 0.3, 1e-12);
      EXPECT_EQ(a[i].start.current_ned_mps[2], 0.0);
    }
  }
  EXPECT_EQ(faults, 5);
  EXPECT_EQ(currents, 5);
  // Not the evaluation's suite (seed 1, the same box).
  eval::EvaluationConfig evaluation;
  evaluation.task = t;
  const auto suite = eval::scenario_episodes(evaluation, eval::Scenario::kSuite);
  const auto ours = pid_validation_episodes(t, c, 1);
  for (std::size_t i = 0; i < ours.size(); ++i) EXPECT_NE(ours[i].goal_ned_m, suite[i].goal_ned_m);
}

TEST(PidObjective, WeighsTheEvaluationsOwnFigures) {
  const PidTuningConfig c = tiny();
  const task::TaskConfig t = nessie_task();
  const auto episodes = pid_validation_episodes(t, c, 5);
  const PidObjective o = pid_objective(nessie(), t, agent::PidGains{}, episodes, c);
  // The same episodes through the evaluation's episode code, one thread.
  eval::EvaluationConfig e;
  e.task = t;
  e.episode_steps = c.episode_steps;
  agent::PidController pid(nessie());
  double time = 0, hold = 0, energy = 0;
  int reached = 0;
  for (const auto& episode : episodes) {
    const eval::SummaryRow row = eval::run_evaluation_episode(nessie(), e, pid, episode, nullptr);
    energy += row.thrust_energy;
    if (!row.reached) continue;
    ++reached;
    time += row.time_to_reach_s;
    hold += row.mean_error_after_reach_m;
  }
  ASSERT_GT(reached, 0);
  const int n = static_cast<int>(episodes.size());
  EXPECT_EQ(o.episodes, n);
  EXPECT_EQ(o.missed, n - reached);
  EXPECT_DOUBLE_EQ(o.mean_time_s, time / reached);
  EXPECT_DOUBLE_EQ(o.mean_hold_m, hold / reached);
  EXPECT_DOUBLE_EQ(o.mean_energy, energy / n);
  EXPECT_DOUBLE_EQ(o.value, o.mean_time_s + 20.0 * o.mean_hold_m +
                                500.0 * (n - reached) / static_cast<double>(n) +
                                0.02 * o.mean_energy);
}

TEST(PidTuning, IsDeterministicForASeedWhateverTheThreadsAndNeverWorse) {
  const task::TaskConfig t = nessie_task();
  PidTuningConfig c = tiny();
  const PidTuningResult a = tune_pid(nessie(), t, agent::PidGains{}, c, 7);
  c.threads = 1;
  int steps = 0;
  const PidTuningResult b =
      tune_pid(nessie(), t, agent::PidGains{}, c, 7, [&](const PidTuningStep& s) {
        ++steps;
        EXPECT_EQ(s.iteration, steps);
        EXPECT_EQ(s.perturbed.size(), 3u);
        EXPECT_LE(s.best.value, a.start_objective.value);
      });
  EXPECT_EQ(steps, c.iterations);
  EXPECT_EQ(agent::pid_gains_text(a.best, ""), agent::pid_gains_text(b.best, ""));
  EXPECT_EQ(a.best_objective.value, b.best_objective.value);
  EXPECT_EQ(a.accepted, b.accepted);
  EXPECT_LE(a.best_objective.value, a.start_objective.value);
  EXPECT_GT(a.accepted, 0);  // the search moved: the comparisons above are not vacuous
  EXPECT_EQ(
      a.start_objective.value,
      pid_objective(nessie(), t, agent::PidGains{}, pid_validation_episodes(t, c, 7), c).value);
  // Another seed searches elsewhere.
  const PidTuningResult other = tune_pid(nessie(), t, agent::PidGains{}, c, 8);
  EXPECT_NE(agent::pid_gains_text(a.best, ""), agent::pid_gains_text(other.best, ""));
}

TEST(PidTuning, PerturbsOnlyTheGainsOfControlledDof) {
  const std::vector<std::string> keys = tunable_gains(nessie());  // no roll authority
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "roll_gain_per_s"), 0);
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "pitch_gain_per_s"), 1);
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "sway_speed_max_mps"), 1);
  EXPECT_EQ(keys.size(), agent::pid_gains_table().fields().size() - 2);
}

TEST(PidTuning, RefusesBadSettings) {
  PidTuningConfig c = tiny();
  c.fault_fraction = 0.8;
  c.current_fraction = 0.3;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = tiny();
  c.sigma = 0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = tiny();
  c.episodes = 0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

TEST(PidTuningRequest, WritesTheGainsBesideTheVehicleForPidGainsFor) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("auvrl_tune_pid_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string vehicle = (dir / "nessie.yaml").string();
  std::filesystem::copy_file(test_support::vehicle_path(), vehicle,
                             std::filesystem::copy_options::overwrite_existing);
  PidTuningRequest request;
  request.vehicle_path = vehicle;
  request.config = tiny();
  request.seed = 2;
  request.command_line = "auvrl tune-pid --vehicle nessie.yaml --seed 2";
  std::ostringstream out;
  const PidTuningResult r = run_pid_tuning_request(request, out);
  EXPECT_NE(out.str().find("defaults:"), std::string::npos) << out.str();
  const agent::VehiclePidGains g = agent::pid_gains_for(sim::load_vehicle_file(vehicle));
  EXPECT_TRUE(g.from_file);
  EXPECT_EQ(g.file, (dir / "nessie.pid.yaml").string());
  EXPECT_EQ(agent::pid_gains_text(g.gains, ""), agent::pid_gains_text(r.best, ""));
  std::ostringstream text;
  text << std::ifstream(g.file).rdbuf();
  EXPECT_NE(text.str().find("# Produced by: " + request.command_line), std::string::npos);
  std::filesystem::remove_all(dir);
}

/// Reached, and how long it took at worst, over a grid of way-points near the vertical of the
/// start (the uniform draws the gains were tuned on hold few of them): 0 to 3 m horizontally,
/// 4 m up to 10 m down, in three directions, healthy and with T1 at 10 %.
struct GridResult {
  int episodes = 0;
  int missed = 0;
  double worst_time_s = 0.0;
  double max_tilt_rad = 0.0;
};

GridResult steep_grid(const sim::VehicleModel& model, const agent::PidGains& gains) {
  eval::EvaluationConfig e;
  task::apply_vehicle(model.facts(), e.task);
  agent::PidController pid(model, gains);
  GridResult g;
  std::vector<agent::TrajectoryRow> trajectory;
  for (const double horizontal_m : {0.0, 0.15, 0.3, 0.6, 1.0, 1.5, 2.0, 3.0}) {
    for (const double down_m : {-4.0, 4.0, 10.0}) {
      for (const double bearing_rad : {0.0, 1.5, 3.0}) {
        for (const eval::Scenario s : {eval::Scenario::kTest1, eval::Scenario::kFault}) {
          eval::EvaluationEpisode episode = eval::scenario_episodes(e, s)[0];
          episode.goal_ned_m = episode.start.position_ned_m +
                               Eigen::Vector3d(horizontal_m * std::cos(bearing_rad),
                                               horizontal_m * std::sin(bearing_rad), down_m);
          const eval::SummaryRow row =
              eval::run_evaluation_episode(model, e, pid, episode, &trajectory);
          ++g.episodes;
          for (const agent::TrajectoryRow& r : trajectory) {
            g.max_tilt_rad = std::max({g.max_tilt_rad, std::abs(r.observation.euler_rpy_rad[0]),
                                       std::abs(r.observation.euler_rpy_rad[1])});
          }
          if (!row.reached || row.end_reason == task::EndReason::kFlipped) {
            ++g.missed;
          } else {
            g.worst_time_s = std::max(g.worst_time_s, row.time_to_reach_s);
          }
        }
      }
    }
  }
  return g;
}

TEST(CommittedPidGains, ReachWayPointsNearTheVerticalWithAndWithoutTheFault) {
  for (const char* name : {"nessie7", "bluerov2_heavy", "bluerov2"}) {
    const sim::VehicleModel model =
        sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/" + name + ".yaml");
    // The gains each vehicle's PID uses: the BlueROV2s' files; Nessie VII's compiled defaults
    // (docs/pid.md says why it has no file).
    const agent::VehiclePidGains gains = agent::pid_gains_for(model);
    EXPECT_EQ(gains.from_file, std::string(name) != "nessie7") << name << ": " << gains.file;
    const GridResult g = steep_grid(model, gains.gains);
    EXPECT_EQ(g.missed, 0) << name;
    EXPECT_LT(g.worst_time_s, 40.0) << name;  // measured 21.0 s (nessie7), 16.1 s, 7.7 s
    // Short of the task's 1.2 rad flip angle; measured 0.22 rad (nessie7), 0.89, 0.65.
    EXPECT_LT(g.max_tilt_rad, 1.1) << name;
    std::printf("%s: %d way-points, %d missed, worst %.1f s, tilt up to %.2f rad\n", name,
                g.episodes, g.missed, g.worst_time_s, g.max_tilt_rad);
  }
}

}  // namespace
}  // namespace auvrl::tuning
