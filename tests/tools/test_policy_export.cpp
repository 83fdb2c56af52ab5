// `auvrl export`: the C header, compiled by a plain C compiler, acts as nn::Mlp::forward does
// and builds the state as task::build_state does for every layout; the ONNX model passes
// onnx.checker and, run by onnxruntime-node, acts as the network does. Each agreement is
// measured on 10,000 seeded random inputs and printed. A test whose tool is missing (cc,
// python3-onnx, node, onnxruntime-node) is skipped, never passed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "agent/vehicle_link.hpp"
#include "agent_test_util.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/random.hpp"
#include "common/nn/serialize.hpp"
#include "common/process.hpp"
#include "common/task/fault_accommodation.hpp"
#include "tools/export/c_header.hpp"
#include "tools/export/policy_export.hpp"

namespace auvrl::tools {
namespace {

using test_support::nessie;
using test_support::TempDir;
using test_support::vehicle_path;

constexpr int kSamples = 10000;
const std::string kPolicy = std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn";
const std::string kDriver = std::string(AUVRL_SOURCE_DIR) + "/tests/tools/export/policy_driver.c";
const std::string kOnnxRun = std::string(AUVRL_SOURCE_DIR) + "/tests/tools/export/onnx_run.js";
const std::string kOnnxScript = std::string(AUVRL_SOURCE_DIR) + "/scripts/export_onnx.py";
const std::string kPython = "/usr/bin/python3";

/// Exit code of a command (its output into log_path), or -1 if it did not exit normally.
int run(const std::vector<std::string>& argv, const std::string& log_path, std::string* log) {
  process::ChildProcess child(argv, log_path);
  int status = child.wait_for_exit(std::chrono::minutes(3));
  if (status == -1) status = child.terminate();
  if (log != nullptr) *log = child.log();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// The first executable `name` on PATH ("" if none).
std::string find_program(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = dir + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

template <class T>
void write_raw(const std::string& path, const std::vector<T>& values) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(T)));
  ASSERT_TRUE(out.good()) << path;
}

template <class T>
std::vector<T> read_raw(const std::string& path) {
  const std::vector<std::uint8_t> bytes = nn::read_file(path);
  std::vector<T> values(bytes.size() / sizeof(T));
  std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
  return values;
}
std::vector<float> read_floats(const std::string& path) { return read_raw<float>(path); }

/// kSamples states of `dim` entries, uniform in [-1, 1]: the range the task's scales bring
/// every input to.
std::vector<float> random_states(int dim, std::uint64_t seed) {
  nn::Rng rng(seed);
  std::vector<float> states(static_cast<std::size_t>(dim) * kSamples);
  for (float& x : states) x = nn::uniform(rng, -1.0f, 1.0f);
  return states;
}

/// The network's actions on the states computed in double from its float32 parameters: the
/// exact values every float32 implementation approximates.
std::vector<double> exact_actions(const std::string& policy, const std::vector<float>& states) {
  const nn::Mlp net = nn::network_from_bytes(nn::read_file(policy), 1);
  const int dim = net.spec().input_dim;
  Eigen::MatrixXd x = Eigen::Map<const nn::Matrix>(states.data(), dim, kSamples).cast<double>();
  for (int l = 0; l < net.num_layers(); ++l) {
    x = (net.weight(l).cast<double>() * x).colwise() + net.bias(l).cast<double>();
    if (net.spec().layer_activation(l) == nn::Activation::kRelu) x = x.cwiseMax(0.0);
    if (net.spec().layer_activation(l) == nn::Activation::kTanh) x = x.array().tanh().matrix();
  }
  return std::vector<double>(x.data(), x.data() + x.size());
}

/// The network's actions on the states (nn::Mlp::forward, one batch).
std::vector<float> network_actions(const std::string& policy, const std::vector<float>& states) {
  nn::Mlp net = nn::network_from_bytes(nn::read_file(policy), kSamples);
  const int dim = net.spec().input_dim;
  const Eigen::Map<const nn::Matrix> in(states.data(), dim, kSamples);
  const nn::Matrix out = net.forward(in);
  return std::vector<float>(out.data(), out.data() + out.size());
}

template <class A, class B>
double max_abs_difference(const std::vector<A>& a, const std::vector<B>& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    worst = std::max(worst, std::abs(static_cast<double>(a[i]) - static_cast<double>(b[i])));
  }
  return worst;
}

