// Missions: the file reader (a good file, malformed files and their messages), the limits check
// and the way-point tracker (holds, restarts, results).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "agent/mission.hpp"
#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"

namespace auvrl::agent {
namespace {

/// A scratch directory, removed at the end of the test.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() /
           ("auvrl_mission_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string file = (path / name).string();
    std::ofstream(file) << text;
    return file;
  }
};

const char* const kLimits =
    "limits:\n"
    "  min_depth_m: 1\n"
    "  max_depth_m: 20\n"
    "  max_distance_from_start_m: 30\n"
    "  max_roll_rad: 0.5\n"
    "  max_pitch_rad: 0.6\n";

TEST(MissionFile, ReadsEveryKey) {
  const TempDir dir;
  const std::string path = dir.write("tour.yaml",
                                     "vehicle: ../vehicles/nessie7.yaml\n"
                                     "start:\n"
                                     "  position_ned_m: [0, 0, 5]\n"
                                     "  euler_rpy_rad: [0, 0, 3.1]\n"
                                     "waypoints:\n"
                                     "  - position_ned_m: [7, 6, 10]\n"
                                     "  - position_ned_m: [-2, 1, 4]\n"
                                     "    reach_radius_m: 1.5\n"
                                     "    hold_s: 0\n"
                                     "events:\n"
                                     "  - time_s: 12\n"
                                     "    kind: current\n"
                                     "    current_ned_mps: [0.1, -0.2, 0]\n"
                                     "  - time_s: 0\n"
                                     "    kind: thruster_efficiency\n"
                                     "    thruster: 2\n"
                                     "    efficiency: 0.25\n"
                                     "sensor_noise:\n"
                                     "  position_m: 0.05\n"
                                     "time_limit_s: 120\n" +
                                         std::string(kLimits) + "  surface_on_abort: true\n");
  const Mission m = read_mission_file(path);
  EXPECT_EQ(m.name, "tour");
  EXPECT_EQ(m.source_file, path);
  EXPECT_EQ(m.vehicle_path, (dir.path.parent_path() / "vehicles/nessie7.yaml").string());
  EXPECT_EQ(m.start.position_ned_m, Eigen::Vector3d(0, 0, 5));
  EXPECT_EQ(m.start.euler_rpy_rad, Eigen::Vector3d(0, 0, 3.1));
  ASSERT_EQ(m.waypoints.size(), 2u);
  EXPECT_EQ(m.waypoints[0].position_ned_m, Eigen::Vector3d(7, 6, 10));
  EXPECT_EQ(m.waypoints[0].reach_radius_m, 0.5);
  EXPECT_EQ(m.waypoints[0].hold_s, 3.0);
  EXPECT_EQ(m.waypoints[1].reach_radius_m, 1.5);
  EXPECT_EQ(m.waypoints[1].hold_s, 0.0);
  // Sorted by time.
  ASSERT_EQ(m.events.size(), 2u);
  EXPECT_EQ(m.events[0].kind, MissionEvent::Kind::kThrusterEfficiency);
  EXPECT_EQ(m.events[0].thruster, 2);
  EXPECT_EQ(m.events[0].efficiency, 0.25);
  EXPECT_EQ(m.events[1].kind, MissionEvent::Kind::kCurrent);
  EXPECT_EQ(m.events[1].time_s, 12.0);
  EXPECT_EQ(m.events[1].current_ned_mps, Eigen::Vector3d(0.1, -0.2, 0));
  EXPECT_EQ(m.sensor_noise.position_m, 0.05);
  EXPECT_EQ(m.sensor_noise.attitude_rad, 0.0);
  EXPECT_EQ(m.time_limit_s, 120.0);
  EXPECT_EQ(m.limits.min_depth_m, 1.0);
  EXPECT_EQ(m.limits.max_depth_m, 20.0);
  EXPECT_EQ(m.limits.max_distance_from_start_m, 30.0);
  EXPECT_EQ(m.limits.max_roll_rad, 0.5);
  EXPECT_EQ(m.limits.max_pitch_rad, 0.6);
  EXPECT_TRUE(m.limits.surface_on_abort);
}

TEST(MissionFile, NameAndVehicleAreOptional) {
  const TempDir dir;
  const std::string path = dir.write("one.yaml",
                                     "name: first dive\n"
                                     "start: {position_ned_m: [0, 0, 5]}\n"
                                     "waypoints: [{position_ned_m: [1, 2, 3]}]\n"
                                     "time_limit_s: 10\n" +
                                         std::string(kLimits));
  const Mission m = read_mission_file(path);
  EXPECT_EQ(m.name, "first dive");
  EXPECT_TRUE(m.vehicle_path.empty());
  EXPECT_TRUE(m.events.empty());
  EXPECT_FALSE(m.limits.surface_on_abort);
}

/// The ConfigError that a mission file with `text` raises (fails the test if none).
config::ConfigError mission_error(const TempDir& dir, const std::string& text) {
  const std::string path = dir.write("bad.yaml", text);
  try {
    read_mission_file(path);
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return config::ConfigError("none");
}

bool mentions(const config::ConfigError& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

TEST(MissionFile, RefusesMalformedFilesNamingKeyAndLine) {
  const TempDir dir;
  const std::string head = "start: {position_ned_m: [0, 0, 5]}\ntime_limit_s: 60\n";
  const std::string limits(kLimits);

  const auto no_position = mission_error(
      dir, head + "waypoints:\n  - position_ned_m: [1, 1, 6]\n  - hold_s: 2\n" + limits);
  EXPECT_EQ(no_position.key(), "waypoints[1].position_ned_m");
  EXPECT_TRUE(mentions(no_position, "missing")) << no_position.what();
  EXPECT_TRUE(mentions(no_position, "line 5")) << no_position.what();

  const auto negative = mission_error(
      dir, head + "waypoints:\n  - position_ned_m: [1, 1, 6]\n    reach_radius_m: -0.5\n" + limits);
  EXPECT_EQ(negative.key(), "waypoints[0].reach_radius_m");
  EXPECT_TRUE(mentions(negative, "> 0")) << negative.what();
  EXPECT_TRUE(mentions(negative, "line 5")) << negative.what();

  const std::string waypoint = "waypoints: [{position_ned_m: [1, 1, 6]}]\n";
  const auto inverted =
      mission_error(dir, head + waypoint +
                             "limits:\n  min_depth_m: 10\n  max_depth_m: 2\n"
                             "  max_distance_from_start_m: 30\n  max_roll_rad: 0.5\n"
                             "  max_pitch_rad: 0.5\n");
  EXPECT_EQ(inverted.key(), "limits.max_depth_m");
  EXPECT_TRUE(mentions(inverted, "min_depth_m")) << inverted.what();
  EXPECT_TRUE(mentions(inverted, "line 6")) << inverted.what();

  EXPECT_EQ(mission_error(dir, head + limits).key(), "waypoints");
  EXPECT_EQ(mission_error(dir, head + "waypoints: []\n" + limits).key(), "waypoints");
  EXPECT_EQ(mission_error(dir, head + waypoint).key(), "limits");
  EXPECT_EQ(mission_error(dir, "start: {position_ned_m: [0, 0, 5]}\n" + waypoint + limits).key(),
            "time_limit_s");
  EXPECT_EQ(mission_error(dir, head + waypoint + limits + "wayponts: []\n").key(), "wayponts");
  EXPECT_EQ(mission_error(dir, head + "waypoints: [{position_ned_m: [1, 1]}]\n" + limits).key(),
            "waypoints[0].position_ned_m");
  EXPECT_EQ(
      mission_error(dir, head + waypoint + limits + "events: [{time_s: 1, kind: leak}]\n").key(),
      "events[0].kind");
  const auto no_efficiency = mission_error(
      dir, head + waypoint + limits + "events: [{time_s: 1, kind: thruster_efficiency}]\n");
  EXPECT_EQ(no_efficiency.key(), "events[0].thruster");
  EXPECT_EQ(mission_error(dir, head + waypoint + limits +
                                   "events: [{time_s: 1, kind: current, thruster: 1}]\n")
                .key(),
            "events[0].thruster");
  EXPECT_EQ(
      mission_error(dir, head + waypoint + limits + "events: [{time_s: 1, kind: current}]\n").key(),
      "events[0].current_ned_mps");
  EXPECT_EQ(mission_error(dir, head + waypoint + limits +
                                   "events: [{time_s: 1, kind: thruster_efficiency, thruster: 0, "
                                   "efficiency: 1.5}]\n")
                .key(),
            "events[0].efficiency");
  EXPECT_EQ(mission_error(dir, head + waypoint + limits + "sensor_noise: {position_m: -1}\n").key(),
            "sensor_noise.position_m");
}

TEST(MissionFile, MissingFileIsAnErrorNamingIt) {
  EXPECT_THROW(read_mission_file("/nonexistent/auvrl/mission.yaml"), config::ConfigError);
}

TEST(MissionFile, DocsMissionsHoldsTheKeysTableAsGenerated) {
  std::ifstream in(std::string(AUVRL_DOCS_DIR) + "/missions.md");
  ASSERT_TRUE(in.good());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string table = config::render_markdown({config::section_doc(mission_table())}, "");
  EXPECT_NE(text.find(table), std::string::npos)
      << "docs/missions.md: replace its `mission` table with `auvrl config-doc`'s:\n"
      << table;
}

TEST(MissionFile, TableDocumentsEveryKeyWithItsUnit) {
  const config::SectionDoc doc = config::section_doc(mission_table());
  std::vector<std::string> keys;
  for (const config::FieldDoc& row : doc.rows) {
    keys.push_back(row.key);
    EXPECT_FALSE(row.doc.empty()) << row.key;
  }
  for (const char* key : {"start.position_ned_m", "waypoints[].reach_radius_m", "events[].kind",
                          "limits.surface_on_abort", "sensor_noise.angular_rate_rad_s"}) {
    EXPECT_NE(std::find(keys.begin(), keys.end(), key), keys.end()) << key;
  }
}

MissionLimits test_limits() {
  MissionLimits limits;
  limits.min_depth_m = 1.0;
  limits.max_depth_m = 20.0;
  limits.max_distance_from_start_m = 30.0;
  limits.max_roll_rad = 0.5;
  limits.max_pitch_rad = 0.6;
  return limits;
}

TEST(MissionLimits, NamesTheLimitAndTheValue) {
  const MissionLimits limits = test_limits();
  const Eigen::Vector3d start(0, 0, 5);
  task::Observation obs;
  obs.position_ned_m = Eigen::Vector3d(3, 4, 10);
  EXPECT_FALSE(check_limits(limits, start, obs));
  obs.position_ned_m.z() = 0.5;
  ASSERT_TRUE(check_limits(limits, start, obs));
  EXPECT_EQ(*check_limits(limits, start, obs), "depth 0.50 m < min_depth_m 1 m");
  obs.position_ned_m.z() = 21.0;
  EXPECT_EQ(*check_limits(limits, start, obs), "depth 21.00 m > max_depth_m 20 m");
  obs.position_ned_m = Eigen::Vector3d(30, 4, 5);
  EXPECT_EQ(*check_limits(limits, start, obs),
            "distance from start 30.27 m > max_distance_from_start_m 30 m");
  obs.position_ned_m = start;
  obs.euler_rpy_rad = Eigen::Vector3d(-0.55, 0, 0);
  EXPECT_EQ(*check_limits(limits, start, obs), "roll -0.550 rad beyond max_roll_rad 0.5 rad");
  obs.euler_rpy_rad = Eigen::Vector3d(0, 0.7, 3.0);
  EXPECT_EQ(*check_limits(limits, start, obs), "pitch 0.700 rad beyond max_pitch_rad 0.6 rad");
  obs.position_ned_m.x() = std::nan("");
  EXPECT_TRUE(check_limits(limits, start, obs));  // a non-finite state is never inside
}

MissionWaypoint waypoint(double x, double radius_m, double hold_s) {
  MissionWaypoint w;
  w.position_ned_m = Eigen::Vector3d(x, 0, 5);
  w.reach_radius_m = radius_m;
  w.hold_s = hold_s;
  return w;
}

TEST(MissionTracker, AdvancesAfterAnUnbrokenHold) {
  MissionTracker tracker({waypoint(10, 0.5, 1.0), waypoint(20, 0.5, 0.0)});
  EXPECT_EQ(tracker.count(), 2);
  EXPECT_EQ(tracker.index(), 0);
  EXPECT_EQ(tracker.goal_ned_m(), Eigen::Vector3d(10, 0, 5));
  tracker.update(0.0, Eigen::Vector3d(0, 0, 5));
  EXPECT_DOUBLE_EQ(tracker.distance_m(), 10.0);
  // Arrives at t = 5 (0.4 m off), holds 0.7 s, leaves, comes back at 6 (0.2 m off).
  double t = 0.0;
  for (int step = 1; step <= 50; ++step) tracker.update(t = step * 0.1, Eigen::Vector3d(1, 0, 5));
  tracker.update(5.0, Eigen::Vector3d(9.6, 0, 5));
  tracker.update(5.7, Eigen::Vector3d(9.6, 0, 5));
  EXPECT_NEAR(tracker.held_s(), 0.7, 1e-12);
  tracker.update(5.8, Eigen::Vector3d(9.0, 0, 5));  // 1 m off: the hold restarts
  EXPECT_EQ(tracker.held_s(), 0.0);
  tracker.update(6.0, Eigen::Vector3d(9.8, 0, 5));
  tracker.update(6.9, Eigen::Vector3d(9.8, 0, 5));
  EXPECT_EQ(tracker.index(), 0);
  tracker.update(7.0, Eigen::Vector3d(9.8, 0, 5));
  EXPECT_EQ(tracker.index(), 1);
  EXPECT_EQ(tracker.goal_ned_m(), Eigen::Vector3d(20, 0, 5));
  EXPECT_FALSE(tracker.done());
  const WaypointResult& first = tracker.results()[0];
  EXPECT_TRUE(first.reached);
  EXPECT_EQ(first.time_to_reach_s, 5.0);  // the first arrival, not the hold that completed
  EXPECT_EQ(first.time_from_previous_s, 5.0);
  EXPECT_NEAR(first.completed_time_s, 7.0, 1e-12);
  // Samples from the arrival to completion: 0.4, 0.4, 1.0, 0.2, 0.2, 0.2.
  EXPECT_NEAR(first.hold_error_m, (0.4 + 0.4 + 1.0 + 0.2 * 3) / 6, 1e-12);
  EXPECT_FALSE(tracker.results()[1].reached);
  EXPECT_LT(tracker.results()[1].time_to_reach_s, 0.0);
  EXPECT_LT(tracker.results()[1].hold_error_m, 0.0);

  // A hold of 0 completes on the first sample inside.
  tracker.update(9.0, Eigen::Vector3d(20.3, 0, 5));
  EXPECT_TRUE(tracker.done());
  EXPECT_EQ(tracker.index(), 2);
  const WaypointResult& second = tracker.results()[1];
  EXPECT_TRUE(second.reached);
  EXPECT_EQ(second.time_to_reach_s, 9.0);
  EXPECT_NEAR(second.time_from_previous_s, 2.0, 1e-12);
  EXPECT_NEAR(second.hold_error_m, 0.3, 1e-12);
  EXPECT_EQ(tracker.current().position_ned_m, Eigen::Vector3d(20, 0, 5));
  tracker.update(10.0, Eigen::Vector3d(0, 0, 5));  // nothing changes once done
  EXPECT_TRUE(tracker.done());
  EXPECT_NEAR(tracker.results()[1].hold_error_m, 0.3, 1e-12);
  EXPECT_EQ(tracker.elapsed_s(), 10.0);
}

TEST(MissionTracker, CompletesCoincidentWaypointsOnOneSampleAndCountsFromItsStart) {
  MissionTracker tracker({waypoint(1, 0.5, 0.0), waypoint(1.2, 0.5, 0.0), waypoint(8, 1, 2)},
                         100.0);
  tracker.update(101.5, Eigen::Vector3d(1.1, 0, 5));
  EXPECT_EQ(tracker.index(), 2);
  EXPECT_EQ(tracker.results()[0].time_to_reach_s, 1.5);
  EXPECT_EQ(tracker.results()[1].time_to_reach_s, 1.5);
  EXPECT_EQ(tracker.results()[1].time_from_previous_s, 0.0);
  EXPECT_EQ(tracker.elapsed_s(), 1.5);
}

TEST(MissionTracker, RefusesUnusableWaypoints) {
  EXPECT_THROW(MissionTracker({}), std::invalid_argument);
  EXPECT_THROW(MissionTracker({waypoint(1, 0.0, 1.0)}), std::invalid_argument);
  EXPECT_THROW(MissionTracker({waypoint(1, 0.5, -1.0)}), std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::agent
