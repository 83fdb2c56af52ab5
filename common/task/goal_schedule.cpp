#include "common/task/goal_schedule.hpp"

#include <cmath>
#include <stdexcept>

namespace auvrl::task {

ScheduleInterpolation parse_interpolation(const std::string& name) {
  if (name == "log_linear") return ScheduleInterpolation::kLogLinear;
  if (name == "linear") return ScheduleInterpolation::kLinear;
  if (name == "step") return ScheduleInterpolation::kStep;
  throw std::invalid_argument("goal schedule interpolation '" + name +
                              "': expected log_linear, linear or step");
}

const char* to_string(ScheduleInterpolation interpolation) {
  switch (interpolation) {
    case ScheduleInterpolation::kLogLinear:
      return "log_linear";
    case ScheduleInterpolation::kLinear:
      return "linear";
    case ScheduleInterpolation::kStep:
      return "step";
  }
  return "?";
}

GoalSchedule::GoalSchedule()
    : GoalSchedule({{0, 1.5}, {3000, 0.5}, {5000, 1e-4}}, ScheduleInterpolation::kLogLinear) {}

GoalSchedule::GoalSchedule(std::vector<ScheduleKnot> knots, ScheduleInterpolation interpolation)
    : knots_(std::move(knots)), interpolation_(interpolation) {
  if (knots_.empty()) throw std::invalid_argument("goal schedule: no knots");
  for (std::size_t i = 0; i < knots_.size(); ++i) {
    const ScheduleKnot& k = knots_[i];
    if (k.episode < 0) throw std::invalid_argument("goal schedule: negative episode count");
    if (!std::isfinite(k.beta_m) || k.beta_m <= 0) {
      throw std::invalid_argument("goal schedule: beta_m must be finite and > 0, got " +
                                  std::to_string(k.beta_m));
    }
    if (i > 0 && k.episode <= knots_[i - 1].episode) {
      throw std::invalid_argument("goal schedule: knot episodes must increase strictly");
    }
  }
}

double GoalSchedule::beta_m(std::int64_t episodes) const {
  if (episodes <= knots_.front().episode) return knots_.front().beta_m;
  for (std::size_t i = 1; i < knots_.size(); ++i) {
    const ScheduleKnot& a = knots_[i - 1];
    const ScheduleKnot& b = knots_[i];
    if (episodes >= b.episode) continue;
    const double s =
        static_cast<double>(episodes - a.episode) / static_cast<double>(b.episode - a.episode);
    switch (interpolation_) {
      case ScheduleInterpolation::kStep:
        return a.beta_m;
      case ScheduleInterpolation::kLinear:
        return a.beta_m + s * (b.beta_m - a.beta_m);
      case ScheduleInterpolation::kLogLinear:
        return a.beta_m * std::pow(b.beta_m / a.beta_m, s);
    }
  }
  return knots_.back().beta_m;
}

}  // namespace auvrl::task