/// A random policy network for a layout of Nessie VII, parameters uniform in [-0.5, 0.5].
std::string random_policy(const TempDir& dir, task::StateLayout layout) {
  task::TaskConfig c;
  c.layout = layout;
  task::apply_vehicle(nessie().facts(), c);
  nn::Mlp net(nn::MlpSpec::actor(c.state_dim(), {32, 16}, c.num_thrusters), 1);
  nn::Rng rng(7);
  for (Eigen::Index i = 0; i < net.num_params(); ++i)
    net.params()[i] = nn::uniform(rng, -0.5f, 0.5f);
  const std::string path = dir.path(std::string(task::to_string(layout)) + ".nn");
  nn::save_network_file(path, net);
  return path;
}

/// Exports `policy` as DIR/auvrl_policy.h and compiles the driver against it; returns the
/// program's path ("" and a failure if it does not compile).
std::string build_driver(const TempDir& dir, const std::string& policy, const std::string& cc) {
  std::ostringstream said;
  run_export_request({policy, "c", dir.path("auvrl_policy.h"), vehicle_path(), "", {}}, said);
  const std::string exe = dir.path("policy_driver");
  std::string log;
  const int code = run({cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2", "-I",
                        dir.path(), kDriver, "-o", exe, "-lm"},
                       dir.path("cc.log"), &log);
  EXPECT_EQ(code, 0) << "the header does not compile as C99 without warnings:\n" << log;
  return code == 0 ? exe : "";
}

TEST(PolicyExportC, ActsAsTheNetworkOn10000States) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  TempDir dir;
  const std::string exe = build_driver(dir, kPolicy, cc);
  ASSERT_FALSE(exe.empty());
  const std::vector<float> states = random_states(29, 1);
  write_raw(dir.path("states.f32"), states);
  std::string log;
  ASSERT_EQ(
      run({exe, "act", dir.path("states.f32"), dir.path("actions.f32")}, dir.path("run.log"), &log),
      0)
      << log;
  const std::vector<float> c_actions = read_floats(dir.path("actions.f32"));
  const std::vector<float> mlp_actions = network_actions(kPolicy, states);
  const double diff = max_abs_difference(c_actions, mlp_actions);
  const std::vector<double> exact = exact_actions(kPolicy, states);
  std::cout << "C header vs nn::Mlp::forward, fast.nn, " << kSamples
            << " states: max abs difference " << diff << " (vs the network in double: C header "
            << max_abs_difference(c_actions, exact) << ", nn::Mlp "
            << max_abs_difference(mlp_actions, exact) << "); header "
            << std::filesystem::file_size(dir.path("auvrl_policy.h")) << " bytes\n";
  RecordProperty("max_abs_difference", std::to_string(diff));
  EXPECT_LE(diff, 1e-5);
}

TEST(PolicyExportC, HoldsTheNetworksParametersBitForBit) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  TempDir dir;
  const std::string exe = build_driver(dir, kPolicy, cc);
  ASSERT_FALSE(exe.empty());
  ASSERT_EQ(run({exe, "params", dir.path("params.f32")}, dir.path("run.log"), nullptr), 0);
  const std::vector<float> params = read_floats(dir.path("params.f32"));
  const nn::Mlp net = nn::network_from_bytes(nn::read_file(kPolicy), 1);
  ASSERT_EQ(params.size(), static_cast<std::size_t>(net.num_params()));
  EXPECT_EQ(std::memcmp(params.data(), net.params().data(), params.size() * sizeof(float)), 0);
}

TEST(PolicyExportC, FloatLiteralsReadBackExactly) {
  for (const float v : {0.0f, -0.0f, 1.0f, -2.0f, 0.1f, 1e-5f, 3.4028235e38f, 1.17549435e-38f,
                        1e-45f, 123456.79f}) {
    const std::string literal = c_float_literal(v);
    EXPECT_EQ(literal.back(), 'f');
    EXPECT_NE(literal.find_first_of(".e"), std::string::npos) << literal;
    EXPECT_EQ(std::strtof(literal.c_str(), nullptr), v) << literal;
  }
  EXPECT_THROW(c_float_literal(std::nanf("")), std::invalid_argument);
}

