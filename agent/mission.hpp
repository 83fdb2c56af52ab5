// Missions of several way-points (config/missions/*.yaml, docs/missions.md): where the vehicle
// starts, the way-points it must reach and hold in turn, timed faults and current changes, the
// safety limits it must stay within, and the tracker that follows a vehicle through them. The
// evaluation (`auvrl eval --mission`) and the deployed controller (auv_controller) share it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "common/task/task.hpp"

namespace auvrl::config {
template <class T>
class Table;
}  // namespace auvrl::config

namespace auvrl::agent {

/// One way-point of a mission: reached once the vehicle has stayed within reach_radius_m of it
/// for hold_s without a break (leaving the radius restarts the hold).
struct MissionWaypoint {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();  ///< NED, m (z: depth)
  double reach_radius_m = 0.5;                               ///< m, > 0
  double hold_s = 3.0;                                       ///< s, >= 0
};

/// Something that happens to the vehicle or the water at a time of the mission.
struct MissionEvent {
  enum class Kind {
    kThrusterEfficiency,  ///< from time_s on, thruster `thruster` gives `efficiency` of its thrust
    kCurrent,             ///< from time_s on, the constant water current is current_ned_mps
  };
  double time_s = 0.0;  ///< s since the mission start, >= 0
  Kind kind = Kind::kThrusterEfficiency;
  int thruster = 0;         ///< kThrusterEfficiency: 0-based thruster index
  double efficiency = 1.0;  ///< kThrusterEfficiency: in [0, 1], 1 = healthy
  Eigen::Vector3d current_ned_mps = Eigen::Vector3d::Zero();  ///< kCurrent: NED, m/s
};

/// "thruster_efficiency" or "current"; throws std::invalid_argument naming both otherwise.
MissionEvent::Kind parse_event_kind(const std::string& name);
const char* to_string(MissionEvent::Kind kind);

/// The envelope the vehicle must stay in; leaving it aborts the mission.
struct MissionLimits {
  double min_depth_m = 0.0;  ///< shallowest allowed depth (NED z), m
  double max_depth_m = 0.0;  ///< deepest allowed depth (NED z), m; > min_depth_m
  /// Farthest allowed distance (3-D) from the mission's start position, m.
  double max_distance_from_start_m = 0.0;
  double max_roll_rad = 0.0;   ///< largest allowed |roll|, rad
  double max_pitch_rad = 0.0;  ///< largest allowed |pitch|, rad
  /// What to do on an abort: false, command zero thrust; true, command a surfacing heave.
  bool surface_on_abort = false;
};

/// Where and how the vehicle starts (at rest).
struct MissionStart {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();  ///< NED, m
  Eigen::Vector3d euler_rpy_rad = Eigen::Vector3d::Zero();   ///< roll, pitch, yaw (ZYX), rad
};

/// Standard deviations of the Gaussian noise on what the vehicle reports (0: none).
struct MissionSensorNoise {
  double position_m = 0.0;
  double attitude_rad = 0.0;
  double velocity_mps = 0.0;  ///< body linear velocity
  double angular_rate_rad_s = 0.0;
};

/// A mission as read from its file (read_mission_file).
struct Mission {
  std::string name;         ///< the file's `name:`, else the file name without extension
  std::string source_file;  ///< the file it was read from ("" if built in code)
  /// The vehicle file, resolved against the mission file's folder; empty: the caller's default.
  std::string vehicle_path;
  MissionStart start;
  std::vector<MissionWaypoint> waypoints;  ///< at least one, in order
  std::vector<MissionEvent> events;        ///< sorted by time (file order among equal times)
  MissionSensorNoise sensor_noise;
  double time_limit_s = 0.0;  ///< the mission ends after this, s since its start; > 0
  MissionLimits limits;
};

/// The keys of a mission file (for the reader and docs/missions.md).
const config::Table<Mission>& mission_table();

/// Reads a mission file. Throws config::ConfigError naming the file, the key and the line (an
/// unknown key, a way-point without position, a negative radius, an inverted depth range, an
/// event without its values, ...) or the file alone (missing, not YAML).
Mission read_mission_file(const std::string& path);
/// The same for a mission sent as YAML text (a MISSION_<id> message); `origin` names it in
/// errors and is its name if it has none. It must not name a vehicle (the controller's is
/// fixed).
Mission read_mission_text(const std::string& yaml_text, const std::string& origin);

/// Why an observation leaves the mission's limits, naming the limit and the value (e.g.
/// "depth 20.31 m > max_depth_m 20 m"); nothing while it is inside them.
std::optional<std::string> check_limits(const MissionLimits& limits,
                                        const Eigen::Vector3d& start_position_ned_m,
                                        const task::Observation& observation);

/// check_limits with the mission's own limits and start.
std::optional<std::string> check_limits(const Mission& mission,
                                        const task::Observation& observation);

/// What became of one way-point. Times are on the clock given to MissionTracker::update.
struct WaypointResult {
  bool reached = false;  ///< held within its radius for its hold time
  /// First time within the radius while it was the current way-point, s since the mission
  /// start; negative if never.
  double time_to_reach_s = -1.0;
  /// The same, from the previous way-point's completion (the mission start for the first), s;
  /// negative if never.
  double time_from_previous_s = -1.0;
  double completed_time_s = -1.0;  ///< when its hold ended, s since the mission start
  /// Mean distance to it from the first arrival until it was completed (or the mission
  /// ended), m; negative if never arrived.
  double hold_error_m = -1.0;
};

/// Follows a vehicle through a mission's way-points: update() with every observed position
/// advances to the next way-point once the current one has been held (within its radius
/// continuously for its hold time).
class MissionTracker {
 public:
  /// start_time_s: the clock of the mission start (update's times are on the same clock).
  /// Throws std::invalid_argument on no way-points, a radius <= 0 or a hold < 0.
  explicit MissionTracker(std::vector<MissionWaypoint> waypoints, double start_time_s = 0.0);

  /// Feeds one observation (times non-decreasing); may complete any number of way-points.
  void update(double time_s, const Eigen::Vector3d& position_ned_m);

  int index() const { return index_; }  ///< the current way-point, from 0; count() when done
  int count() const { return static_cast<int>(waypoints_.size()); }
  bool done() const { return index_ >= count(); }
  /// The current way-point (the last one once done).
  const MissionWaypoint& current() const;
  const Eigen::Vector3d& goal_ned_m() const { return current().position_ned_m; }
  /// Distance from the last position fed to the current way-point, m (infinity before any).
  double distance_m() const { return distance_m_; }
  double elapsed_s() const { return last_time_s_ - start_time_s_; }  ///< since the start, s
  /// Time held so far within the current way-point's radius, s (0 outside).
  double held_s() const;
  const std::vector<WaypointResult>& results() const { return results_; }
  const std::vector<MissionWaypoint>& waypoints() const { return waypoints_; }

 private:
  /// Checks the current way-point against one observation; true if it was completed.
  bool visit(double time_s, const Eigen::Vector3d& position_ned_m);

  std::vector<MissionWaypoint> waypoints_;
  std::vector<WaypointResult> results_;
  double start_time_s_;
  double last_time_s_;
  int index_ = 0;
  double distance_m_;
  bool inside_ = false;
  double hold_start_s_ = 0.0;
  double previous_completion_s_ = 0.0;  ///< since the mission start
  double error_sum_m_ = 0.0;            ///< over the samples since the first arrival
  int error_samples_ = 0;
};

}  // namespace auvrl::agent
