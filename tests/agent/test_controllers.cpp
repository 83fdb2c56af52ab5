// The controllers: the policy's size checks, the PID baseline on the Nessie VII model
// (allocation, limits, reaching test 1 well inside 70 s and holding station there), on vehicles
// with other controlled DOF (no pitch, no sway, roll), and its per-vehicle gains files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>

#include "agent/controller.hpp"
#include "agent/episode.hpp"
#include "agent/pid_controller.hpp"
#include "agent/vehicle_link.hpp"
#include "common/config/yaml_config.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/gemm.hpp"
#include "common/nn/mlp.hpp"
#include "common/nn/serialize.hpp"
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

// With integral action the network sees the state built for the goal moved by the task's
// integrator (within 1e-6 of building it for that goal: the controller rewrites the goal
// entries of the state it is given); reset() clears the offset; gain 0 leaves the state as is.
TEST(PolicyController, IntegralActionShowsTheNetworkTheMovedGoal) {
  task::TaskConfig task;
  task.layout = task::StateLayout::kExtended;
  task.position_filter.time_constant_s = 0.0;  // the next test has it
  task::apply_vehicle(nessie().facts(), task);
  const int dim = task.state_dim();
  PolicyController policy(actor(dim, 6), dim, 6);
  policy.use_driving_aids(task);
  nn::Mlp reference = actor(dim, 6);
  task::Observation obs;
  obs.position_ned_m = Eigen::Vector3d(2.0, 1.0, 6.0);
  obs.euler_rpy_rad = Eigen::Vector3d(0.05, -0.1, 1.2);
  obs.velocity_body_mps = Eigen::Vector3d(0.1, 0.0, -0.05);
  const Eigen::Vector3d goal(2.3, 0.6, 6.2);  // 0.54 m off: inside the 1 m radius
  const task::ActionVector previous = task::ActionVector::Constant(6, 0.2f);
  task::StateVector state, moved_state;
  task::build_state(task, obs, goal, previous, state);
  task::ActionVector action;
  Eigen::Vector3d expected_offset = Eigen::Vector3d::Zero();
  for (int t = 0; t < 30; ++t) {
    policy.act(obs, goal, state, action);
    const Eigen::Vector3d moved =
        task::advance_goal_integral(task, goal, obs.position_ned_m, expected_offset);
    task::build_state(task, obs, moved, previous, moved_state);
    EXPECT_LE((action - reference.forward(moved_state)).cwiseAbs().maxCoeff(), 1e-6) << t;
  }
  EXPECT_LE((policy.goal_offset_ned_m() - expected_offset).norm(), 1e-12);
  EXPECT_NEAR(policy.goal_offset_ned_m().norm(),
              30 * 0.1 * 0.1 * (goal - obs.position_ned_m).norm(), 1e-9);
  policy.reset();
  EXPECT_EQ(policy.goal_offset_ned_m(), Eigen::Vector3d::Zero());
  task.integral.gain_per_s = 0.0;
  policy.use_driving_aids(task);
  policy.act(obs, goal, state, action);
  EXPECT_EQ(action, reference.forward(state));
  EXPECT_EQ(policy.goal_offset_ned_m(), Eigen::Vector3d::Zero());
}