/// kSamples random navigation records for the driver's `state` mode (see policy_driver.c).
std::vector<double> random_navigation(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int record = 12 + 2 * n + 3;
  std::vector<double> nav(static_cast<std::size_t>(record) * kSamples);
  for (int s = 0; s < kSamples; ++s) {
    double* r = nav.data() + static_cast<std::ptrdiff_t>(s) * record;
    for (int i = 0; i < 3; ++i) {
      r[i] = 30.0 * u(rng);                          // position NED, m
      r[3 + i] = (i == 2 ? 3.14159 : 1.5) * u(rng);  // roll, pitch, yaw, rad
      r[6 + i] = 2.0 * u(rng);                       // body velocity, m/s
      r[9 + i] = 1.0 * u(rng);                       // body rates, rad/s
      r[12 + 2 * n + i] = 30.0 * u(rng);             // goal NED, m
    }
    for (int i = 0; i < n; ++i) {
      r[12 + i] = 40.0 * u(rng);                                        // realised thrust, N
      r[12 + n + i] = static_cast<double>(static_cast<float>(u(rng)));  // previous action
    }
  }
  return nav;
}

/// task::build_state on the same records.
std::vector<float> task_states(const task::TaskConfig& c, const std::vector<double>& nav) {
  const int n = c.num_thrusters, record = 12 + 2 * n + 3;
  std::vector<float> out;
  task::StateVector state;
  for (int s = 0; s < kSamples; ++s) {
    const double* r = nav.data() + static_cast<std::ptrdiff_t>(s) * record;
    task::Observation obs;
    obs.position_ned_m = Eigen::Vector3d(r[0], r[1], r[2]);
    obs.euler_rpy_rad = Eigen::Vector3d(r[3], r[4], r[5]);
    obs.velocity_body_mps = Eigen::Vector3d(r[6], r[7], r[8]);
    obs.angular_rate_body_rad_s = Eigen::Vector3d(r[9], r[10], r[11]);
    const std::vector<double> thrust(r + 12, r + 12 + n);
    task::ActionVector previous(n);
    for (int i = 0; i < n; ++i) previous[i] = static_cast<float>(r[12 + n + i]);
    const Eigen::Vector3d goal(r[12 + 2 * n], r[13 + 2 * n], r[14 + 2 * n]);
    task::build_state(c, obs, goal, previous, state, thrust);
    out.insert(out.end(), state.data(), state.data() + state.size());
  }
  return out;
}

/// One layout per case: fast.nn for extended_thrust, random networks for the others.
class PolicyExportLayout : public testing::TestWithParam<std::string> {};

TEST_P(PolicyExportLayout, BuildsTheStateAndActsAsAuvrlDoes) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  TempDir dir;
  const task::StateLayout layout = task::parse_layout(GetParam());
  const std::string policy =
      layout == task::StateLayout::kExtendedThrust ? kPolicy : random_policy(dir, layout);
  const std::string exe = build_driver(dir, policy, cc);
  ASSERT_FALSE(exe.empty());
  task::TaskConfig c;
  c.layout = layout;
  task::apply_vehicle(nessie().facts(), c);
  const std::vector<double> nav = random_navigation(c.num_thrusters, 2);
  write_raw(dir.path("nav.f64"), nav);
  std::string log;
  ASSERT_EQ(
      run({exe, "state", dir.path("nav.f64"), dir.path("states.f32")}, dir.path("run.log"), &log),
      0)
      << log;
  const double state_diff =
      max_abs_difference(read_floats(dir.path("states.f32")), task_states(c, nav));
  const std::vector<float> states = random_states(c.state_dim(), 3);
  write_raw(dir.path("random.f32"), states);
  ASSERT_EQ(
      run({exe, "act", dir.path("random.f32"), dir.path("actions.f32")}, dir.path("run.log"), &log),
      0)
      << log;
  const std::vector<float> c_actions = read_floats(dir.path("actions.f32"));
  const double act_diff = max_abs_difference(c_actions, network_actions(policy, states));
  const double exact_diff = max_abs_difference(c_actions, exact_actions(policy, states));
  std::cout << task::to_string(layout) << ": auvrl_policy_build_state vs task::build_state on "
            << kSamples << " navigation records: max abs difference " << state_diff
            << "; auvrl_policy_act vs nn::Mlp::forward: " << act_diff
            << ", vs the network in double: " << exact_diff << "\n";
  EXPECT_LE(state_diff, 1e-6);
  // The header rounds each layer once (near the network in double); nn::Mlp's float32 sums
  // round at every term, up to about 1.4e-5 on these uniform states for fast.nn.
  EXPECT_LE(exact_diff, 5e-6);
  EXPECT_LE(act_diff, 2e-5);
}

