// The goal-radius schedule: the paper's knots, the interpolations between them, validation.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "common/config/yaml_config.hpp"
#include "common/task/goal_schedule.hpp"
#include "common/task/task_yaml.hpp"

namespace auvrl::task {
namespace {

TEST(GoalSchedule, PaperKnotsExactly) {
  const GoalSchedule s;
  EXPECT_EQ(s.interpolation(), ScheduleInterpolation::kLogLinear);
  EXPECT_DOUBLE_EQ(s.beta_m(0), 1.5);
  EXPECT_DOUBLE_EQ(s.beta_m(3000), 0.5);
  EXPECT_DOUBLE_EQ(s.beta_m(5000), 1e-4);
}

TEST(GoalSchedule, ConstantBeforeTheFirstAndAfterTheLastKnot) {
  const GoalSchedule s;
  EXPECT_DOUBLE_EQ(s.beta_m(-10), 1.5);
  EXPECT_DOUBLE_EQ(s.beta_m(5001), 1e-4);
  EXPECT_DOUBLE_EQ(s.beta_m(1000000), 1e-4);
}

TEST(GoalSchedule, LogLinearBetweenKnots) {
  const GoalSchedule s;
  // Geometric midpoints.
  EXPECT_NEAR(s.beta_m(1500), std::sqrt(1.5 * 0.5), 1e-12);
  EXPECT_NEAR(s.beta_m(4000), std::sqrt(0.5 * 1e-4), 1e-12);
  // log(beta) is linear in the episode count within a segment.
  for (int e : {1, 750, 2250, 2999}) {
    const double f = e / 3000.0;
    EXPECT_NEAR(std::log(s.beta_m(e)), (1 - f) * std::log(1.5) + f * std::log(0.5), 1e-12) << e;
  }
  for (int e : {3001, 3500, 4999}) {
    const double f = (e - 3000) / 2000.0;
    EXPECT_NEAR(std::log(s.beta_m(e)), (1 - f) * std::log(0.5) + f * std::log(1e-4), 1e-12) << e;
  }
  // Strictly decreasing over the schedule.
  for (int e = 1; e <= 5000; ++e) EXPECT_LT(s.beta_m(e), s.beta_m(e - 1)) << e;
}

TEST(GoalSchedule, LinearMode) {
  const GoalSchedule s({{0, 1.5}, {3000, 0.5}, {5000, 1e-4}}, ScheduleInterpolation::kLinear);
  EXPECT_DOUBLE_EQ(s.beta_m(0), 1.5);
  EXPECT_NEAR(s.beta_m(1500), 1.0, 1e-12);
  EXPECT_NEAR(s.beta_m(750), 1.25, 1e-12);
  EXPECT_DOUBLE_EQ(s.beta_m(3000), 0.5);
  EXPECT_NEAR(s.beta_m(4000), 0.5 + 0.5 * (1e-4 - 0.5), 1e-12);
  EXPECT_DOUBLE_EQ(s.beta_m(6000), 1e-4);
}

TEST(GoalSchedule, StepMode) {
  const GoalSchedule s({{0, 1.5}, {3000, 0.5}, {5000, 1e-4}}, ScheduleInterpolation::kStep);
  EXPECT_DOUBLE_EQ(s.beta_m(2999), 1.5);
  EXPECT_DOUBLE_EQ(s.beta_m(3000), 0.5);
  EXPECT_DOUBLE_EQ(s.beta_m(4999), 0.5);
  EXPECT_DOUBLE_EQ(s.beta_m(5000), 1e-4);
}

TEST(GoalSchedule, SingleKnotIsConstant) {
  const GoalSchedule s({{100, 0.5}}, ScheduleInterpolation::kLogLinear);
  EXPECT_DOUBLE_EQ(s.beta_m(0), 0.5);
  EXPECT_DOUBLE_EQ(s.beta_m(100), 0.5);
  EXPECT_DOUBLE_EQ(s.beta_m(10000), 0.5);
}

TEST(GoalSchedule, InvalidKnotsRejected) {
  const auto make = [](std::vector<ScheduleKnot> knots) {
    return GoalSchedule(std::move(knots), ScheduleInterpolation::kLogLinear);
  };
  EXPECT_THROW(make({}), std::invalid_argument);
  EXPECT_THROW(make({{0, 1.5}, {0, 0.5}}), std::invalid_argument);     // not increasing
  EXPECT_THROW(make({{3000, 1.5}, {0, 0.5}}), std::invalid_argument);  // decreasing
  EXPECT_THROW(make({{-1, 1.5}}), std::invalid_argument);              // negative episode
  EXPECT_THROW(make({{0, 0.0}}), std::invalid_argument);               // beta 0
  EXPECT_THROW(make({{0, -0.5}}), std::invalid_argument);              // negative beta
  EXPECT_THROW(make({{0, std::numeric_limits<double>::quiet_NaN()}}), std::invalid_argument);
  EXPECT_THROW(make({{0, std::numeric_limits<double>::infinity()}}), std::invalid_argument);
}

TEST(GoalSchedule, InterpolationNames) {
  for (ScheduleInterpolation i : {ScheduleInterpolation::kLogLinear, ScheduleInterpolation::kLinear,
                                  ScheduleInterpolation::kStep}) {
    EXPECT_EQ(parse_interpolation(to_string(i)), i);
  }
  EXPECT_THROW(parse_interpolation("exponential"), std::invalid_argument);
}

// Found by fuzz_run_config: an episode beyond int64's range was converted (undefined).
TEST(GoalScheduleFile, KnotEpisodesMustBeWholeNumbersInRange) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("auvrl_schedule_" + std::to_string(getpid()) + ".yaml"))
                               .string();
  const auto read = [&](const std::string& knots) {
    std::ofstream(path) << "schedule:\n  knots: " << knots << "\n";
    config::Section root = config::load_file(path);
    return read_goal_schedule(root.child("schedule"), GoalSchedule());
  };
  EXPECT_DOUBLE_EQ(read("[[0, 1.5], [3000, 0.5]]").beta_m(3000), 0.5);
  for (const char* bad :
       {"[[0, 1.5], [7.8e28, 0.5]]", "[[-1, 1.5]]", "[[0, 1.5], [2.5, 0.5]]", "[[.nan, 1.5]]"}) {
    try {
      read(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("knots"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace auvrl::task