// With the position filter the network sees the state built where the task's filter puts the
// vehicle (and, with integral action too, for the goal its integrator moved from there); the
// first step after reset() is the measured position.
TEST(PolicyController, ThePositionFilterShowsTheNetworkTheEstimatedPosition) {
  task::TaskConfig task;
  task.layout = task::StateLayout::kExtendedThrust;
  task::apply_vehicle(nessie().facts(), task);
  ASSERT_TRUE(task.position_filter.enabled());  // on by default
  // The made-up thrust below has T4 at 0 N under a -3.9 N command: a dead thruster to the
  // fault accommodation (tested below), not what this test looks at.
  task.fault_accommodation.enabled = false;
  const int dim = task.state_dim();
  const std::vector<double> thrust_n = {5.0, -3.0, 1.0, 0.0, 2.0, -7.0};
  const task::ActionVector previous = task::ActionVector::Constant(6, -0.1f);
  const Eigen::Vector3d goal(2.3, 0.6, 6.2);
  for (double gain_per_s : {0.0, 0.1}) {
    task.integral.gain_per_s = gain_per_s;
    PolicyController policy(actor(dim, 6), task);
    nn::Mlp reference = actor(dim, 6);
    task::PositionFilter filter(task.position_filter, task.control_step_s);
    Eigen::Vector3d expected_offset = Eigen::Vector3d::Zero();
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, 0.1);
    for (int t = 0; t < 40; ++t) {
      task::Observation obs;
      obs.position_ned_m = Eigen::Vector3d(2.0 + noise(rng), 1.0 + noise(rng), 6.0 + noise(rng));
      obs.euler_rpy_rad = Eigen::Vector3d(0.05, -0.1, 1.2);
      obs.velocity_body_mps = Eigen::Vector3d(0.02, 0.0, -0.01);
      task::StateVector state, expected_state;
      task::build_state(task, obs, goal, previous, state, thrust_n);
      task::ActionVector action;
      policy.act(obs, goal, state, action);
      task::Observation estimated = obs;
      estimated.position_ned_m = filter.update(obs);
      if (t == 0) {
        EXPECT_EQ(estimated.position_ned_m, obs.position_ned_m);
      }
      const Eigen::Vector3d shown =
          task::advance_goal_integral(task, goal, estimated.position_ned_m, expected_offset);
      task::build_state(task, estimated, shown, previous, expected_state, thrust_n);
      EXPECT_LE((action - reference.forward(expected_state)).cwiseAbs().maxCoeff(), 1e-5)
          << "gain " << gain_per_s << " step " << t;
    }
    EXPECT_LE((policy.goal_offset_ned_m() - expected_offset).norm(), 1e-12);
  }
}