INSTANTIATE_TEST_SUITE_P(AllLayouts, PolicyExportLayout,
                         testing::Values("paper", "extended", "extended_thrust"));

// The header's integral action moves the way-point as the policy controller's does
// (task::advance_goal_integral), step by step: inside and outside its radius, and up to its
// largest offset.
TEST(PolicyExportC, IntegratesTheGoalAsAuvrlDoes) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  TempDir dir;
  const std::string exe = build_driver(dir, kPolicy, cc);
  ASSERT_FALSE(exe.empty());
  task::TaskConfig c;
  task::apply_vehicle(nessie().facts(), c);
  ASSERT_TRUE(c.integral.enabled());
  // A vehicle held off its way-point by a steady push (0.62 m) and wandering about that
  // (+-0.4 m an axis), every 7th step 1.5 m away (outside the 1 m radius): the offset grows
  // about 6 mm a step until it reaches its largest length (1 m).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  const Eigen::Vector3d goal(3.0, -2.0, 8.0), push(-0.5, 0.3, 0.2);
  std::vector<double> records, expected;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  int inside = 0;
  for (int t = 0; t < 3000; ++t) {
    Eigen::Vector3d position = goal + Eigen::Vector3d(1.5, 0.0, 0.0);
    if (t % 7 != 6) position = goal + push + Eigen::Vector3d(u(rng), u(rng), u(rng));
    records.insert(records.end(),
                   {position[0], position[1], position[2], goal[0], goal[1], goal[2]});
    inside += (goal - position).norm() <= c.integral.radius_m;
    const Eigen::Vector3d moved = task::advance_goal_integral(c, goal, position, offset);
    expected.insert(expected.end(), {moved[0], moved[1], moved[2]});
  }
  EXPECT_GT(inside, 1500);
  EXPECT_LE(inside, 3000 - 428);
  EXPECT_NEAR(offset.norm(), c.integral.max_offset_m, 1e-9);
  write_raw(dir.path("nav.f64"), records);
  std::string log;
  ASSERT_EQ(run({exe, "integrate", dir.path("nav.f64"), dir.path("moved.f64")}, dir.path("run.log"),
                &log),
            0)
      << log;
  EXPECT_LE(max_abs_difference(read_raw<double>(dir.path("moved.f64")), expected), 1e-12);
}

// The header's position filter estimates the position as the policy controller's does
// (task::PositionFilter), step by step, on a vehicle that turns, climbs and changes speed under
// noisy fixes, and takes the fix itself on the first step.
TEST(PolicyExportC, FiltersThePositionAsAuvrlDoes) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  TempDir dir;
  const std::string exe = build_driver(dir, kPolicy, cc);
  ASSERT_FALSE(exe.empty());
  task::TaskConfig c;
  task::apply_vehicle(nessie().facts(), c);
  ASSERT_TRUE(c.position_filter.enabled());
  task::PositionFilter filter(c.position_filter, c.control_step_s);
  std::mt19937_64 rng(6);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<double> records, expected;
  for (int t = 0; t < 2000; ++t) {
    const double time_s = 0.1 * t;
    task::Observation obs;
    obs.position_ned_m = Eigen::Vector3d(std::sin(0.05 * time_s) * 20.0 + noise(rng),
                                         time_s * 0.3 + noise(rng), 5.0 + noise(rng));
    obs.euler_rpy_rad = Eigen::Vector3d(0.05 * std::sin(time_s), -0.2 + 0.01 * noise(rng),
                                        std::remainder(0.1 * time_s, 2.0 * 3.14159265358979));
    obs.velocity_body_mps = Eigen::Vector3d(1.0 + std::cos(0.3 * time_s), 0.2, -0.1 + noise(rng));
    for (const Eigen::Vector3d* v :
         {&obs.position_ned_m, &obs.euler_rpy_rad, &obs.velocity_body_mps}) {
      records.insert(records.end(), v->data(), v->data() + 3);
    }
    const Eigen::Vector3d estimate = filter.update(obs);
    if (t == 0) {
      EXPECT_EQ(estimate, obs.position_ned_m);
    }
    expected.insert(expected.end(), estimate.data(), estimate.data() + 3);
  }
  write_raw(dir.path("nav.f64"), records);
  std::string log;
  ASSERT_EQ(run({exe, "filter", dir.path("nav.f64"), dir.path("estimates.f64")},
                dir.path("run.log"), &log),
            0)
      << log;
  EXPECT_LE(max_abs_difference(read_raw<double>(dir.path("estimates.f64")), expected), 1e-9);
}

