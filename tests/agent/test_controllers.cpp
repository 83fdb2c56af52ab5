// The controllers: the policy's size checks, and the PID baseline on the Nessie VII model
// (allocation, limits, reaching test 1 well inside 70 s and holding station there).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "agent/controller.hpp"
#include "agent/pid_controller.hpp"
#include "common/nn/mlp.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {
namespace {

using Tau = Eigen::Matrix<double, 6, 1>;

/// The five controllable DOF of a body force/moment: roll (row 3) dropped. The lateral
/// thrusters sit 5 cm off the roll axis, so sway and yaw come with a small roll moment that
/// the allocation neither asks for nor can cancel.
Eigen::Matrix<double, 5, 1> controllable(const Tau& tau) {
  Eigen::Matrix<double, 5, 1> out;
  out << tau[0], tau[1], tau[2], tau[4], tau[5];
  return out;
}

nn::Mlp actor(int inputs, int outputs) {
  nn::Mlp net(nn::MlpSpec::actor(inputs, {16, 16}, outputs), 1);
  nn::Rng rng(1);
  net.init_lillicrap(rng);
  return net;
}

const sim::VehicleModel& nessie() {
  static const sim::VehicleModel model =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
  return model;
}

TEST(PolicyController, AcceptsANetworkThatFitsAndActsWithIt) {
  PolicyController policy(actor(18, 6), 18, 6);
  task::StateVector state = task::StateVector::LinSpaced(18, -1.0f, 1.0f);
  task::ActionVector action;
  policy.act(task::Observation{}, Eigen::Vector3d::Zero(), state, action);
  nn::Mlp reference = actor(18, 6);
  const Eigen::VectorXf expected = reference.forward(state);
  ASSERT_EQ(action.size(), 6);
  EXPECT_EQ(action, expected);
  EXPECT_EQ(policy.name(), "policy");
}

TEST(PolicyController, RejectsNetworksThatDoNotFit) {
  EXPECT_THROW(PolicyController(actor(23, 6), 18, 6), std::invalid_argument);  // wrong layout
  EXPECT_THROW(PolicyController(actor(18, 4), 18, 6), std::invalid_argument);  // wrong outputs
  // A critic (state and action in) is not a policy.
  nn::Mlp critic(nn::MlpSpec::critic(18, 6, {16, 16}, 1), 1);
  EXPECT_THROW(PolicyController(std::move(critic), 18, 6), std::invalid_argument);
  try {
    PolicyController(actor(23, 6), 18, 6);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("in=18"), std::string::npos) << e.what();
  }
}

TEST(PolicyController, SetNetworkChecksSizesAndKeepsTheOldOneOnError) {
  PolicyController policy(actor(23, 6), 23, 6);
  const Eigen::VectorXf before = policy.network().params();
  EXPECT_THROW(policy.set_network(actor(18, 6)), std::invalid_argument);
  EXPECT_EQ(Eigen::VectorXf(policy.network().params()), before);
  EXPECT_NO_THROW(policy.set_network(actor(23, 6)));
}

TEST(PidController, PseudoInverseReproducesTheFiveControllableDof) {
  const PidController pid(nessie());
  const Eigen::MatrixXd b = nessie().allocation;
  const Eigen::MatrixXd& pinv = pid.allocation_pseudo_inverse();
  ASSERT_EQ(pinv.rows(), 6);
  ASSERT_EQ(pinv.cols(), 6);
  for (int axis : {0, 1, 2, 4, 5}) {
    Tau unit = Tau::Zero();
    unit[axis] = 1.0;
    EXPECT_LT(controllable(b * pinv * unit - unit).norm(), 1e-9) << "axis " << axis;
  }
  // Roll is not asked of the thrusters (no authority): its column is zero.
  EXPECT_LT(pinv.col(3).norm(), 1e-12);
}

TEST(PidController, AllocationStaysInRangeAndServesYawBeforeSurge) {
  const PidController pid(nessie());
  const double max_n = nessie().thruster_dynamics.max_thrust_n;
  const Eigen::MatrixXd b = nessie().allocation;
  // Within range: exact.
  Tau small = Tau::Zero();
  small << 10.0, 0.0, 5.0, 0.0, 2.0, 3.0;
  EXPECT_LT(controllable(b * pid.allocate(small) - small).cwiseAbs().maxCoeff(), 1e-9);
  // Full surge and a strong yaw moment together: yaw is delivered in full, surge scaled.
  Tau both = Tau::Zero();
  both[0] = 200.0;
  both[5] = 20.0;
  const Eigen::VectorXd f = pid.allocate(both);
  EXPECT_LE(f.cwiseAbs().maxCoeff(), max_n + 1e-9);
  const Tau achieved = b * f;
  EXPECT_NEAR(achieved[5], 20.0, 1e-9);
  EXPECT_GT(achieved[0], 30.0);
  EXPECT_LT(achieved[0], 200.0);
  EXPECT_NEAR(achieved[1], 0.0, 1e-9);
  // Impossible heave alone: scaled as a whole, never past the limit.
  Tau heave = Tau::Zero();
  heave[2] = 500.0;
  const Eigen::VectorXd fh = pid.allocate(heave);
  EXPECT_NEAR(fh.cwiseAbs().maxCoeff(), max_n, 1e-9);
  const Tau achieved_heave = b * fh;
  EXPECT_NEAR(achieved_heave[4], 0.0, 1e-9);  // no pitch moment from scaling
}

