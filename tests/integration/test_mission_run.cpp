// auvrl run as a real process (inside this test's private network namespace, so --network
// host): the PID flies a three-way-point mission on auv_sim --realtime at x10 with a thruster
// fault and a current change injected live mid-mission; every way-point is reached, the files are
// written, the fault reached the vehicle and the LCM log holds it. The log played back by
// lcm-logplayer (auvrl replay) gives the same files and plots. Then what is refused before anything
// starts: an existing run directory, a policy that does not fit the vehicle, a replay without a
// log.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;
namespace fs = std::filesystem;

const std::string kConfigDir = AUVRL_CONFIG_DIR;
constexpr double kFaultTimeS = 6.0;  ///< mission time of the fault, s

/// Three way-points around the start; T1 at 10 % from kFaultTimeS on; a current change at 8 s.
std::string write_mission(const std::string& dir) {
  const std::string path = dir + "/mission.yaml";
  std::ofstream(path)
      << "name: triangle\n"
         "start: {position_ned_m: [0, 0, 5], euler_rpy_rad: [0, 0, 0]}\n"
         "waypoints:\n"
         "  - {position_ned_m: [3, 2, 6], reach_radius_m: 0.5, hold_s: 1}\n"
         "  - {position_ned_m: [3, -1, 5], reach_radius_m: 0.5, hold_s: 1}\n"
         "  - {position_ned_m: [0, 0, 5], reach_radius_m: 0.5, hold_s: 1}\n"
         "events:\n"
         "  - {time_s: 6, kind: thruster_efficiency, thruster: 0, efficiency: 0.1}\n"
         "  - {time_s: 8, kind: current, current_ned_mps: [0.1, 0, 0]}\n"
         "time_limit_s: 120\n"
         "limits: {min_depth_m: 1, max_depth_m: 20, max_distance_from_start_m: "
         "30, max_roll_rad: 1, max_pitch_rad: 1, surface_on_abort: false}\n";
  return path;
}

/// A CSV file as a header and rows of cells (no quoted commas in what is read here).
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    throw std::runtime_error("no column " + name);
  }
};

Csv read_csv(const std::string& path) {
  Csv csv;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    if (csv.header.empty()) {
      csv.header = cells;
    } else {
      csv.rows.push_back(cells);
    }
  }
  return csv;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