// Runs the header's fault accommodation and auvrl's (task::ThrusterFaultAccommodation) on the
// same 300 steps of the simulator with these thruster efficiencies, the states the
// simulator's and the actions a random walk; returns the faults auvrl found. The actions must
// agree step by step. cc: the C compiler that builds the driver.
task::ThrusterFaultAccommodation accommodate_like_auvrl(const std::string& cc,
                                                        const std::vector<double>& efficiency,
                                                        std::vector<float>& actions) {
  task::TaskConfig c;
  c.layout = task::StateLayout::kExtendedThrust;
  task::apply_vehicle(nessie().facts(), c);
  task::ThrusterFaultAccommodation faults(c);
  TempDir dir;
  const std::string exe = build_driver(dir, kPolicy, cc);
  EXPECT_FALSE(exe.empty());
  auto link = agent::make_in_process_link(nessie());
  agent::EpisodeStart start;
  start.thruster_efficiency = efficiency;
  agent::VehicleReport report = *link->reset(start);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> walk(-0.15f, 0.15f);
  task::ActionVector previous = task::ActionVector::Zero(6), wanted = previous;
  std::vector<float> records, expected;
  for (int t = 0; t < 300; ++t) {
    task::StateVector state;
    task::build_state(c, report.observation, Eigen::Vector3d(0, 0, 5), previous, state,
                      report.thrust_realised_n);
    for (int i = 0; i < 6; ++i) wanted[i] = std::clamp(wanted[i] + walk(rng), -1.0f, 1.0f);
    records.insert(records.end(), state.data(), state.data() + state.size());
    records.insert(records.end(), wanted.data(), wanted.data() + 6);
    task::ActionVector action = wanted;
    faults.apply(state, action);
    expected.insert(expected.end(), action.data(), action.data() + 6);
    std::vector<double> thrust_n(6);
    for (int i = 0; i < 6; ++i) thrust_n[i] = action[i] * c.max_thrust_n;
    report = *link->step(thrust_n);
    previous = action;
  }
  write_raw(dir.path("records.f32"), records);
  std::string log;
  EXPECT_EQ(run({exe, "faults", dir.path("records.f32"), dir.path("actions.f32")},
                dir.path("run.log"), &log),
            0)
      << log;
  actions = read_raw<float>(dir.path("actions.f32"));
  EXPECT_EQ(actions.size(), expected.size());
  if (actions.size() == expected.size()) {
    EXPECT_LE(max_abs_difference(actions, expected), 1e-6);
  }
  return faults;
}

// The header finds the front vertical thruster dead when auvrl does and rewrites the actions
// as auvrl does.
TEST(PolicyExportC, AccommodatesADeadThrusterAsAuvrlDoes) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  std::vector<float> actions;
  const task::ThrusterFaultAccommodation faults =
      accommodate_like_auvrl(cc, {1, 1, 1, 1, 1, 0}, actions);
  ASSERT_TRUE(faults.dead(5));
  ASSERT_FALSE(actions.empty());
  EXPECT_EQ(actions[actions.size() - 1], 0.0f);  // T6, dead, gets nothing
}

// The same with T1 at 10 % as well: weak, it keeps the walk's commands while the healthy
// thrusters make up its shortfall, as auvrl's do.
TEST(PolicyExportC, AccommodatesAWeakAndADeadThrusterAsAuvrlDoes) {
  const std::string cc = find_program("cc");
  if (cc.empty()) GTEST_SKIP() << "no C compiler `cc` on PATH (apt-get install build-essential)";
  std::vector<float> actions;
  const task::ThrusterFaultAccommodation faults =
      accommodate_like_auvrl(cc, {0.1, 1, 1, 1, 1, 0}, actions);
  ASSERT_TRUE(faults.weak(0));
  ASSERT_TRUE(faults.dead(5));
  for (int i = 1; i < 5; ++i) EXPECT_FALSE(faults.weak(i) || faults.dead(i)) << "T" << i + 1;
}

