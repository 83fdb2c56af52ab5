#include "launcher/mission_record.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace auvrl::launcher {

namespace {

task::Observation observation_of(const auvrl_lcm::vehicle_state_t& msg) {
  task::Observation o;
  for (int i = 0; i < 3; ++i) {
    o.position_ned_m[i] = msg.position_ned_m[i];
    o.euler_rpy_rad[i] = msg.euler_rpy_rad[i];
    o.velocity_body_mps[i] = msg.velocity_body_mps[i];
    o.angular_rate_body_rad_s[i] = msg.angular_rate_body_rad_s[i];
  }
  return o;
}

/// Efficiencies and currents are copied, not computed: equal means the same double within the
/// rounding of text.
constexpr double kCopiedValueTolerance = 1e-9;

}  // namespace

MissionEventLog::MissionEventLog(const agent::Mission& mission,
                                 std::vector<std::string> thruster_names)
    : thruster_names_(std::move(thruster_names)), efficiency_(thruster_names_.size(), 1.0) {
  for (const agent::MissionEvent& e : mission.events) {
    if (e.kind == agent::MissionEvent::Kind::kCurrent && e.time_s == 0.0) {
      const Eigen::Vector3d& c = e.current_ned_mps;
      start_current_ned_mps_ = c;
      events_.push_back(
          {0.0, fmt::format("t=0 s: water current [{:g}, {:g}, {:g}] m/s NED, set with the "
                            "vehicle's reset",
                            c.x(), c.y(), c.z())});
      continue;
    }
    live_.push_back(e);
  }
  live_seen_.assign(live_.size(), false);
}

std::string MissionEventLog::take_due(
    const std::function<bool(const agent::MissionEvent&)>& matches) {
  for (std::size_t k = 0; k < live_.size(); ++k) {
    if (live_seen_[k] || !matches(live_[k])) continue;
    live_seen_[k] = true;
    return fmt::format("due at {:g} s", live_[k].time_s);
  }
  return "not one of the mission's events";
}

MissionRunEvent MissionEventLog::add_current(const auvrl_lcm::water_current_t& current,
                                             std::optional<double> mission_time_s,
                                             const std::string& channel) {
  const double t = mission_time_s.value_or(0.0);
  const Eigen::Vector3d c(current.current_constant_ned_mps[0], current.current_constant_ned_mps[1],
                          current.current_constant_ned_mps[2]);
  const std::string due = take_due([&](const agent::MissionEvent& e) {
    return e.kind == agent::MissionEvent::Kind::kCurrent &&
           (e.current_ned_mps - c).cwiseAbs().maxCoeff() <= kCopiedValueTolerance;
  });
  events_.push_back({t, fmt::format("t={:.1f} s ({}): water current [{:g}, {:g}, {:g}] m/s NED, "
                                    "injected on {}",
                                    t, due, c.x(), c.y(), c.z(), channel)});
  return events_.back();
}

std::vector<MissionRunEvent> MissionEventLog::add_fault(const auvrl_lcm::thruster_fault_t& fault,
                                                        std::optional<double> mission_time_s,
                                                        const std::string& channel) {
  std::vector<MissionRunEvent> added;
  if (fault.thruster_efficiency.size() != efficiency_.size()) return added;
  const double t = mission_time_s.value_or(0.0);
  for (std::size_t i = 0; i < efficiency_.size(); ++i) {
    const double efficiency = fault.thruster_efficiency[i];
    if (std::abs(efficiency - efficiency_[i]) <= kCopiedValueTolerance) continue;
    efficiency_[i] = efficiency;
    const std::string due = take_due([&](const agent::MissionEvent& e) {
      return e.kind == agent::MissionEvent::Kind::kThrusterEfficiency &&
             e.thruster == static_cast<int>(i) &&
             std::abs(e.efficiency - efficiency) <= kCopiedValueTolerance;
    });
    added.push_back({t, fmt::format("t={:.1f} s ({}): thruster {} ({}) at {:g} % efficiency, "
                                    "injected on {}",
                                    t, due, i, thruster_names_[i], 100.0 * efficiency, channel)});
  }
  events_.insert(events_.end(), added.begin(), added.end());
  return added;
}

MissionRecorder::MissionRecorder(int num_thrusters)
    : num_thrusters_(num_thrusters), command_n_(static_cast<std::size_t>(num_thrusters), 0.0) {}

void MissionRecorder::add_state(const auvrl_lcm::vehicle_state_t& state, double wall_s) {
  if (state.num_thrusters != num_thrusters_) return;
  if (!states_.empty() && state.sim_time_s < states_.back().sim_time_s && !start_estimate_s_) {
    states_.clear();  // the vehicle was reset again before the mission started: a new clock
  }
  if (!states_.empty() && state.sim_time_s <= states_.back().sim_time_s) return;
  agent::TrajectoryRow row;
  row.time_s = state.sim_time_s;
  row.observation = observation_of(state);
  row.thrust_command_n = command_n_;
  row.thrust_realised_n = state.thrust_realised_n;
  states_.push_back({state.sim_time_s, wall_s, std::move(row)});
}

