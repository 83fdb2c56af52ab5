// The observation vectors: sizes, contents and scaling of both layouts, the goal error in the
// body frame, hindsight relabelling, position recovery and way-point sampling.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/task/task.hpp"

namespace auvrl::task {
namespace {

constexpr double kPi = 3.14159265358979323846;

TaskConfig config(StateLayout layout) {
  TaskConfig c;
  c.layout = layout;
  return c;
}

StateVector build(const TaskConfig& c, const Observation& obs, const Eigen::Vector3d& goal,
                  const ActionVector& previous,
                  const std::vector<double>& thrust_n = std::vector<double>(6, 0.0)) {
  StateVector s;
  build_state(c, obs, goal, previous, s, thrust_n);
  return s;
}

/// Extended-layout body-frame goal error in metres.
Eigen::Vector3d body_error_m(const TaskConfig& c, const StateVector& s) {
  return s.head<3>().cast<double>() * c.scales.position_m;
}

TEST(StateLayout, Dimensions) {
  EXPECT_EQ(config(StateLayout::kPaper).state_dim(), 18);
  EXPECT_EQ(config(StateLayout::kExtended).state_dim(), 23);
  EXPECT_EQ(config(StateLayout::kExtendedThrust).state_dim(), 29);
  TaskConfig c = config(StateLayout::kPaper);
  c.num_thrusters = 8;
  EXPECT_EQ(c.state_dim(), 20);
  c.layout = StateLayout::kExtended;
  EXPECT_EQ(c.state_dim(), 25);
  c.layout = StateLayout::kExtendedThrust;
  EXPECT_EQ(c.state_dim(), 33);
  const Observation obs;
  for (StateLayout layout :
       {StateLayout::kPaper, StateLayout::kExtended, StateLayout::kExtendedThrust}) {
    const TaskConfig t = config(layout);
    EXPECT_EQ(build(t, obs, Eigen::Vector3d(1, 2, 3), ActionVector::Zero(6)).size(), t.state_dim());
  }
}

TEST(StateLayout, WrongPreviousActionSizeIsRejected) {
  StateVector s;
  EXPECT_THROW(build_state(config(StateLayout::kPaper), Observation{}, Eigen::Vector3d::Zero(),
                           ActionVector::Zero(5), s),
               std::invalid_argument);
}

TEST(StateLayout, PaperContentsAndScaling) {
  TaskConfig c = config(StateLayout::kPaper);
  c.scales.position_m = 20.0;
  c.scales.linear_velocity_mps = 2.0;
  c.scales.angular_rate_rad_s = 0.5;
  Observation obs;
  obs.position_ned_m = Eigen::Vector3d(2.0, -4.0, 6.0);
  obs.euler_rpy_rad = Eigen::Vector3d(0.1, 0.2, 1.0);  // the paper's layout has no attitude
  obs.velocity_body_mps = Eigen::Vector3d(1.0, -0.5, 0.2);
  obs.angular_rate_body_rad_s = Eigen::Vector3d(0.1, -0.2, 0.3);
  ActionVector prev(6);
  prev << 0.1f, -0.2f, 0.3f, -0.4f, 0.5f, -0.6f;
  const StateVector s = build(c, obs, Eigen::Vector3d(7.0, 6.0, 10.0), prev);
  const float expected[18] = {0.1f, -0.2f, 0.3f, 0.25f, 0.5f,  0.2f, 0.5f,  -0.25f, 0.1f,
                              0.2f, -0.4f, 0.6f, 0.1f,  -0.2f, 0.3f, -0.4f, 0.5f,   -0.6f};
  for (int i = 0; i < 18; ++i) EXPECT_NEAR(s[i], expected[i], 1e-6) << i;
}

TEST(StateLayout, ExtendedContentsAndScaling) {
  TaskConfig c = config(StateLayout::kExtended);
  c.scales.position_m = 5.0;
  c.scales.linear_velocity_mps = 2.0;
  c.scales.angular_rate_rad_s = 0.5;
  c.scales.depth_m = 20.0;
  Observation obs;
  obs.position_ned_m = Eigen::Vector3d(1.0, 1.0, 8.0);
  obs.euler_rpy_rad = Eigen::Vector3d(0.1, -0.2, 2.5);
  obs.velocity_body_mps = Eigen::Vector3d(1.0, -0.5, 0.2);
  obs.angular_rate_body_rad_s = Eigen::Vector3d(0.1, -0.2, 0.3);
  ActionVector prev(6);
  prev << 0.1f, -0.2f, 0.3f, -0.4f, 0.5f, -0.6f;
  const Eigen::Vector3d goal(4.0, -3.0, 10.0);
  const StateVector s = build(c, obs, goal, prev);
  const Eigen::Vector3d e_body =
      body_to_ned(obs.euler_rpy_rad).transpose() * (goal - obs.position_ned_m);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(s[i], e_body[i] / 5.0, 1e-6);
  EXPECT_NEAR(s[3], (goal - obs.position_ned_m).norm() / 5.0, 1e-6);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(s[4 + 2 * i], std::sin(obs.euler_rpy_rad[i]), 1e-6);
    EXPECT_NEAR(s[5 + 2 * i], std::cos(obs.euler_rpy_rad[i]), 1e-6);
  }
  EXPECT_NEAR(s[10], 0.5, 1e-6);
  EXPECT_NEAR(s[11], -0.25, 1e-6);
  EXPECT_NEAR(s[12], 0.1, 1e-6);
  EXPECT_NEAR(s[13], 0.2, 1e-6);
  EXPECT_NEAR(s[14], -0.4, 1e-6);
  EXPECT_NEAR(s[15], 0.6, 1e-6);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(s[16 + i], prev[i]);
  EXPECT_NEAR(s[22], 8.0 / 20.0, 1e-6);
}

TEST(StateLayout, GoalNorthOfAVehicleYawedToEastIsOnItsPortSide) {
  const TaskConfig c = config(StateLayout::kExtended);
  Observation obs;
  obs.position_ned_m = Eigen::Vector3d(3.0, 4.0, 5.0);
  obs.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, kPi / 2);  // facing east
  const StateVector s =
      build(c, obs, obs.position_ned_m + Eigen::Vector3d(6.0, 0.0, 0.0), ActionVector::Zero(6));
  const Eigen::Vector3d e = body_error_m(c, s);
  EXPECT_NEAR(e.x(), 0.0, 1e-5);
  EXPECT_NEAR(e.y(), -6.0, 1e-5);  // port = body y negative
  EXPECT_NEAR(e.z(), 0.0, 1e-5);
  // Yawed to the west it is on the starboard side; yawed north it is straight ahead.
  obs.euler_rpy_rad.z() = -kPi / 2;
  EXPECT_NEAR(body_error_m(c, build(c, obs, obs.position_ned_m + Eigen::Vector3d(6, 0, 0),
                                    ActionVector::Zero(6)))
                  .y(),
              6.0, 1e-5);
  obs.euler_rpy_rad.z() = 0.0;
  EXPECT_NEAR(body_error_m(c, build(c, obs, obs.position_ned_m + Eigen::Vector3d(6, 0, 0),
                                    ActionVector::Zero(6)))
                  .x(),
              6.0, 1e-5);
  // Facing away (test 2): the goal is straight behind.
  obs.euler_rpy_rad.z() = kPi;
  EXPECT_NEAR(body_error_m(c, build(c, obs, obs.position_ned_m + Eigen::Vector3d(6, 0, 0),
                                    ActionVector::Zero(6)))
                  .x(),
              -6.0, 1e-5);
}