TEST(PolicyExportC, DocumentsLayoutScalesAndThrusters) {
  const ExportedPolicy policy = load_exported_policy(kPolicy, vehicle_path(), "");
  const std::string header = policy_c_header(policy);
  EXPECT_NE(header.find("State layout: extended_thrust"), std::string::npos);
  EXPECT_NE(header.find("[ 0] goal_error_body_x = way-point minus position, body frame x "
                        "(forward) [m] / 10\n"),
            std::string::npos);
  EXPECT_NE(header.find("[28] thrust_realised_5 = realised thrust of T6_vertical_front"),
            std::string::npos);
  std::size_t at = 0;
  for (int i = 0; i < 6; ++i) {  // action i is thruster i, in the vehicle file's order
    const std::string line = "[" + std::to_string(i) + "] " +
                             nessie().facts().thruster_names[static_cast<std::size_t>(i)] + "\n";
    at = header.find(line, at);
    ASSERT_NE(at, std::string::npos) << line;
  }
  EXPECT_NE(header.find("#define AUVRL_POLICY_MAX_THRUST_N 39.24\n"), std::string::npos);
  // The opening comment ends where it should: nothing in it closed it early.
  EXPECT_EQ(header.find("*/"), header.find(" */\n\n#ifndef AUVRL_POLICY_H") + 1);
}

TEST(PolicyExport, InfersOrChecksTheLayoutAndRefusesBadRequests) {
  TempDir dir;
  std::ostringstream said;
  EXPECT_EQ(load_exported_policy(kPolicy, vehicle_path(), "").task.layout,
            task::StateLayout::kExtendedThrust);
  try {
    load_exported_policy(kPolicy, vehicle_path(), "paper");
    FAIL() << "fast.nn exported with the paper layout";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the paper layout has 18 inputs, the network 29"),
              std::string::npos)
        << e.what();
  }
  nn::Mlp odd(nn::MlpSpec::actor(20, {8}, 6), 1);
  nn::save_network_file(dir.path("odd.nn"), odd);
  try {
    load_exported_policy(dir.path("odd.nn"), vehicle_path(), "");
    FAIL() << "a 20-input network fits no layout of six thrusters";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("fits no state layout"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_exported_policy(kPolicy, vehicle_path(), "sideways"), std::invalid_argument);
  EXPECT_THROW(run_export_request({kPolicy, "tflite", dir.path("x"), vehicle_path(), "", {}}, said),
               std::invalid_argument);
  EXPECT_THROW(run_export_request({kPolicy, "c", "", vehicle_path(), "", {}}, said),
               std::invalid_argument);
  EXPECT_THROW(load_exported_policy(dir.path("missing.nn"), vehicle_path(), ""),
               std::runtime_error);
}

/// What the ONNX tests need that may be missing here ("" when all is there).
std::string missing_onnx_tools(std::string& module_dir) {
  const char* env = std::getenv("AUVRL_ONNXRUNTIME_NODE_DIR");
  module_dir = env != nullptr ? env : AUVRL_ONNXRUNTIME_NODE_DIR;
  if (::access(kPython.c_str(), X_OK) != 0) return kPython + " (apt-get install python3)";
  const std::string log =
      (std::filesystem::temp_directory_path() / "auvrl_onnx_probe.log").string();
  if (run({kPython, "-c", "import onnx"}, log, nullptr) != 0) {
    return "python3-onnx (apt-get install python3-onnx)";
  }
  if (find_program("node").empty()) return "node on PATH (apt-get install nodejs)";
  if (!std::filesystem::exists(module_dir + "/onnxruntime-node/package.json")) {
    return "onnxruntime-node in " + module_dir + " (scripts/install-onnxruntime-node.sh)";
  }
  return "";
}