void MissionRecorder::add_command(const auvrl_lcm::thruster_cmd_t& command) {
  if (command.num_thrusters != num_thrusters_) return;
  command_n_ = command.thrust_n;
}

void MissionRecorder::add_status(const auvrl_lcm::mission_status_t& status) {
  status_ = status;
  using State = auvrl_lcm::mission_status_t;
  if (states_.empty() || status.supervisor_state == State::STATE_WAITING) return;
  const double estimate = states_.back().sim_time_s - status.elapsed_s;
  if (!start_estimate_s_ || estimate < *start_estimate_s_) start_estimate_s_ = estimate;
}

std::size_t MissionRecorder::first_mission_sample() const {
  if (!start_estimate_s_ || states_.empty()) return states_.size();
  // The recorded state nearest the estimate (the times are increasing).
  const auto after = std::lower_bound(states_.begin(), states_.end(), *start_estimate_s_,
                                      [](const Sample& s, double t) { return s.sim_time_s < t; });
  std::size_t i = static_cast<std::size_t>(after - states_.begin());
  if (i == states_.size() || (i > 0 && *start_estimate_s_ - states_[i - 1].sim_time_s <
                                           states_[i].sim_time_s - *start_estimate_s_)) {
    --i;
  }
  return i;
}

std::optional<double> MissionRecorder::start_time_s() const {
  const std::size_t first = first_mission_sample();
  if (first >= states_.size()) return std::nullopt;
  return states_[first].sim_time_s;
}

std::optional<double> MissionRecorder::mission_time_s() const {
  const std::optional<double> start = start_time_s();
  if (!start) return std::nullopt;
  return states_.back().sim_time_s - *start;
}

double MissionRecorder::last_state_wall_s() const {
  return states_.empty() ? -1.0 : states_.back().wall_s;
}

std::vector<agent::TrajectoryRow> MissionRecorder::trajectory() const {
  std::vector<agent::TrajectoryRow> rows;
  const std::size_t first = first_mission_sample();
  if (first >= states_.size()) return rows;
  const double start = states_[first].sim_time_s;
  for (std::size_t i = first; i < states_.size(); ++i) {
    rows.push_back(states_[i].row);
    rows.back().time_s = states_[i].sim_time_s - start;
  }
  return rows;
}

double MissionRecorder::mission_wall_s() const {
  const std::size_t first = first_mission_sample();
  if (first >= states_.size()) return 0.0;
  return states_.back().wall_s - states_[first].wall_s;
}

MissionAnalysis analyse_waypoints(const std::vector<agent::MissionWaypoint>& waypoints,
                                  std::vector<agent::TrajectoryRow>& rows, double max_thrust_n) {
  agent::MissionTracker tracker(waypoints);
  MissionAnalysis out;
  out.waypoints.resize(waypoints.size());
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    out.waypoints[i].index = static_cast<int>(i);
    out.waypoints[i].waypoint = waypoints[i];
  }
  for (agent::TrajectoryRow& row : rows) {
    // The way-point current before this row (the last one once the mission is done).
    const int current = std::min(tracker.index(), tracker.count() - 1);
    row.distance_m = (tracker.goal_ned_m() - row.observation.position_ned_m).norm();
    out.waypoint_index.push_back(current);
    if (!tracker.done() && !row.thrust_command_n.empty()) {
      double sum = 0.0;
      for (double f : row.thrust_command_n) sum += (f / max_thrust_n) * (f / max_thrust_n);
      out.waypoints[static_cast<std::size_t>(current)].thrust_energy +=
          sum / static_cast<double>(row.thrust_command_n.size());
    }
    tracker.update(row.time_s, row.observation.position_ned_m);
  }
  for (std::size_t i = 0; i < out.waypoints.size(); ++i) {
    out.waypoints[i].result = tracker.results()[i];
  }
  return out;
}

std::string format_waypoint_table(const std::vector<eval::MissionWaypointRow>& rows) {
  const auto value = [](double v, int decimals) {
    return v < 0 ? std::string("-") : fmt::format("{:.{}f}", v, decimals);
  };
  std::string out =
      "| way-point | x, y, z (m) | reached | time to reach (s) | from previous (s) | hold error "
      "(m) | energy |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const eval::MissionWaypointRow& r : rows) {
    const Eigen::Vector3d& p = r.waypoint.position_ned_m;
    out += fmt::format("| {} | {:g}, {:g}, {:g} | {} | {} | {} | {} | {:.1f} |\n", r.index + 1,
                       p.x(), p.y(), p.z(), r.result.reached ? "yes" : "no",
                       value(r.result.time_to_reach_s, 1), value(r.result.time_from_previous_s, 1),
                       value(r.result.hold_error_m, 3), r.thrust_energy);
  }
  return out;
}

}  // namespace auvrl::launcher