TEST(StateLayout, NoseUpPitchPutsAGoalAheadBelowTheBodyXAxis) {
  const TaskConfig c = config(StateLayout::kExtended);
  Observation obs;
  obs.euler_rpy_rad = Eigen::Vector3d(0.0, kPi / 6, 0.0);  // 30 deg nose up, facing north
  const StateVector s = build(c, obs, Eigen::Vector3d(10.0, 0.0, 0.0), ActionVector::Zero(6));
  const Eigen::Vector3d e = body_error_m(c, s);
  EXPECT_NEAR(e.x(), 10.0 * std::cos(kPi / 6), 1e-5);
  EXPECT_NEAR(e.y(), 0.0, 1e-5);
  EXPECT_NEAR(e.z(), 10.0 * std::sin(kPi / 6), 1e-5);  // body z down: below the nose
}

TEST(StateLayout, StarboardDownRollLeansDownTowardStarboard) {
  const TaskConfig c = config(StateLayout::kExtended);
  Observation obs;
  obs.euler_rpy_rad = Eigen::Vector3d(kPi / 6, 0.0, 0.0);  // 30 deg roll, starboard down
  const StateVector s = build(c, obs, Eigen::Vector3d(0.0, 0.0, 10.0), ActionVector::Zero(6));
  const Eigen::Vector3d e = body_error_m(c, s);
  EXPECT_NEAR(e.x(), 0.0, 1e-5);
  EXPECT_NEAR(e.y(), 10.0 * std::sin(kPi / 6), 1e-5);
  EXPECT_NEAR(e.z(), 10.0 * std::cos(kPi / 6), 1e-5);
}