TEST(PidController, CommandsAreNormalisedAndClipped) {
  PidController pid(nessie());
  task::Observation obs;
  obs.position_ned_m = Eigen::Vector3d(0, 0, 5);
  obs.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, 3.0);
  task::ActionVector action;
  pid.act(obs, Eigen::Vector3d(30.0, -20.0, 15.0), task::StateVector(), action);
  ASSERT_EQ(action.size(), 6);
  EXPECT_LE(action.cwiseAbs().maxCoeff(), 1.0f);
  EXPECT_GT(action.cwiseAbs().maxCoeff(), 0.5f);  // far away: it pushes hard
  EXPECT_EQ(pid.name(), "pid");
}

TEST(PidController, RejectsBadGainsAndVehiclesWithoutAuthority) {
  PidGains bad;
  bad.yaw_gain_per_s = -1.0;
  EXPECT_THROW(PidController(nessie(), bad), std::invalid_argument);
  bad = PidGains{};
  bad.velocity_gain_per_s = std::nan("");
  EXPECT_THROW(PidController(nessie(), bad), std::invalid_argument);
  // Without the lateral thrusters there is no sway.
  sim::VehicleModel crippled = nessie();
  crippled.allocation.col(2).setZero();
  crippled.allocation.col(3).setZero();
  try {
    PidController pid(crippled);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sway"), std::string::npos) << e.what();
  }
}

/// Test 1 with the PID: the full 70 s, trajectory recorded.
struct PidRun {
  eval::SummaryRow row;
  std::vector<TrajectoryRow> trajectory;
};

PidRun run_pid(eval::Scenario scenario) {
  PidController pid(nessie());
  eval::EvaluationConfig config;
  config.task.num_thrusters = nessie().num_thrusters();
  PidRun r;
  r.row = eval::run_evaluation_episode(nessie(), config, pid,
                                       eval::scenario_episodes(config, scenario)[0], &r.trajectory);
  return r;
}

TEST(PidController, ReachesTest1WellInside70sAndHoldsStation) {
  const PidRun r = run_pid(eval::Scenario::kTest1);
  ASSERT_TRUE(r.row.reached);
  EXPECT_LT(r.row.time_to_reach_s, 20.0);           // measured 8.3 s
  EXPECT_EQ(r.trajectory.size(), 701u);             // the full 70 s: it did not stop on arrival
  EXPECT_LT(r.row.mean_error_after_reach_m, 0.15);  // measured 0.03 m
  EXPECT_LT(r.row.final_error_m, 0.1);
  // Holding: once settled it stays well inside the 0.5 m sphere, level and nearly still.
  for (const TrajectoryRow& row : r.trajectory) {
    if (row.time_s < 30.0) continue;
    EXPECT_LT(row.distance_m, 0.25) << "t = " << row.time_s;
    EXPECT_LT(std::abs(row.observation.euler_rpy_rad[1]), 0.1) << "t = " << row.time_s;
    EXPECT_LT(row.observation.velocity_body_mps.norm(), 0.1) << "t = " << row.time_s;
  }
}

TEST(PidController, ReachesTest2AndTheFaultAndTheCurrentCase) {
  for (eval::Scenario s :
       {eval::Scenario::kTest2, eval::Scenario::kFault, eval::Scenario::kCurrent}) {
    const PidRun r = run_pid(s);
    EXPECT_TRUE(r.row.reached) << eval::to_string(s);
    EXPECT_LT(r.row.time_to_reach_s, 30.0) << eval::to_string(s);  // measured 8.5-11.6 s
    EXPECT_LT(r.row.final_error_m, 0.25) << eval::to_string(s);
    EXPECT_EQ(r.row.end_reason, task::EndReason::kReached) << eval::to_string(s);
  }
}

TEST(PidController, TurnsBeforeDrivingWhenFacingAway) {
  const PidRun r = run_pid(eval::Scenario::kTest2);
  // During the first two seconds it turns (and heaves) but does not drive forward or back.
  for (const TrajectoryRow& row : r.trajectory) {
    if (row.time_s > 2.0) break;
    EXPECT_LT(std::abs(row.observation.velocity_body_mps[0]), 0.1) << "t = " << row.time_s;
  }
}

}  // namespace
}  // namespace auvrl::agent
