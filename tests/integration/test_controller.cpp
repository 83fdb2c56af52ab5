// auv_controller as a real process in a private network namespace. The test is the vehicle's
// driver: it publishes SIM_STATE_0 at the control rate and watches SIM_CMD_0 and MISSION_STATUS,
// so that each safety case can be provoked: states stopped (zero thrust within 3 steps, STALE,
// resumed when they return), a NaN state, a limit exceeded (abort with the reason), a policy
// file that does not fit or is damaged and a malformed mission (refused at start, naming the
// file and the field). Last, the PID flies a two-way-point mission on auv_sim in real time.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/mission_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/nn/file_io.hpp"
#include "common/transport.hpp"
#include "sim/vehicle_model.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;
using Status = auvrl_lcm::mission_status_t;

const std::string kConfigDir = AUVRL_CONFIG_DIR;

/// A one-way-point mission 10 m ahead, limits 2-20 m deep, 50 m from the start.
std::string write_mission(const std::string& dir, const std::string& extra = "") {
  const std::string path = dir + "/mission.yaml";
  std::ofstream(path) << "name: ahead\n"
                         "start: {position_ned_m: [0, 0, 5], euler_rpy_rad: [0, 0, 0]}\n"
                         "waypoints:\n"
                         "  - {position_ned_m: [10, 0, 5], reach_radius_m: 0.5, hold_s: 3}\n"
                         "time_limit_s: 120\n"
                         "limits: {min_depth_m: 2, max_depth_m: 20, max_distance_from_start_m: "
                         "50, max_roll_rad: 1, max_pitch_rad: 1, surface_on_abort: false}\n"
                      << extra;
  return path;
}

/// The driver's side: states out, commands and status in.
class FakeVehicle {
 public:
  FakeVehicle()
      : transport_(transport::make_transport({})),
        facts_(sim::load_vehicle_file(kConfigDir + "/vehicles/nessie7.yaml").facts()),
        commands_(*transport_, channels::sim_command(0), 64),
        status_(*transport_, channels::kMissionStatus, 64) {}

  /// Publishes one state at depth_m (time advancing 0.1 s per state).
  void publish(double depth_m, double surge_mps = 0.0) {
    auvrl_lcm::vehicle_state_t s{};
    s.utime = transport::now_utime();
    s.seq = ++seq_;
    s.step_count = seq_;
    s.sim_time_s = 0.1 * static_cast<double>(seq_);
    s.position_ned_m[2] = depth_m;
    s.velocity_body_mps[0] = surge_mps;
    s.vehicle_name = facts_.name;
    s.vehicle_file_crc32 = static_cast<std::int32_t>(facts_.file_crc32);
    s.num_thrusters = static_cast<std::int8_t>(facts_.num_thrusters());
    s.thrust_realised_n.assign(static_cast<std::size_t>(s.num_thrusters), 0.0);
    transport::publish(*transport_, channels::sim_state(0), s);
    last_state_at = std::chrono::steady_clock::now();
  }
  /// Publishes states at 10 Hz for `seconds`, keeping the newest command and status.
  void drive(double seconds, double depth_m, double surge_mps = 0.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      publish(depth_m, surge_mps);
      listen(0.1);
    }
  }
  /// Handles traffic for `seconds`, keeping the newest command and status.
  void listen(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      transport_->handle(10);
      if (auto c = commands_.take()) {
        command = *c;
        command_at = std::chrono::steady_clock::now();
      }
      if (auto s = status_.take()) status = *s;
    }
  }
  void send(const auvrl_lcm::mission_t& mission) {
    transport::publish(*transport_, channels::mission(0), mission);
  }
  double max_abs_command() const {
    double m = 0;
    for (double f : command.thrust_n) m = std::max(m, std::abs(f));
    return m;
  }

  auvrl_lcm::thruster_cmd_t command{};
  std::chrono::steady_clock::time_point command_at;
  std::chrono::steady_clock::time_point last_state_at;
  Status status{};

 private:
  std::unique_ptr<transport::Transport> transport_;
  VehicleFacts facts_;
  transport::Latest<auvrl_lcm::thruster_cmd_t> commands_;
  transport::Latest<Status> status_;
  std::int64_t seq_ = 0;
};