TEST(StateLayout, BodyToNedIsARotation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-1.5, 1.5);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix3d r = body_to_ned(Eigen::Vector3d(angle(rng), angle(rng), 2 * angle(rng)));
    EXPECT_NEAR((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
}

/// Random observations: positions in the training region, any yaw, roll and pitch within
/// +-1.2 rad (beyond that the episode has ended), velocities and a previous action.
Observation random_observation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> pos(-10.0, 10.0), tilt(-1.2, 1.2), yaw(-kPi, kPi),
      vel(-1.5, 1.5);
  Observation o;
  o.position_ned_m = Eigen::Vector3d(pos(rng), pos(rng), 8.0 + 0.7 * pos(rng));
  o.euler_rpy_rad = Eigen::Vector3d(tilt(rng), tilt(rng), yaw(rng));
  o.velocity_body_mps = Eigen::Vector3d(vel(rng), vel(rng), vel(rng));
  o.angular_rate_body_rad_s = Eigen::Vector3d(vel(rng), vel(rng), vel(rng));
  return o;
}

TEST(StateLayout, ExtendedThrustIsTheExtendedStateThenTheNormalisedThrust) {
  TaskConfig ext = config(StateLayout::kExtended);
  TaskConfig thr = config(StateLayout::kExtendedThrust);
  ext.max_thrust_n = thr.max_thrust_n = 40.0;
  std::mt19937_64 rng(5);
  const Observation obs = random_observation(rng);
  ActionVector prev(6);
  prev << 0.1f, -0.2f, 0.3f, -0.4f, 0.5f, -0.6f;
  const std::vector<double> thrust = {40.0, -40.0, 20.0, -10.0, 0.0, 4.0};
  const Eigen::Vector3d goal(7.0, 6.0, 10.0);
  const StateVector e = build(ext, obs, goal, prev, thrust);
  const StateVector t = build(thr, obs, goal, prev, thrust);
  ASSERT_EQ(t.size(), e.size() + 6);
  EXPECT_EQ(t.head(e.size()), e);  // the extended state, entry for entry
  const float expected[] = {1.0f, -1.0f, 0.5f, -0.25f, 0.0f, 0.1f};
  for (int i = 0; i < 6; ++i) EXPECT_FLOAT_EQ(t[e.size() + i], expected[i]) << i;
  // The thrust is required, one value per thruster.
  StateVector s;
  EXPECT_THROW(build_state(thr, obs, goal, prev, s), std::invalid_argument);
  EXPECT_THROW(build_state(thr, obs, goal, prev, s, std::vector<double>(5, 0.0)),
               std::invalid_argument);
}