// The fine-tuning drives its way-points in lockstep (run_policy_episodes): every summary and
// trajectory must be the one the episode gives alone, with the driving aids, a dead thruster,
// sensor noise and episodes that end at different steps.
TEST(RunPolicyEpisodes, GiveEachEpisodeWhatItGivesAlone) {
  if (!nn::gemm::uses_avx512()) {
    GTEST_SKIP() << "the batched pass is bit-exact with the AVX-512 products only";
  }
  task::TaskConfig task;
  task.layout = task::StateLayout::kExtendedThrust;
  task::apply_vehicle(nessie().facts(), task);
  task.max_steps = 120;
  ASSERT_TRUE(task.position_filter.enabled());
  ASSERT_TRUE(task.integral.enabled());
  // The committed policy, which reaches its way-points: the episodes end at their own steps.
  const nn::Mlp committed =
      nn::network_from_bytes(nn::read_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn"), 1);
  nn::Mlp network(committed.spec(), 5);
  network.copy_params_from(committed);
  std::vector<EpisodeOptions> options(5);
  for (std::size_t i = 0; i < options.size(); ++i) {
    EpisodeOptions& o = options[i];
    o.goal_ned_m = Eigen::Vector3d(1.0 + static_cast<double>(i), -2.0, 5.5);
    o.start.euler_rpy_rad[2] = 0.7 * static_cast<double>(i);
    o.start.seed = 11 + i;
    o.run_full_time = true;
    o.steps_after_reach = static_cast<int>(10 * i);
  }
  options[1].start.thruster_efficiency = {1.0, 0.0, 1.0, 1.0, 1.0, 1.0};
  options[2].start.sensor_noise.position_sigma_m = 0.1;
  options[3].start.position_ned_m = Eigen::Vector3d(1.0, 0.0, 5.0);

  std::vector<std::unique_ptr<VehicleLink>> links;
  std::vector<PolicyController> aids;
  std::vector<std::vector<TrajectoryRow>> together(options.size()), alone(options.size());
  std::vector<PolicyEpisode> episodes;
  for (std::size_t i = 0; i < options.size(); ++i) {
    links.push_back(make_in_process_link(nessie()));
    aids.emplace_back(network, task);
  }
  for (std::size_t i = 0; i < options.size(); ++i) {
    options[i].trajectory = &together[i];
    episodes.push_back({&task, links[i].get(), &aids[i], &options[i]});
  }
  const std::vector<EpisodeSummary> summaries = run_policy_episodes(network, episodes);
  ASSERT_EQ(summaries.size(), options.size());
  std::set<int> lengths;
  for (std::size_t i = 0; i < options.size(); ++i) {
    PolicyController policy(network, task);
    EpisodeOptions o = options[i];
    o.trajectory = &alone[i];
    const EpisodeSummary one = run_episode(task, *links[i], policy, o);
    const EpisodeSummary& s = summaries[i];
    lengths.insert(s.length_steps);
    EXPECT_EQ(s.length_steps, one.length_steps) << i;
    EXPECT_EQ(s.end_reason, one.end_reason) << i;
    EXPECT_EQ(s.time_to_reach_s, one.time_to_reach_s) << i;
    EXPECT_EQ(s.thrust_energy, one.thrust_energy) << i;
    EXPECT_EQ(s.final_distance_m, one.final_distance_m) << i;
    EXPECT_EQ(s.mean_error_after_reach_m, one.mean_error_after_reach_m) << i;
    EXPECT_EQ(s.episode_return, one.episode_return) << i;
    ASSERT_EQ(together[i].size(), alone[i].size()) << i;
    for (std::size_t k = 0; k < alone[i].size(); ++k) {
      ASSERT_EQ(together[i][k].thrust_command_n, alone[i][k].thrust_command_n) << i << " " << k;
      ASSERT_EQ(together[i][k].distance_m, alone[i][k].distance_m) << i << " " << k;
    }
  }
  EXPECT_GE(lengths.size(), 4u) << "the episodes should end at different steps";
}

TEST(RunPolicyEpisodes, RefusesMoreEpisodesThanTheNetworksBatchOrANetworkThatDoesNotFit) {
  task::TaskConfig task;
  task::apply_vehicle(nessie().facts(), task);
  nn::Mlp network = actor(task.state_dim(), 6);  // a batch of 1
  std::unique_ptr<VehicleLink> a = make_in_process_link(nessie());
  std::unique_ptr<VehicleLink> b = make_in_process_link(nessie());
  PolicyController pa(network, task), pb(network, task);
  const EpisodeOptions options;
  EXPECT_THROW(run_policy_episodes(
                   network, {{&task, a.get(), &pa, &options}, {&task, b.get(), &pb, &options}}),
               std::invalid_argument);
  nn::Mlp wider(nn::MlpSpec::actor(task.state_dim() + 1, {16, 16}, 6), 2);
  EXPECT_THROW(run_policy_episodes(wider, {{&task, a.get(), &pa, &options}}),
               std::invalid_argument);
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

const sim::VehicleModel& heavy() {
  static const sim::VehicleModel model =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/bluerov2_heavy.yaml");
  return model;
}

/// A standard BlueROV2's layout built in code from the Heavy's model: its four vectored
/// horizontal thrusters, and two vertical thrusters at the sides at x = 0 instead of the Heavy's
/// four: surge, sway, heave, roll and yaw, but no pitch. With the Heavy's own figures (the
/// horizontal thrusters 8.5 cm below the CG, the CB 1 cm above it) surge thrust alone pitches
/// the nose up past 1.2 rad within a second, which no controller of the other DOF can stop;
/// here they sit 2 cm below the CG and the CB 5 cm above it, so that the vehicle's own pitch
/// stability (about 6.6 N m/rad) outweighs the pitch moment of surge (2 cm x the thrust).
sim::VehicleModel no_pitch_vehicle() {
  sim::VehicleModel model = heavy();
  model.name = "bluerov2_no_pitch";
  model.source_file.clear();  // built in code: no gains file beside it
  model.file_crc32 = 0;
  model.cob_body_m = Eigen::Vector3d(0.0, 0.0, -0.05);
  model.thrusters.resize(6);
  for (int i = 0; i < 4; ++i)
    model.thrusters[static_cast<std::size_t>(i)].position_body_m[2] = 0.02;
  model.thrusters[4] = {"T5_starboard_vertical", {0.0, 0.218, 0.0}, {0.0, 0.0, -1.0}};
  model.thrusters[5] = {"T6_port_vertical", {0.0, -0.218, 0.0}, {0.0, 0.0, -1.0}};
  sim::finalize_vehicle_model(model);
  return model;
}

/// Nessie VII without its two lateral thrusters: surge and yaw from T1/T2, heave and pitch
/// from T5/T6, no sway.
sim::VehicleModel no_sway_vehicle() {
  sim::VehicleModel model = nessie();
  model.name = "nessie7_no_sway";
  model.source_file.clear();
  model.file_crc32 = 0;
  model.thrusters.erase(model.thrusters.begin() + 2, model.thrusters.begin() + 4);
  sim::finalize_vehicle_model(model);
  return model;
}

/// One evaluation episode of `steps` control steps to `goal` from the task's start, the
/// trajectory and the PID's asked-for tau at every step.
struct ShortRun {
  eval::SummaryRow row;
  std::vector<TrajectoryRow> trajectory;
  std::vector<Tau> taus;
};

/// Records the PID's tau after every act().
class TauRecorder final : public Controller {
 public:
  explicit TauRecorder(PidController& pid) : pid_(pid) {}
  void reset() override {
    pid_.reset();
    taus.clear();
  }
  void act(const task::Observation& obs, const Eigen::Vector3d& goal, const task::StateVector& x,
           task::ActionVector& action) override {
    pid_.act(obs, goal, x, action);
    taus.push_back(pid_.last_tau());
  }
  std::string name() const override { return "pid"; }
  std::vector<Tau> taus;

 private:
  PidController& pid_;
};

ShortRun run_short(const sim::VehicleModel& model, PidController& pid, const Eigen::Vector3d& goal,
                   int steps) {
  eval::EvaluationConfig config;
  config.task.num_thrusters = model.num_thrusters();
  config.episode_steps = steps;
  eval::EvaluationEpisode episode = eval::scenario_episodes(config, eval::Scenario::kTest1)[0];
  episode.goal_ned_m = goal;
  TauRecorder recorder(pid);
  ShortRun r;
  r.row = eval::run_evaluation_episode(model, config, recorder, episode, &r.trajectory);
  r.taus = recorder.taus;
  return r;
}

TEST(PidController, DrivesWhatANoPitchVehicleControlsAndAsksNoPitchMoment) {
  const sim::VehicleModel model = no_pitch_vehicle();
  ASSERT_FALSE(model.controlled_axes[sim::kPitch]);
  ASSERT_TRUE(model.controlled_axes[sim::kSway]);
  PidController pid(model);
  // The pseudo-inverse reproduces every controlled DOF (surge comes with the pitch moment of
  // thrusters 2 cm below the CG, which is no request) and leaves pitch out.
  Eigen::MatrixXd b = model.allocation;
  b.row(sim::kPitch).setZero();
  for (int axis = 0; axis < 6; ++axis) {
    if (!model.controlled_axes[static_cast<std::size_t>(axis)]) continue;
    Tau unit = Tau::Zero();
    unit[axis] = 1.0;
    EXPECT_LT((b * pid.allocation_pseudo_inverse() * unit - unit).norm(), 1e-9) << axis;
  }
  EXPECT_LT(pid.allocation_pseudo_inverse().col(sim::kPitch).norm(), 1e-12);
  // A way-point ahead, to the side and below: reached within 30 s, never a pitch moment asked.
  const ShortRun r = run_short(model, pid, Eigen::Vector3d(5.0, 3.0, 8.0), 300);
  EXPECT_TRUE(r.row.reached);
  EXPECT_LT(r.row.final_error_m, 0.5);
  ASSERT_EQ(r.taus.size(), 300u);
  for (const Tau& tau : r.taus) ASSERT_EQ(tau[sim::kPitch], 0.0);
}

TEST(PidController, LeavesLateralErrorsToTheHeadingWithoutSway) {
  const sim::VehicleModel model = no_sway_vehicle();
  ASSERT_FALSE(model.controlled_axes[sim::kSway]);
  ASSERT_TRUE(model.controlled_axes[sim::kPitch]);
  PidController pid(model);
  // Abeam of the start: the vehicle must turn to it, since it cannot slide sideways.
  const ShortRun r = run_short(model, pid, Eigen::Vector3d(1.0, 6.0, 7.0), 400);
  EXPECT_TRUE(r.row.reached);
  EXPECT_LT(r.row.final_error_m, 0.5);
  for (const Tau& tau : r.taus) ASSERT_EQ(tau[sim::kSway], 0.0);
}

TEST(PidController, HoldsRollLevelOnlyWhenItsGainsAreOn) {
  // The Heavy controls roll; with the defaults (roll loop off) no roll moment is asked.
  ASSERT_TRUE(heavy().controlled_axes[sim::kRoll]);
  PidController off(heavy());
  task::Observation obs;
  obs.position_ned_m = Eigen::Vector3d(0, 0, 5);
  obs.euler_rpy_rad = Eigen::Vector3d(0.3, 0.0, 0.0);
  obs.angular_rate_body_rad_s = Eigen::Vector3d(0.2, 0.0, 0.0);
  task::ActionVector action;
  off.act(obs, Eigen::Vector3d(5.0, 0.0, 5.0), task::StateVector(), action);
  EXPECT_EQ(off.last_tau()[sim::kRoll], 0.0);
  PidGains gains;
  gains.roll_gain_per_s = 1.0;
  gains.roll_rate_gain_per_s = 2.0;
  PidController on(heavy(), gains);
  on.act(obs, Eigen::Vector3d(5.0, 0.0, 5.0), task::StateVector(), action);
  const double inertia = heavy().mass_total(sim::kRoll, sim::kRoll);
  EXPECT_NEAR(on.last_tau()[sim::kRoll], inertia * 2.0 * (1.0 * -0.3 - 0.2), 1e-12);
  // Nessie VII has no roll authority: the gains are ignored there.
  PidController nessie_pid(nessie(), gains);
  nessie_pid.act(obs, Eigen::Vector3d(5.0, 0.0, 5.0), task::StateVector(), action);
  EXPECT_EQ(nessie_pid.last_tau()[sim::kRoll], 0.0);
}

/// A scratch directory, removed at the end of the test.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() /
           ("auvrl_pid_gains_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(PidGainsFile, SitsBesideTheVehicleFile) {
  EXPECT_EQ(pid_gains_path("config/vehicles/bluerov2.yaml"), "config/vehicles/bluerov2.pid.yaml");
  EXPECT_EQ(pid_gains_path("/a/b.yml"), "/a/b.pid.yaml");
  EXPECT_EQ(pid_gains_path("/a/vehicle"), "/a/vehicle.pid.yaml");
}

TEST(PidGainsFile, RoundTripsExactly) {
  const TempDir dir;
  PidGains gains;
  gains.surge_position_gain_per_s = 0.1234567890123456789;
  gains.roll_rate_gain_per_s = 6.372918273645;
  gains.integral_force_max_n = 1e-7;
  write_pid_gains_file(dir.file("g.pid.yaml"), gains, "how it was made\n\nseed 1");
  const PidGains back = read_pid_gains_file(dir.file("g.pid.yaml"));
  EXPECT_EQ(pid_gains_text(back, ""), pid_gains_text(gains, ""));
  EXPECT_EQ(back.surge_position_gain_per_s, gains.surge_position_gain_per_s);
  EXPECT_EQ(back.roll_rate_gain_per_s, gains.roll_rate_gain_per_s);
  // The header is comments; a key left out keeps its default.
  EXPECT_EQ(pid_gains_text(gains, "a\nb").rfind("# a\n# b\n", 0), 0u);
  write_text(dir.file("partial.pid.yaml"), "# only one\nyaw_gain_per_s: 0.3\n");
  const PidGains partial = read_pid_gains_file(dir.file("partial.pid.yaml"));
  EXPECT_EQ(partial.yaw_gain_per_s, 0.3);
  EXPECT_EQ(partial.velocity_gain_per_s, PidGains{}.velocity_gain_per_s);
}

/// The ConfigError a gains file with `text` raises (fails the test if none).
config::ConfigError gains_error(const TempDir& dir, const std::string& text) {
  const std::string path = dir.file("bad.pid.yaml");
  write_text(path, text);
  try {
    read_pid_gains_file(path);
  } catch (const config::ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for: " << text;
  return config::ConfigError("none");
}

TEST(PidGainsFile, RefusesBadKeysAndGainsNamingFileKeyAndLine) {
  const TempDir dir;
  const std::string path = dir.file("bad.pid.yaml");
  const config::ConfigError unknown = gains_error(dir, "yaw_gain_per_s: 0.4\nyaw_gian: 1\n");
  EXPECT_NE(std::string(unknown.what()).find(path), std::string::npos) << unknown.what();
  EXPECT_NE(std::string(unknown.what()).find("yaw_gian"), std::string::npos) << unknown.what();
  EXPECT_NE(std::string(unknown.what()).find("line 2"), std::string::npos) << unknown.what();
  const config::ConfigError negative = gains_error(dir, "# c\npitch_gain_per_s: -1.2\n");
  EXPECT_EQ(negative.key(), "pitch_gain_per_s");
  EXPECT_NE(std::string(negative.what()).find(path), std::string::npos) << negative.what();
  EXPECT_NE(std::string(negative.what()).find(">= 0"), std::string::npos) << negative.what();
  EXPECT_EQ(gains_error(dir, "velocity_gain_per_s: .nan\n").key(), "velocity_gain_per_s");
  EXPECT_EQ(gains_error(dir, "velocity_gain_per_s: .inf\n").key(), "velocity_gain_per_s");
  EXPECT_EQ(gains_error(dir, "velocity_gain_per_s: fast\n").key(), "velocity_gain_per_s");
}

TEST(PidGainsFile, ChosenForAModelWhenBesideItsVehicleFile) {
  const TempDir dir;
  std::filesystem::copy_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/bluerov2_heavy.yaml",
                             dir.file("rov.yaml"));
  const sim::VehicleModel model = sim::load_vehicle_file(dir.file("rov.yaml"));
  const VehiclePidGains none = pid_gains_for(model);
  EXPECT_FALSE(none.from_file);
  EXPECT_EQ(none.file, dir.file("rov.pid.yaml"));
  EXPECT_EQ(pid_gains_text(none.gains, ""), pid_gains_text(PidGains{}, ""));
  write_text(dir.file("rov.pid.yaml"), "roll_rate_gain_per_s: 4.5\n");
  const VehiclePidGains found = pid_gains_for(model);
  EXPECT_TRUE(found.from_file);
  EXPECT_EQ(found.gains.roll_rate_gain_per_s, 4.5);
  write_text(dir.file("rov.pid.yaml"), "roll_rate_gain: 4.5\n");
  EXPECT_THROW(pid_gains_for(model), config::ConfigError);
  // A model built in code has no file beside it.
  EXPECT_FALSE(pid_gains_for(no_pitch_vehicle()).from_file);
  EXPECT_TRUE(pid_gains_for(no_pitch_vehicle()).file.empty());
}

}  // namespace
}  // namespace auvrl::agent
