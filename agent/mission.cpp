#include "agent/mission.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "common/config/table.hpp"

namespace auvrl::agent {
namespace {

config::Table<MissionWaypoint> make_waypoint_table() {
  using W = MissionWaypoint;
  config::Table<W> t("waypoints", "the way-points, in the order the vehicle must reach them");
  t.field("position_ned_m", &W::position_ned_m, "m", "the way-point, NED (z: depth)").required();
  t.field("reach_radius_m", &W::reach_radius_m, "m", "within this distance it counts as reached")
      .positive();
  t.field("hold_s", &W::hold_s, "s", "stay within the radius this long, unbroken, to complete it")
      .range(0.0);
  return t;
}

/// Each kind needs its own keys and refuses the other kind's.
void check_event_keys(const config::Section& section, MissionEvent& event) {
  const bool thruster = event.kind == MissionEvent::Kind::kThrusterEfficiency;
  const char* needed[2] = {"thruster", "efficiency"};
  for (const char* key : needed) {
    if (thruster && !section.has(key)) section.fail(key, "missing (kind thruster_efficiency)");
    if (!thruster && section.has(key)) section.fail(key, "only for kind thruster_efficiency");
  }
  if (!thruster && !section.has("current_ned_mps")) {
    section.fail("current_ned_mps", "missing (kind current)");
  }
  if (thruster && section.has("current_ned_mps")) {
    section.fail("current_ned_mps", "only for kind current");
  }
}

config::Table<MissionEvent> make_event_table() {
  using E = MissionEvent;
  config::Table<E> t("events", "timed faults and current changes");
  t.field("time_s", &E::time_s, "s", "when it happens, since the mission start")
      .required()
      .range(0.0);
  t.choice("kind", &E::kind, parse_event_kind, to_string, "thruster_efficiency, current",
           "what happens")
      .required();
  t.field("thruster", &E::thruster, "",
          "kind thruster_efficiency (required there): which thruster, from 0")
      .range(0);
  t.field("efficiency", &E::efficiency, "",
          "kind thruster_efficiency (required there): share of its thrust it gives")
      .range(0.0, 1.0);
  t.field("current_ned_mps", &E::current_ned_mps, "m/s",
          "kind current (required there): the constant water velocity from then on, NED");
  t.validate(check_event_keys);
  return t;
}

config::Table<MissionStart> make_start_table() {
  using S = MissionStart;
  config::Table<S> t("start", "where the vehicle starts, at rest");
  t.field("position_ned_m", &S::position_ned_m, "m", "start position, NED").required();
  t.field("euler_rpy_rad", &S::euler_rpy_rad, "rad", "start roll, pitch, yaw (ZYX)");
  return t;
}

config::Table<MissionSensorNoise> make_noise_table() {
  using N = MissionSensorNoise;
  config::Table<N> t("sensor_noise",
                     "standard deviations of the noise on what the vehicle reports");
  t.field("position_m", &N::position_m, "m", "on the position").range(0.0);
  t.field("attitude_rad", &N::attitude_rad, "rad", "on roll, pitch and yaw").range(0.0);
  t.field("velocity_mps", &N::velocity_mps, "m/s", "on the body velocities").range(0.0);
  t.field("angular_rate_rad_s", &N::angular_rate_rad_s, "rad/s", "on the body rates").range(0.0);
  return t;
}

config::Table<MissionLimits> make_limits_table() {
  using L = MissionLimits;
  config::Table<L> t("limits", "the safety envelope: leaving it aborts the mission");
  t.field("min_depth_m", &L::min_depth_m, "m", "shallowest allowed depth (NED z)").required();
  t.field("max_depth_m", &L::max_depth_m, "m", "deepest allowed depth (NED z), > min_depth_m")
      .required();
  t.field("max_distance_from_start_m", &L::max_distance_from_start_m, "m",
          "farthest allowed distance from the start position")
      .required()
      .positive();
  t.field("max_roll_rad", &L::max_roll_rad, "rad", "largest allowed |roll|").required().positive();
  t.field("max_pitch_rad", &L::max_pitch_rad, "rad", "largest allowed |pitch|")
      .required()
      .positive();
  t.field("surface_on_abort", &L::surface_on_abort, "",
          "on an abort: true, command a surfacing heave; false, zero thrust");
  t.validate([](const config::Section& section, MissionLimits& limits) {
    if (limits.max_depth_m <= limits.min_depth_m) {
      section.fail("max_depth_m", fmt::format("must be > min_depth_m ({}), got {}",
                                              limits.min_depth_m, limits.max_depth_m));
    }
  });
  return t;
}

config::Table<Mission> make_mission_table() {
  using M = Mission;
  config::Table<M> t("mission",
                     "A mission (config/missions/*.yaml): a start, way-points to reach and hold "
                     "in turn, timed events, a time limit and safety limits.");
  t.field("name", &M::name, "", "shown in the output (default: the file name without .yaml)");
  t.field("vehicle", &M::vehicle_path, "path",
          "vehicle file, relative to this file's folder (default: the caller's vehicle)");
  t.section("start", make_start_table(), &M::start).required();
  t.list("waypoints", make_waypoint_table(), &M::waypoints, 1).required();
  t.list("events", make_event_table(), &M::events);
  t.section("sensor_noise", make_noise_table(), &M::sensor_noise);
  t.field("time_limit_s", &M::time_limit_s, "s", "the mission ends after this")
      .required()
      .positive();
  t.section("limits", make_limits_table(), &M::limits).required();
  return t;
}

/// "dir/tour.yaml" -> "tour".
std::string file_stem(const std::string& path) {
  const auto slash = path.rfind('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto dot = name.rfind('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

}  // namespace

MissionEvent::Kind parse_event_kind(const std::string& name) {
  if (name == "thruster_efficiency") return MissionEvent::Kind::kThrusterEfficiency;
  if (name == "current") return MissionEvent::Kind::kCurrent;
  throw std::invalid_argument("expected thruster_efficiency or current, got '" + name + "'");
}

const char* to_string(MissionEvent::Kind kind) {
  return kind == MissionEvent::Kind::kCurrent ? "current" : "thruster_efficiency";
}

const config::Table<Mission>& mission_table() {
  static const config::Table<Mission> table = make_mission_table();
  return table;
}

namespace {

/// Reads a mission from its root section (a file's or a message's), events sorted by time.
Mission read_mission(config::Section& root) {
  Mission mission;
  mission_table().read_keys(root, mission);
  root.finish();
  std::stable_sort(
      mission.events.begin(), mission.events.end(),
      [](const MissionEvent& a, const MissionEvent& b) { return a.time_s < b.time_s; });
  return mission;
}

}  // namespace

Mission read_mission_file(const std::string& path) {
  config::Section root = config::load_file(path);
  Mission mission = read_mission(root);
  mission.source_file = path;
  if (mission.name.empty()) mission.name = file_stem(path);
  if (!mission.vehicle_path.empty()) {
    mission.vehicle_path = std::filesystem::path(config::resolve_path(root, mission.vehicle_path))
                               .lexically_normal()
                               .string();
  }
  return mission;
}

Mission read_mission_text(const std::string& yaml_text, const std::string& origin) {
  config::Section root = config::load_text(yaml_text, origin);
  Mission mission = read_mission(root);
  if (!mission.vehicle_path.empty()) {
    root.fail("vehicle", "a mission sent to a running controller cannot change its vehicle");
  }
  if (mission.name.empty()) mission.name = origin;
  return mission;
}

std::optional<std::string> check_limits(const MissionLimits& limits,
                                        const Eigen::Vector3d& start_position_ned_m,
                                        const task::Observation& observation) {
  const double depth_m = observation.position_ned_m.z();
  if (!(depth_m >= limits.min_depth_m)) {
    return fmt::format("depth {:.2f} m < min_depth_m {} m", depth_m, limits.min_depth_m);
  }
  if (!(depth_m <= limits.max_depth_m)) {
    return fmt::format("depth {:.2f} m > max_depth_m {} m", depth_m, limits.max_depth_m);
  }
  const double distance_m = (observation.position_ned_m - start_position_ned_m).norm();
  if (!(distance_m <= limits.max_distance_from_start_m)) {
    return fmt::format("distance from start {:.2f} m > max_distance_from_start_m {} m", distance_m,
                       limits.max_distance_from_start_m);
  }
  const double roll_rad = observation.euler_rpy_rad.x();
  if (!(std::abs(roll_rad) <= limits.max_roll_rad)) {
    return fmt::format("roll {:.3f} rad beyond max_roll_rad {} rad", roll_rad, limits.max_roll_rad);
  }
  const double pitch_rad = observation.euler_rpy_rad.y();
  if (!(std::abs(pitch_rad) <= limits.max_pitch_rad)) {
    return fmt::format("pitch {:.3f} rad beyond max_pitch_rad {} rad", pitch_rad,
                       limits.max_pitch_rad);
  }
  return std::nullopt;
}

std::optional<std::string> check_limits(const Mission& mission,
                                        const task::Observation& observation) {
  return check_limits(mission.limits, mission.start.position_ned_m, observation);
}

MissionTracker::MissionTracker(std::vector<MissionWaypoint> waypoints, double start_time_s)
    : waypoints_(std::move(waypoints)),
      results_(waypoints_.size()),
      start_time_s_(start_time_s),
      last_time_s_(start_time_s),
      distance_m_(std::numeric_limits<double>::infinity()) {
  if (waypoints_.empty()) throw std::invalid_argument("a mission needs at least one way-point");
  for (std::size_t i = 0; i < waypoints_.size(); ++i) {
    const MissionWaypoint& w = waypoints_[i];
    if (!(w.reach_radius_m > 0) || !(w.hold_s >= 0) || !w.position_ned_m.allFinite()) {
      throw std::invalid_argument(fmt::format(
          "way-point {}: needs a finite position, reach_radius_m > 0 and hold_s >= 0", i));
    }
  }
}

const MissionWaypoint& MissionTracker::current() const {
  return waypoints_[static_cast<std::size_t>(std::min(index_, count() - 1))];
}

double MissionTracker::held_s() const {
  return inside_ && !done() ? last_time_s_ - hold_start_s_ : 0.0;
}

void MissionTracker::update(double time_s, const Eigen::Vector3d& position_ned_m) {
  last_time_s_ = time_s;
  while (!done() && visit(time_s, position_ned_m)) {
  }
}

bool MissionTracker::visit(double time_s, const Eigen::Vector3d& position_ned_m) {
  // Sample times are sums of control steps: a hold of 3 s may end at 2.9999999999 s.
  constexpr double kTimeToleranceS = 1e-9;
  const MissionWaypoint& goal = waypoints_[static_cast<std::size_t>(index_)];
  WaypointResult& result = results_[static_cast<std::size_t>(index_)];
  const double since_start_s = time_s - start_time_s_;
  distance_m_ = (position_ned_m - goal.position_ned_m).norm();
  if (distance_m_ <= goal.reach_radius_m) {
    if (!inside_) hold_start_s_ = time_s;
    inside_ = true;
    if (result.time_to_reach_s < 0) {
      result.time_to_reach_s = since_start_s;
      result.time_from_previous_s = since_start_s - previous_completion_s_;
    }
  } else {
    inside_ = false;
  }
  if (result.time_to_reach_s >= 0) {
    error_sum_m_ += distance_m_;
    ++error_samples_;
    result.hold_error_m = error_sum_m_ / error_samples_;
  }
  if (!inside_ || time_s - hold_start_s_ < goal.hold_s - kTimeToleranceS) return false;
  result.reached = true;
  result.completed_time_s = since_start_s;
  previous_completion_s_ = since_start_s;
  ++index_;
  inside_ = false;
  error_sum_m_ = 0.0;
  error_samples_ = 0;
  return true;
}

}  // namespace auvrl::agent