TEST(Relabel, EqualsBuildingTheStateForTheNewGoal) {
  for (StateLayout layout :
       {StateLayout::kPaper, StateLayout::kExtended, StateLayout::kExtendedThrust}) {
    const TaskConfig c = config(layout);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> goal(-10.0, 10.0);
    std::uniform_real_distribution<float> act(-1.0f, 1.0f);
    for (int i = 0; i < 500; ++i) {
      const Observation obs = random_observation(rng);
      const Eigen::Vector3d old_goal(goal(rng), goal(rng), 8.0 + 0.7 * goal(rng));
      const Eigen::Vector3d new_goal(goal(rng), goal(rng), 8.0 + 0.7 * goal(rng));
      ActionVector prev(6);
      for (int k = 0; k < 6; ++k) prev[k] = act(rng);
      std::vector<double> thrust(6);
      for (double& f : thrust) f = 39.24 * act(rng);
      StateVector relabelled = build(c, obs, old_goal, prev, thrust);
      relabel_state(c, old_goal, new_goal, relabelled);
      const StateVector direct = build(c, obs, new_goal, prev, thrust);
      ASSERT_EQ(relabelled.size(), direct.size());
      EXPECT_LT((relabelled - direct).cwiseAbs().maxCoeff(), 2e-6f)
          << to_string(layout) << " sample " << i;
    }
  }
}

TEST(Relabel, ToTheSameGoalChangesNothing) {
  const TaskConfig c = config(StateLayout::kExtended);
  std::mt19937_64 rng(3);
  const Observation obs = random_observation(rng);
  const Eigen::Vector3d goal(1.0, 2.0, 3.0);
  StateVector s = build(c, obs, goal, ActionVector::Zero(6));
  const StateVector before = s;
  relabel_state(c, goal, goal, s);
  EXPECT_LT((s - before).cwiseAbs().maxCoeff(), 1e-6f);
}

// The goal integrator: within its radius the offset moves by gain x step x error (NED); outside
// it, or with the gain at 0, nothing moves; its length never exceeds max_offset_m.
TEST(GoalIntegral, IntegratesTheErrorInsideItsRadiusAndClampsTheOffset) {
  TaskConfig c;
  c.control_step_s = 0.1;
  c.integral.gain_per_s = 0.5;
  c.integral.radius_m = 1.0;
  c.integral.max_offset_m = 0.3;
  const Eigen::Vector3d goal(4.0, -2.0, 6.0);
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  // 0.4 m short of it along north: +0.02 m a step.
  Eigen::Vector3d moved = advance_goal_integral(c, goal, goal - Eigen::Vector3d(0.4, 0, 0), offset);
  EXPECT_NEAR(offset.x(), 0.02, 1e-15);
  EXPECT_EQ(moved, goal + offset);
  // 1.5 m away: outside the radius, the offset stays (and still moves the goal).
  moved = advance_goal_integral(c, goal, goal + Eigen::Vector3d(0, 1.5, 0), offset);
  EXPECT_NEAR(offset.x(), 0.02, 1e-15);
  EXPECT_EQ(offset.y(), 0.0);
  EXPECT_EQ(moved, goal + offset);
  // Held off long enough, it stops at its largest length, in the error's direction.
  for (int t = 0; t < 100; ++t) {
    advance_goal_integral(c, goal, goal - Eigen::Vector3d(0.0, 0.6, 0.8), offset);
  }
  EXPECT_NEAR(offset.norm(), 0.3, 1e-12);
  EXPECT_GT(offset.dot(Eigen::Vector3d(0.0, 0.6, 0.8)), 0.29);
  // Off: the goal itself.
  c.integral.gain_per_s = 0.0;
  Eigen::Vector3d none = Eigen::Vector3d::Zero();
  EXPECT_EQ(advance_goal_integral(c, goal, goal - Eigen::Vector3d(0.4, 0, 0), none), goal);
  EXPECT_EQ(none, Eigen::Vector3d::Zero());
}

