// The goal-radius schedule of the paper's goal-driven architecture (section IV-A): the sphere
// of radius beta around the way-point that counts as reached shrinks as training progresses,
// so that early, poor policies still see successes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace auvrl::config {
template <class T>
class Table;
}  // namespace auvrl::config

namespace auvrl::task {

/// How beta moves between two knots.
enum class ScheduleInterpolation {
  /// Geometric (linear in log beta): the default. Radii that span orders of magnitude
  /// (0.5 m to 1e-4 m) shrink by the same factor per episode instead of collapsing at once.
  kLogLinear,
  kLinear,  ///< linear in beta
  kStep,    ///< beta jumps to the next knot's value when its episode count is reached
};

/// Parses "log_linear", "linear" or "step"; throws std::invalid_argument otherwise.
ScheduleInterpolation parse_interpolation(const std::string& name);
const char* to_string(ScheduleInterpolation interpolation);

/// One knot: from this many finished episodes on, beta is (or reaches) beta_m.
struct ScheduleKnot {
  std::int64_t episode = 0;
  double beta_m = 0.0;
};

/// beta as a function of the number of finished episodes: piecewise between knots, constant
/// before the first and after the last. The paper: 1.5 m at first, 0.5 m after 3000 episodes,
/// its minimum 1e-4 m after 5000.
class GoalSchedule {
 public:
  /// The paper's schedule with log-linear interpolation.
  GoalSchedule();
  /// Throws std::invalid_argument unless knots are non-empty, episodes strictly increasing
  /// and >= 0, and every beta finite and > 0.
  GoalSchedule(std::vector<ScheduleKnot> knots, ScheduleInterpolation interpolation);

  /// Goal radius after `episodes` finished episodes, m.
  double beta_m(std::int64_t episodes) const;

  const std::vector<ScheduleKnot>& knots() const { return knots_; }
  ScheduleInterpolation interpolation() const { return interpolation_; }

 private:
  std::vector<ScheduleKnot> knots_;
  ScheduleInterpolation interpolation_;
};

/// The `schedule:` section as written (the paper's schedule by default); to_goal_schedule()
/// checks it and builds the schedule.
struct GoalScheduleConfig {
  ScheduleInterpolation interpolation = ScheduleInterpolation::kLogLinear;
  std::vector<std::vector<double>> knots{
      {0, 1.5}, {3000, 0.5}, {5000, 1e-4}};  ///< [episode, beta_m]
};

/// The keys of a `schedule:` section (common/task/task_yaml.cpp).
const config::Table<GoalScheduleConfig>& goal_schedule_table();

}  // namespace auvrl::task