ChildProcess start_controller(const std::string& dir, const std::vector<std::string>& extra) {
  std::vector<std::string> argv = {test_support::bin_path("auv_controller"), "--mission",
                                   dir + "/mission.yaml", "--controller", "pid"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return ChildProcess(argv, dir + "/controller.log");
}

TEST(Controller, StoppedStatesZeroTheThrustWithinThreeStepsAndResume) {
  const std::string dir = test_support::make_temp_dir("auvrl_controller_stale_");
  write_mission(dir);
  FakeVehicle vehicle;
  ChildProcess controller = start_controller(dir, {});
  vehicle.drive(1.5, 5.0);
  ASSERT_EQ(vehicle.status.supervisor_state, +Status::STATE_ACTIVE) << controller.log();
  EXPECT_GT(vehicle.max_abs_command(), 1.0) << "the PID should drive toward the way-point";
  EXPECT_EQ(vehicle.status.waypoint_count, 1);
  EXPECT_NEAR(vehicle.status.distance_m, 10.0, 1e-6);
  // The states stop: zero thrust and STALE at the third missed step. A step counts as missed
  // half a step after its state was due, so at 3.5 control steps (0.35 s) after the last state.
  const auto stopped = vehicle.last_state_at;
  bool zero_seen = false;
  double zero_after_s = -1;
  while (std::chrono::steady_clock::now() - stopped < std::chrono::seconds(2)) {
    vehicle.listen(0.01);
    if (!zero_seen && vehicle.max_abs_command() == 0.0) {
      zero_seen = true;
      zero_after_s = std::chrono::duration<double>(vehicle.command_at - stopped).count();
    }
  }
  std::printf("[ figures  ] zero thrust %.3f s after the last state\n", zero_after_s);
  ASSERT_TRUE(zero_seen) << controller.log();
  EXPECT_GT(zero_after_s, 0.25) << controller.log();  // two missed steps hold the command
  EXPECT_LT(zero_after_s, 0.45) << controller.log();
  EXPECT_EQ(vehicle.status.supervisor_state, +Status::STATE_STALE) << controller.log();
  EXPECT_EQ(vehicle.status.reason, "no state for 3 control steps");
  EXPECT_EQ(vehicle.status.stale_events, 1);
  // They return: the PID drives again.
  vehicle.drive(0.5, 5.0);
  EXPECT_EQ(vehicle.status.supervisor_state, +Status::STATE_ACTIVE) << controller.log();
  EXPECT_GT(vehicle.max_abs_command(), 1.0);
  EXPECT_EQ(controller.terminate(), 0) << controller.log();
  EXPECT_NE(controller.log().find("STALE: no state for 3 control steps"), std::string::npos)
      << controller.log();
}

TEST(Controller, ANaNStateZeroesTheThrustAndALimitAbortsWithTheReason) {
  const std::string dir = test_support::make_temp_dir("auvrl_controller_limits_");
  write_mission(dir);
  FakeVehicle vehicle;
  ChildProcess controller = start_controller(dir, {});
  vehicle.drive(1.0, 5.0);
  ASSERT_EQ(vehicle.status.supervisor_state, +Status::STATE_ACTIVE) << controller.log();
  vehicle.publish(5.0, std::numeric_limits<double>::quiet_NaN());
  vehicle.listen(0.05);
  EXPECT_EQ(vehicle.status.supervisor_state, +Status::STATE_NON_FINITE) << controller.log();
  EXPECT_EQ(vehicle.max_abs_command(), 0.0);
  EXPECT_EQ(vehicle.status.non_finite_states, 1);
  vehicle.drive(0.3, 5.0);
  EXPECT_EQ(vehicle.status.supervisor_state, +Status::STATE_ACTIVE) << controller.log();
  // Deeper than the mission's 20 m: aborted for good, zero thrust.
  vehicle.drive(0.3, 20.5);
  EXPECT_EQ(vehicle.status.supervisor_state, +Status::STATE_ABORTED) << controller.log();
  EXPECT_NE(vehicle.status.reason.find("max_depth_m"), std::string::npos) << vehicle.status.reason;
  EXPECT_EQ(vehicle.max_abs_command(), 0.0);
  vehicle.drive(0.3, 5.0);
  EXPECT_EQ(vehicle.status.supervisor_state, +Status::STATE_ABORTED);
  EXPECT_EQ(vehicle.max_abs_command(), 0.0);
  controller.terminate();
  EXPECT_NE(controller.log().find("ABORTED: "), std::string::npos) << controller.log();
}

TEST(Controller, ANewMissionSentOverLcmReplacesTheRunningOne) {
  const std::string dir = test_support::make_temp_dir("auvrl_controller_new_mission_");
  write_mission(dir);
  FakeVehicle vehicle;
  ChildProcess controller = start_controller(dir, {});
  vehicle.drive(1.0, 5.0);
  ASSERT_EQ(vehicle.status.mission_name, "ahead") << controller.log();
  auvrl_lcm::mission_t mission{};
  mission.yaml =
      "name: sideways\nstart: {position_ned_m: [0, 0, 5]}\n"
      "waypoints:\n  - {position_ned_m: [0, 8, 6]}\n  - {position_ned_m: [0, 0, 5]}\n"
      "time_limit_s: 60\nlimits: {min_depth_m: 1, max_depth_m: 20, "
      "max_distance_from_start_m: 30, max_roll_rad: 1, max_pitch_rad: 1}\n";
  vehicle.send(mission);
  vehicle.drive(0.5, 5.0);
  EXPECT_EQ(vehicle.status.mission_name, "sideways") << controller.log();
  EXPECT_EQ(vehicle.status.waypoint_count, 2);
  EXPECT_EQ(vehicle.status.goal_ned_m[1], 8.0);
  // One that would change the vehicle is refused; the running mission stays.
  mission.yaml = "vehicle: other.yaml\n" + mission.yaml;
  vehicle.send(mission);
  vehicle.drive(0.5, 5.0);
  EXPECT_EQ(vehicle.status.mission_name, "sideways") << controller.log();
  EXPECT_EQ(controller.terminate(), 0);
  EXPECT_NE(controller.log().find("new mission 'sideways' (2 way-points)"), std::string::npos)
      << controller.log();
  EXPECT_NE(controller.log().find("mission refused, keeping 'sideways'"), std::string::npos)
      << controller.log();
  EXPECT_NE(controller.log().find("cannot change its vehicle"), std::string::npos)
      << controller.log();
}

TEST(Controller, FilesThatDoNotFitAreRefusedAtStartNamingThem) {
  const std::string dir = test_support::make_temp_dir("auvrl_controller_files_");
  write_mission(dir);
  const auto refused = [&](const std::vector<std::string>& argv, const std::string& expected) {
    ChildProcess p(argv, dir + "/refused.log");
    const int status = p.wait_for_exit(std::chrono::seconds(10));
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << p.log();
    EXPECT_NE(p.log().find(expected), std::string::npos) << p.log();
  };
  const std::string bin = test_support::bin_path("auv_controller");
  // Nessie VII's policy on BlueROV2 Heavy: 29 inputs fit no layout of 8 thrusters.
  refused({bin, "--mission", dir + "/mission.yaml", "--policy", kConfigDir + "/policies/fast.nn",
           "--vehicle", kConfigDir + "/vehicles/bluerov2_heavy.yaml"},
          "policy file " + kConfigDir +
              "/policies/fast.nn (vehicle bluerov2_heavy): a policy with 29 inputs fits no "
              "state layout for 8 thrusters");
  // A damaged copy: the CRC fails.
  std::vector<std::uint8_t> bytes = nn::read_file(kConfigDir + "/policies/fast.nn");
  bytes[bytes.size() / 2] ^= 0x40;
  const std::string damaged = dir + "/damaged.nn";
  std::ofstream(damaged, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  refused({bin, "--mission", dir + "/mission.yaml", "--policy", damaged},
          "policy file " + damaged + ": not a usable network file");
  // A way-point with a negative reach radius.
  const std::string bad = dir + "/bad.yaml";
  std::ofstream(bad) << "name: bad\nstart: {position_ned_m: [0, 0, 5], euler_rpy_rad: [0, 0, 0]}\n"
                        "waypoints:\n  - {position_ned_m: [1, 0, 5], reach_radius_m: -1}\n"
                        "time_limit_s: 10\n"
                        "limits: {min_depth_m: 1, max_depth_m: 20, max_distance_from_start_m: 30, "
                        "max_roll_rad: 1, max_pitch_rad: 1}\n";
  refused({bin, "--mission", bad, "--controller", "pid"}, bad);
  refused({bin, "--mission", bad, "--controller", "pid"}, "reach_radius_m");
}

TEST(Controller, ThePidFliesAMissionOnTheRealTimeSimulator) {
  const std::string dir = test_support::make_temp_dir("auvrl_controller_sim_");
  const std::string mission = dir + "/mission.yaml";
  std::ofstream(mission) << "name: two\n"
                            "start: {position_ned_m: [0, 0, 5], euler_rpy_rad: [0, 0, 0]}\n"
                            "waypoints:\n"
                            "  - {position_ned_m: [3, 2, 6], reach_radius_m: 0.5, hold_s: 1}\n"
                            "  - {position_ned_m: [0, 0, 5], reach_radius_m: 0.5, hold_s: 1}\n"
                            "time_limit_s: 120\n"
                            "limits: {min_depth_m: 1, max_depth_m: 20, "
                            "max_distance_from_start_m: 30, max_roll_rad: 1, max_pitch_rad: 1, "
                            "surface_on_abort: false}\n";
  ChildProcess sim({test_support::bin_path("auv_sim"), "--realtime", "--realtime-factor", "10"},
                   dir + "/sim.log");
  // The operator puts the vehicle at the mission's start (the sim steps only reset vehicles).
  auto transport = transport::make_transport({});
  auvrl_lcm::vehicle_reset_t reset{};
  reset.seq = 1;
  reset.position_ned_m[2] = 5.0;
  transport::Latest<auvrl_lcm::vehicle_state_t> states(*transport, channels::sim_state(0));
  for (int i = 0; i < 50 && !states.has_value(); ++i) {
    transport::publish(*transport, channels::sim_reset(0), reset);
    transport->handle(100);
  }
  ASSERT_TRUE(states.has_value()) << sim.log();
  const auto start = std::chrono::steady_clock::now();
  ChildProcess controller({test_support::bin_path("auv_controller"), "--mission", mission,
                           "--controller", "pid", "--speed", "10", "--exit-when-finished"},
                          dir + "/controller.log");
  const int status = controller.wait_for_exit(std::chrono::seconds(60));
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ figures  ] two way-points at x10 in %.1f s of wall-clock\n", wall_s);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << controller.log();
  EXPECT_NE(controller.log().find("way-point 1 of 2 done"), std::string::npos) << controller.log();
  EXPECT_NE(controller.log().find("mission complete"), std::string::npos) << controller.log();
}

}  // namespace