TEST(GoalIntegral, UnusableSettingsAreRefusedByName) {
  TaskConfig c;
  c.integral.gain_per_s = -0.1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.integral.gain_per_s = 0.1;
  c.integral.radius_m = 0.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.integral.radius_m = 1.0;
  c.integral.max_offset_m = std::nan("");
  try {
    c.validate();
    ADD_FAILURE() << "a NaN max_offset_m was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("task.integral.max_offset_m"), std::string::npos);
  }
}

TEST(Relabel, WithAShiftEqualsBuildingTheStateWhereTheVehicleWouldBe) {
  for (StateLayout layout :
       {StateLayout::kPaper, StateLayout::kExtended, StateLayout::kExtendedThrust}) {
    const TaskConfig c = config(layout);
    std::mt19937_64 rng(43);
    std::uniform_real_distribution<double> shift(-0.5, 0.5);
    for (int i = 0; i < 500; ++i) {
      Observation obs = random_observation(rng);
      const Eigen::Vector3d goal(7.0, 6.0, 10.0), new_goal(6.5, 6.2, 9.0);
      const Eigen::Vector3d by(shift(rng), shift(rng), shift(rng));
      StateVector shifted = build(c, obs, goal, ActionVector::Constant(6, 0.3f));
      relabel_state(c, goal, new_goal, by, shifted);
      obs.position_ned_m += by;
      const StateVector direct = build(c, obs, new_goal, ActionVector::Constant(6, 0.3f));
      EXPECT_LT((shifted - direct).cwiseAbs().maxCoeff(), 2e-6f)
          << to_string(layout) << " sample " << i;
    }
  }
}

/// A vehicle pitched, rolled and yawed, moving at a constant body velocity: its NED velocity is
/// constant, so its position is a straight line in time.
Observation steady_motion(double t_s) {
  Observation o;
  o.euler_rpy_rad = Eigen::Vector3d(0.1, -0.2, 2.0);
  o.velocity_body_mps = Eigen::Vector3d(1.2, -0.3, 0.2);
  o.position_ned_m =
      Eigen::Vector3d(1.0, -2.0, 5.0) + t_s * body_to_ned(o.euler_rpy_rad) * o.velocity_body_mps;
  return o;
}

TEST(PositionFilter, FollowsNoiseFreeMotionAndStartsAtTheMeasurement) {
  PositionFilterSettings settings;
  PositionFilter filter(settings, 0.1);
  EXPECT_NEAR(filter.gain(), 1.0 - std::exp(-0.1 / 0.5), 1e-15);
  for (int step = 0; step < 300; ++step) {
    const Observation o = steady_motion(0.1 * step);
    EXPECT_LT((filter.update(o) - o.position_ned_m).norm(), 1e-12) << step;
  }
  // After reset() the first estimate is the measurement itself, wherever the vehicle is.
  filter.reset();
  Observation elsewhere = steady_motion(0.0);
  elsewhere.position_ned_m = Eigen::Vector3d(-4.0, 3.0, 9.0);
  EXPECT_EQ(filter.update(elsewhere), elsewhere.position_ned_m);
}

// A vehicle at rest with white position noise: the estimate's spread is the measurement's times
// sqrt(g / (2 - g)) (a first-order filter with gain g per step): 0.32 of it for 0.5 s at 0.1 s.
TEST(PositionFilter, CutsWhitePositionNoiseAsAFirstOrderFilterDoes) {
  PositionFilter filter(PositionFilterSettings{}, 0.1);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1);
  double sum_sq = 0.0;
  const int steps = 40000;
  for (int step = 0; step < steps; ++step) {
    Observation o;
    o.position_ned_m = Eigen::Vector3d(noise(rng), noise(rng), 5.0 + noise(rng));
    const Eigen::Vector3d error = filter.update(o) - Eigen::Vector3d(0.0, 0.0, 5.0);
    if (step >= 100) sum_sq += error.squaredNorm() / 3.0;
  }
  const double spread_m = std::sqrt(sum_sq / (steps - 100));
  const double g = filter.gain();
  EXPECT_NEAR(spread_m, 0.1 * std::sqrt(g / (2.0 - g)), 0.003);
  EXPECT_LT(spread_m, 0.035);
}