TEST(PolicyExportOnnx, CheckedAndRunByOnnxruntimeNodeActsAsTheNetwork) {
  std::string module_dir;
  const std::string missing = missing_onnx_tools(module_dir);
  if (!missing.empty()) GTEST_SKIP() << "missing " << missing;
  TempDir dir;
  const std::string model = dir.path("policy.onnx");
  std::ostringstream said;
  ExportRequest request{kPolicy, "onnx", model, vehicle_path(), "", {}};
  request.onnx.script = kOnnxScript;
  run_export_request(request, said);
  std::string log;
  // onnx.checker, and the names and doc strings a user reads.
  const std::string check =
      "import onnx, sys\n"
      "m = onnx.load(sys.argv[1])\n"
      "onnx.checker.check_model(m, full_check=True)\n"
      "g = m.graph\n"
      "assert [i.name for i in g.input] == ['state'] and [o.name for o in g.output] == ['action']\n"
      "assert 'extended_thrust' in g.doc_string and 'goal_error_body_x' in g.input[0].doc_string\n"
      "assert 'T6_vertical_front' in g.output[0].doc_string and 'nessie7' in m.doc_string\n"
      "assert m.opset_import[0].version == 17 and m.ir_version == 8\n"
      "print('checked', onnx.__version__)\n";
  ASSERT_EQ(run({kPython, "-c", check, model}, dir.path("check.log"), &log), 0) << log;
  const std::vector<float> states = random_states(29, 1);
  write_raw(dir.path("states.f32"), states);
  ASSERT_EQ(run({find_program("node"), kOnnxRun, module_dir, model, dir.path("states.f32"), "29",
                 dir.path("actions.f32")},
                dir.path("node.log"), &log),
            0)
      << log;
  const std::vector<float> onnx_actions = read_floats(dir.path("actions.f32"));
  const double diff = max_abs_difference(onnx_actions, network_actions(kPolicy, states));
  std::cout << log << "ONNX model (onnxruntime-node) vs nn::Mlp::forward, fast.nn, " << kSamples
            << " states: max abs difference " << diff << " (vs the network in double: "
            << max_abs_difference(onnx_actions, exact_actions(kPolicy, states)) << "); model "
            << std::filesystem::file_size(model) << " bytes\n";
  RecordProperty("max_abs_difference", std::to_string(diff));
  EXPECT_LE(diff, 1e-5);
  EXPECT_FALSE(std::filesystem::exists(model + ".spec.json")) << "the intermediate is removed";
}

TEST(PolicyExportOnnx, SaysWhenPython3OnnxIsMissing) {
  if (::access(kPython.c_str(), X_OK) != 0) GTEST_SKIP() << "no " << kPython;
  TempDir dir;
  std::ostringstream said;
  // -S: no site-packages, so `import onnx` fails as it does without python3-onnx.
  ExportRequest request{kPolicy, "onnx", dir.path("p.onnx"), vehicle_path(), "", {}};
  request.onnx = {{kPython, "-S"}, kOnnxScript};
  try {
    run_export_request(request, said);
    FAIL() << "exported without python3-onnx";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("apt-get install python3-onnx"), std::string::npos)
        << e.what();
  }
  request.onnx.python = {dir.path("no-python3")};
  EXPECT_THROW(run_export_request(request, said), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(dir.path("p.onnx")));
  EXPECT_FALSE(std::filesystem::exists(dir.path("p.onnx.spec.json")));
}

TEST(PolicyExportOnnx, ScriptRefusesParametersThatDoNotMatchTheirChecksum) {
  std::string module_dir;
  const std::string missing = missing_onnx_tools(module_dir);
  if (missing.rfind("python3-onnx", 0) == 0 || missing.rfind(kPython, 0) == 0) {
    GTEST_SKIP() << "missing " << missing;
  }
  TempDir dir;
  std::string spec = onnx_spec_json(load_exported_policy(kPolicy, vehicle_path(), ""));
  const std::size_t weight = spec.find("\"weight\": [") + 11;
  spec.replace(weight, spec.find(',', weight) - weight, "12.5");  // the first weight changes
  std::ofstream(dir.path("spec.json")) << spec;
  std::string log;
  EXPECT_EQ(run({kPython, kOnnxScript, dir.path("spec.json"), dir.path("p.onnx")},
                dir.path("script.log"), &log),
            2);
  EXPECT_NE(log.find("CRC-32"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir.path("p.onnx")));
}

}  // namespace
}  // namespace auvrl::tools