TEST(MissionRun, ThePidFliesAMissionWithALiveThrusterFaultAndItsLogReplaysToTheSameFiles) {
  const std::string dir = test_support::make_temp_dir("auvrl_mission_run_");
  const std::string mission = write_mission(dir);
  const std::string run = dir + "/run";
  const auto start = std::chrono::steady_clock::now();
  ChildProcess auvrl({test_support::bin_path("auvrl"), "run", "--mission", mission, "--controller",
                      "pid", "--speed", "10", "--run-dir", run, "--network", "host"},
                     dir + "/auvrl.log");
  const int status = auvrl.wait_for_exit(std::chrono::seconds(60));
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ figures  ] auvrl run: three way-points at x10 in %.1f s of wall-clock\n", wall_s);
  ASSERT_EQ(exit_code(status), 0) << auvrl.log();
  const std::string out = auvrl.log();

  const Csv waypoints = read_csv(run + "/waypoints.csv");
  ASSERT_EQ(waypoints.rows.size(), 3u) << out;
  for (const auto& row : waypoints.rows) {
    EXPECT_EQ(row[waypoints.column("reached")], "1") << "way-point " << row[0] << "\n" << out;
    EXPECT_FALSE(row[waypoints.column("time_to_reach_s")].empty());
  }
  // Every state from the mission start, the first at t = 0.
  const Csv trajectory = read_csv(run + "/trajectory.csv");
  ASSERT_GT(trajectory.rows.size(), 50u);
  EXPECT_EQ(trajectory.rows.front()[trajectory.column("t")], "0");

  // The fault was injected at its time and reached the vehicle: from shortly after it T1 gives
  // at most 10 % of its 40 N.
  EXPECT_NE(out.find("(due at 6 s): thruster 0 (T1_forward_port) at 10 % efficiency, injected "
                     "on SIM_FAULT_0"),
            std::string::npos)
      << out;
  const Csv events = read_csv(run + "/events.csv");
  ASSERT_EQ(events.rows.size(), 2u);
  const double injected_s = std::stod(events.rows[0][0]);
  EXPECT_GE(injected_s, kFaultTimeS);
  EXPECT_LT(injected_s, kFaultTimeS + 0.5);
  double before_n = 0, after_n = 0;
  for (const auto& row : trajectory.rows) {
    const double t = std::stod(row[trajectory.column("t")]);
    const double thrust = std::abs(std::stod(row[trajectory.column("thrust_1")]));
    if (t < injected_s) before_n = std::max(before_n, thrust);
    if (t > injected_s + 0.3) after_n = std::max(after_n, thrust);
  }
  EXPECT_GT(before_n, 10.0) << "T1 should work hard before the fault";
  EXPECT_LE(after_n, 4.0 + 1e-6) << "T1 at 10 % of 40 N after the fault";
  // The current change was injected live at its time.
  EXPECT_NE(out.find("(due at 8 s): water current [0.1, 0, 0] m/s NED, injected on SIM_CURRENT_0"),
            std::string::npos)
      << out;
  EXPECT_GE(std::stod(events.rows[1][0]), 8.0);
  EXPECT_LT(std::stod(events.rows[1][0]), 8.5);

  // The LCM log exists and holds the fault.
  EXPECT_GT(fs::file_size(run + "/logs/lcmlog-0000.lcmlog"), 1000u);
  const std::string summary = read_text(run + "/logs/lcmlog-0000-summary.txt");
  EXPECT_NE(summary.find("SIM_FAULT_0 "), std::string::npos) << summary;
  const std::string report = read_text(run + "/report.md");
  EXPECT_NE(report.find("| state | DONE |"), std::string::npos) << report;
  EXPECT_NE(report.find("way-point 3 of 3 done"), std::string::npos) << report;
  EXPECT_TRUE(fs::exists(run + "/vehicle.csv"));
  EXPECT_TRUE(fs::exists(run + "/plots/mission_3d.png") ||
              report.find("No plots: ") != std::string::npos)
      << report;
  for (const char* name : {"logger", "sim", "controller"}) {
    EXPECT_TRUE(fs::exists(run + "/processes/" + name + ".log")) << name;
  }

  // The log replayed by lcm-logplayer (at the speed it was recorded) gives the same files, byte
  // for byte, and the same plots.
  const std::string replay = dir + "/replay";
  ChildProcess replayer({test_support::bin_path("auvrl"), "replay", "--run-dir", run, "--out",
                         replay, "--speed", "1", "--network", "host"},
                        dir + "/replay.log");
  ASSERT_EQ(exit_code(replayer.wait_for_exit(std::chrono::seconds(60))), 0) << replayer.log();
  for (const char* name : {"trajectory.csv", "waypoints.csv", "events.csv", "vehicle.csv"}) {
    EXPECT_EQ(read_text(replay + "/" + name), read_text(run + "/" + name)) << name;
    EXPECT_NE(replayer.log().find(std::string(name) + ": identical"), std::string::npos)
        << replayer.log();
  }
  for (const char* name : {"plots/mission_3d.png", "plots/mission_thrusters.png"}) {
    if (!fs::exists(run + "/" + name)) continue;  // no matplotlib: said in the report above
    EXPECT_EQ(read_text(replay + "/" + name), read_text(run + "/" + name)) << name;
  }
  EXPECT_NE(read_text(replay + "/report.md").find("| trajectory.csv | identical |"),
            std::string::npos);
}

TEST(MissionRun, RefusesAnExistingRunAndAPolicyThatDoesNotFitBeforeStarting) {
  const std::string dir = test_support::make_temp_dir("auvrl_mission_refused_");
  const std::string mission = write_mission(dir);
  const auto refused = [&](const std::vector<std::string>& extra, const std::string& expected) {
    std::vector<std::string> argv = {
        test_support::bin_path("auvrl"), "run", "--mission", mission, "--network", "host"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    ChildProcess p(argv, dir + "/refused.log");
    const int status = p.wait_for_exit(std::chrono::seconds(20));
    EXPECT_EQ(exit_code(status), 2) << p.log();
    EXPECT_NE(p.log().find(expected), std::string::npos) << p.log();
  };
  // dir holds the mission file: not an empty directory.
  refused({"--controller", "pid", "--run-dir", dir}, "already exists and is not empty");
  // Nessie VII's policy on BlueROV2 Heavy: 29 inputs fit no layout of 8 thrusters.
  refused({"--policy", kConfigDir + "/policies/fast.nn", "--vehicle",
           kConfigDir + "/vehicles/bluerov2_heavy.yaml", "--run-dir", dir + "/run"},
          "fits no state layout for 8 thrusters");
  EXPECT_FALSE(fs::exists(dir + "/run")) << "nothing is created for a refused run";

  // A replay of a directory without logs/, named.
  ChildProcess replay(
      {test_support::bin_path("auvrl"), "replay", "--run-dir", dir, "--network", "host"},
      dir + "/replay.log");
  EXPECT_EQ(exit_code(replay.wait_for_exit(std::chrono::seconds(20))), 2) << replay.log();
  EXPECT_NE(replay.log().find(dir + " has no logs/"), std::string::npos) << replay.log();
}

}  // namespace