TEST(PositionFilter, UnusableSettingsAreRefusedByName) {
  EXPECT_THROW(PositionFilter(PositionFilterSettings{0.0}, 0.1), std::invalid_argument);
  EXPECT_THROW(PositionFilter(PositionFilterSettings{0.5}, 0.0), std::invalid_argument);
  TaskConfig c;
  for (double bad : {-0.1, PositionFilterSettings::kMaxTimeConstantS + 1.0, std::nan("")}) {
    c.position_filter.time_constant_s = bad;
    try {
      c.validate();
      ADD_FAILURE() << "time constant " << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("task.position_filter.time_constant_s"),
                std::string::npos)
          << e.what();
    }
  }
  c.position_filter.time_constant_s = 0.0;
  EXPECT_NO_THROW(c.validate());
}

TEST(PositionFromState, RecoversThePositionInEveryLayout) {
  for (StateLayout layout :
       {StateLayout::kPaper, StateLayout::kExtended, StateLayout::kExtendedThrust}) {
    const TaskConfig c = config(layout);
    std::mt19937_64 rng(11);
    for (int i = 0; i < 200; ++i) {
      const Observation obs = random_observation(rng);
      const Eigen::Vector3d goal(7.0, 6.0, 10.0);
      const StateVector s = build(c, obs, goal, ActionVector::Zero(6));
      EXPECT_LT((position_from_state(c, goal, s) - obs.position_ned_m).norm(), 1e-4)
          << to_string(layout) << " sample " << i;
    }
  }
}

TEST(SampleGoal, InsideTheBoxAndCoveringIt) {
  TaskConfig c;
  c.goal_min_ned_m = Eigen::Vector3d(-10.0, -5.0, 1.0);
  c.goal_max_ned_m = Eigen::Vector3d(10.0, 5.0, 15.0);
  std::mt19937_64 rng(5);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo, sum = Eigen::Vector3d::Zero();
  const int n = 5000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d g = sample_goal(c, rng);
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(g[k], c.goal_min_ned_m[k]);
      ASSERT_LE(g[k], c.goal_max_ned_m[k]);
    }
    lo = lo.cwiseMin(g);
    hi = hi.cwiseMax(g);
    sum += g;
  }
  // Uniform: it reaches near every face and its mean is the box centre.
  const Eigen::Vector3d size = c.goal_max_ned_m - c.goal_min_ned_m;
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(lo[k] - c.goal_min_ned_m[k], 0.01 * size[k]);
    EXPECT_LT(c.goal_max_ned_m[k] - hi[k], 0.01 * size[k]);
    EXPECT_NEAR(sum[k] / n, 0.5 * (c.goal_min_ned_m[k] + c.goal_max_ned_m[k]), 0.03 * size[k]);
  }
}

TEST(SampleGoal, DeterministicPerSeed) {
  const TaskConfig c;
  std::mt19937_64 a(123), b(123), other(124);
  bool any_difference = false;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d ga = sample_goal(c, a);
    EXPECT_EQ(ga, sample_goal(c, b));
    any_difference |= ga != sample_goal(c, other);
  }
  EXPECT_TRUE(any_difference);
  // A degenerate box gives its one point.
  TaskConfig point;
  point.goal_min_ned_m = point.goal_max_ned_m = Eigen::Vector3d(7.0, 6.0, 10.0);
  EXPECT_EQ(sample_goal(point, a), Eigen::Vector3d(7.0, 6.0, 10.0));
}

TEST(SampleStart, AtRestAtTheStartPoseByDefault) {
  TaskConfig c;
  c.start_position_ned_m = Eigen::Vector3d(1.0, 2.0, 3.0);
  c.start_yaw_rad = 0.4;
  c.start_velocity_max_body_mps = Eigen::Vector3d(1.0, 1.0, 1.0);  // unused at fraction 0
  std::mt19937_64 rng(9);
  for (int i = 0; i < 100; ++i) {
    const StartState s = sample_start(c, rng);
    EXPECT_EQ(s.position_ned_m, c.start_position_ned_m);
    EXPECT_EQ(s.euler_rpy_rad, Eigen::Vector3d(0.0, 0.0, 0.4));
    EXPECT_EQ(s.velocity_body_mps, Eigen::Vector3d::Zero());
    EXPECT_EQ(s.angular_rate_body_rad_s, Eigen::Vector3d::Zero());
  }
}

TEST(SampleStart, RandomStartsHaveTheirShareAndStayInsideTheirSpreads) {
  TaskConfig c;
  c.random_start_fraction = 0.3;
  c.start_yaw_rad = 3.0;  // near +pi: the drawn yaw must wrap
  c.start_attitude_spread_rad = Eigen::Vector3d(0.1, 0.4, kPi);
  c.start_velocity_max_body_mps = Eigen::Vector3d(1.5, 0.5, 0.25);
  c.start_rate_max_body_rad_s = Eigen::Vector3d(0.2, 0.3, 0.6);
  ASSERT_NO_THROW(c.validate());
  std::mt19937_64 rng(17);
  const int n = 20000;
  int random = 0;
  Eigen::Vector3d max_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_sum = Eigen::Vector3d::Zero();
  double min_yaw = 10.0, max_yaw = -10.0;
  for (int i = 0; i < n; ++i) {
    const StartState s = sample_start(c, rng);
    EXPECT_EQ(s.position_ned_m, c.start_position_ned_m);
    if (s.velocity_body_mps.isZero() && s.euler_rpy_rad == Eigen::Vector3d(0.0, 0.0, 3.0)) {
      EXPECT_TRUE(s.angular_rate_body_rad_s.isZero());
      continue;
    }
    ++random;
    for (int k = 0; k < 2; ++k) {
      ASSERT_LE(std::abs(s.euler_rpy_rad[k]), c.start_attitude_spread_rad[k]);
    }
    ASSERT_GT(s.euler_rpy_rad[2], -kPi - 1e-12);
    ASSERT_LE(s.euler_rpy_rad[2], kPi + 1e-12);
    min_yaw = std::min(min_yaw, s.euler_rpy_rad[2]);
    max_yaw = std::max(max_yaw, s.euler_rpy_rad[2]);
    for (int k = 0; k < 3; ++k) {
      ASSERT_LE(std::abs(s.velocity_body_mps[k]), c.start_velocity_max_body_mps[k]);
      ASSERT_LE(std::abs(s.angular_rate_body_rad_s[k]), c.start_rate_max_body_rad_s[k]);
    }
    max_velocity = max_velocity.cwiseMax(s.velocity_body_mps.cwiseAbs());
    velocity_sum += s.velocity_body_mps;
  }
  EXPECT_NEAR(static_cast<double>(random) / n, 0.3, 0.02);
  // A full yaw spread covers every heading; velocities reach their limits, centred on rest.
  EXPECT_LT(min_yaw, -kPi + 0.01);
  EXPECT_GT(max_yaw, kPi - 0.01);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(max_velocity[k], 0.99 * c.start_velocity_max_body_mps[k]);
    EXPECT_NEAR(velocity_sum[k] / random, 0.0, 0.03 * c.start_velocity_max_body_mps[k]);
  }
}

TEST(SampleStart, TakesTheSameDrawsEitherWaySoGoalsDoNotShift) {
  // One stream for goals and starts would still give the same goals whatever the fraction.
  TaskConfig rest, spread;
  spread.random_start_fraction = 1.0;
  spread.start_velocity_max_body_mps = Eigen::Vector3d(1.0, 1.0, 1.0);
  std::mt19937_64 a(3), b(3);
  for (int i = 0; i < 50; ++i) {
    sample_start(rest, a);
    const StartState s = sample_start(spread, b);
    EXPECT_FALSE(s.velocity_body_mps.isZero());
    EXPECT_EQ(sample_goal(rest, a), sample_goal(rest, b));
  }
}

}  // namespace
}  // namespace auvrl::task
