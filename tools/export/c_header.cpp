#include "tools/export/c_header.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <stdexcept>

#include "common/task/fault_accommodation.hpp"

namespace auvrl::tools {

std::string c_float_literal(float value) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument("a network parameter is not finite: cannot export it");
  }
  std::string s = fmt::format("{}", value);  // shortest form that reads back to the same float
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s + "f";
}

namespace {

/// A double as a C double literal that reads back to the same value ("10.0", "39.24").
std::string c_double_literal(double value) {
  std::string s = fmt::format("{}", value);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

/// Text as the lines of a C block comment (" * line"); "*/" cannot end the comment early.
std::string comment_lines(const std::string& text) {
  std::string out = " * ";
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      out += i + 1 < text.size() ? "\n * " : "\n";
    } else if (c == '/' && i > 0 && text[i - 1] == '*') {
      out += " /";
    } else {
      out += c;
    }
  }
  while (out.find(" \n") != std::string::npos) out.replace(out.find(" \n"), 2, "\n");
  return out;
}

/// The share of the distance to the position fix the filter closes each step (0: off).
double position_filter_gain(const task::TaskConfig& task) {
  if (!task.position_filter.enabled()) return 0.0;
  return task::PositionFilter(task.position_filter, task.control_step_s).gain();
}

/// The task's fault accommodation when the policy has one (on, and a layout with the realised
/// thrust), as auvrl's policy controller builds it.
std::optional<task::ThrusterFaultAccommodation> fault_accommodation(const ExportedPolicy& policy) {
  if (!task::has_fault_accommodation(policy.task)) return std::nullopt;
  return task::ThrusterFaultAccommodation(policy.task);
}

/// The header's opening comment: what it holds and how a vehicle uses it.
std::string opening_comment(const ExportedPolicy& policy) {
  const std::string use =
      "Exported by `auvrl export --format c` (docs/export.md): a self-contained C99 header, no\n"
      "dependency beyond <math.h> (link with -lm); every function is static inline.\n"
      "\n" +
      describe_policy(policy) +
      "\n"
      "Use, every control step (" +
      fmt::format("{} s", policy.vehicle.control_step_s) +
      "), as auvrl's episode does:\n"
      "  auvrl_nav nav;          (the vehicle's navigation data, SI units, see below)\n"
      "  double goal_ned_m[3];   (the way-point, NED, m)\n"
      "  float previous[AUVRL_POLICY_NUM_ACTIONS];  (zeros at the start, then the last action)\n"
      "  double offset_ned_m[3];  (zeros at the start of a mission; kept across way-points)\n"
      "  auvrl_position_filter filter;  (zeros at the start of a mission)\n"
      "  auvrl_fault_accommodation faults;  (zeros at the start of a mission)\n"
      "  double moved_goal_ned_m[3];\n"
      "  float state[AUVRL_POLICY_STATE_DIM], action[AUVRL_POLICY_NUM_ACTIONS];\n"
      "  auvrl_policy_filter_position(&filter, &nav);\n"
      "  auvrl_policy_integrate_goal(offset_ned_m, &nav, goal_ned_m, moved_goal_ned_m);\n"
      "  auvrl_policy_build_state(&nav, moved_goal_ned_m, previous, state);\n"
      "  auvrl_policy_act(state, action);\n"
      "  auvrl_policy_accommodate_faults(&faults, state, action);\n"
      "  thrust command of thruster i (N) = action[i] * AUVRL_POLICY_MAX_THRUST_N;\n"
      "  copy action into previous.\n";
  return "/* auvrl_policy.h: a trained auvrl policy.\n *\n" + comment_lines(use) + " */\n";
}

/// Size, scale and thruster-name macros.
std::string macros(const ExportedPolicy& policy) {
  const nn::MlpSpec& spec = policy.network.spec();
  int width = 1;
  for (int h : spec.hidden) width = std::max(width, h);
  const task::ObservationScales& k = policy.task.scales;
  std::string out = fmt::format(
      "#define AUVRL_POLICY_LAYOUT \"{}\"\n"
      "#define AUVRL_POLICY_STATE_DIM {}\n"
      "#define AUVRL_POLICY_NUM_ACTIONS {}\n"
      "#define AUVRL_POLICY_NUM_THRUSTERS {}\n"
      "#define AUVRL_POLICY_NUM_PARAMS {}\n"
      "#define AUVRL_POLICY_MAX_WIDTH {}\n"
      "/* Action +-1 = +- this thrust, N. */\n"
      "#define AUVRL_POLICY_MAX_THRUST_N {}\n"
      "/* The control step, s. */\n"
      "#define AUVRL_POLICY_CONTROL_STEP_S {}\n"
      "/* Integral action (auvrl_policy_integrate_goal): gain 1/s (0: off), radius and largest\n"
      " * offset, m. */\n"
      "#define AUVRL_POLICY_INTEGRAL_GAIN_PER_S {}\n"
      "#define AUVRL_POLICY_INTEGRAL_RADIUS_M {}\n"
      "#define AUVRL_POLICY_INTEGRAL_MAX_OFFSET_M {}\n"
      "/* Position filter (auvrl_policy_filter_position): the share of the distance to the\n"
      " * position fix closed each control step (0: off). */\n"
      "#define AUVRL_POLICY_POSITION_FILTER_GAIN {}\n"
      "/* Fault accommodation (auvrl_policy_accommodate_faults): 1 on, 0 off (or a layout\n"
      " * without the realised thrust). */\n"
      "#define AUVRL_POLICY_FAULT_ACCOMMODATION {}\n"
      "/* Scales: a state entry is the quantity divided by its scale. */\n"
      "#define AUVRL_POLICY_SCALE_POSITION_M {}\n"
      "#define AUVRL_POLICY_SCALE_LINEAR_VELOCITY_MPS {}\n"
      "#define AUVRL_POLICY_SCALE_ANGULAR_RATE_RAD_S {}\n"
      "#define AUVRL_POLICY_SCALE_DEPTH_M {}\n"
      "/* Thruster i's name (action i). */\n",
      task::to_string(policy.task.layout), spec.input_dim, spec.output_dim,
      policy.vehicle.num_thrusters(), policy.network.num_params(), width,
      c_double_literal(policy.task.max_thrust_n), c_double_literal(policy.task.control_step_s),
      c_double_literal(policy.task.integral.gain_per_s),
      c_double_literal(policy.task.integral.radius_m),
      c_double_literal(policy.task.integral.max_offset_m),
      c_double_literal(position_filter_gain(policy.task)), fault_accommodation(policy) ? 1 : 0,
      c_double_literal(k.position_m), c_double_literal(k.linear_velocity_mps),
      c_double_literal(k.angular_rate_rad_s), c_double_literal(k.depth_m));
  for (int i = 0; i < policy.vehicle.num_thrusters(); ++i) {
    out += fmt::format("#define AUVRL_POLICY_THRUSTER_{}_NAME \"{}\"\n", i,
                       policy.vehicle.thruster_names[static_cast<std::size_t>(i)]);
  }
  return out;
}

/// The parameter array, six values a line.
std::string params_array(const ExportedPolicy& policy) {
  const auto params = policy.network.params();
  std::string out =
      "/* Every parameter of the network, float32, in auvrl's layout (nn::Mlp::params()): each\n"
      " * layer's weight matrix (out x in, column-major: W[o][i] at offset + i * out + o), layer\n"
      " * 0 first, then each layer's bias. */\n"
      "static const float auvrl_policy_params[AUVRL_POLICY_NUM_PARAMS] = {\n";
  for (Eigen::Index i = 0; i < params.size(); ++i) {
    out += (i % 6 == 0 ? "    " : " ") + c_float_literal(params[i]) + ",";
    if (i % 6 == 5 || i + 1 == params.size()) out += "\n";
  }
  return out + "};\n";
}

/// The layer function and auvrl_policy_act, one call per weight layer.
std::string act_function(const ExportedPolicy& policy) {
  const nn::MlpSpec& spec = policy.network.spec();
  std::string out =
      "/* One weight layer: out = activation(W in + b); activation 0 identity, 1 ReLU, 2 tanh.\n"
      " * The sums are taken in double (a product of two floats is exact in double), so each\n"
      " * layer's output is W in + b rounded once to float. */\n"
      "static inline void auvrl_policy_layer_(int n_in, int n_out, const float *w, const float "
      "*b,\n"
      "                                       int activation, const float *in, float *out) {\n"
      "  int i, o;\n"
      "  for (o = 0; o < n_out; ++o) {\n"
      "    double sum = (double)b[o];\n"
      "    float z;\n"
      "    for (i = 0; i < n_in; ++i) sum += (double)w[i * n_out + o] * (double)in[i];\n"
      "    z = (float)sum;\n"
      "    out[o] = activation == 1 ? (z > 0.0f ? z : 0.0f) : activation == 2 ? tanhf(z) : z;\n"
      "  }\n"
      "}\n\n"
      "/* The policy: state (AUVRL_POLICY_STATE_DIM floats, see auvrl_policy_build_state) ->\n"
      " * action (AUVRL_POLICY_NUM_ACTIONS floats in [-1, 1]). state and action must not\n"
      " * overlap. Uses 2 x AUVRL_POLICY_MAX_WIDTH floats of stack. */\n"
      "static inline void auvrl_policy_act(const float *state, float *action) {\n";
  const int layers = spec.num_layers();
  const int buffers = std::min(layers - 1, 2);
  for (int b = 0; b < buffers; ++b) out += fmt::format("  float h{}[AUVRL_POLICY_MAX_WIDTH];\n", b);
  for (int l = 0; l < layers; ++l) {
    const std::string in = l == 0 ? "state" : fmt::format("h{}", (l - 1) % 2);
    const std::string dst = l + 1 == layers ? "action" : fmt::format("h{}", l % 2);
    const float* base = policy.network.params().data();
    out += fmt::format(
        "  auvrl_policy_layer_({}, {}, auvrl_policy_params + {}, auvrl_policy_params + {}, {},\n"
        "                      {}, {});\n",
        spec.layer_in(l), spec.layer_out(l), policy.network.weight(l).data() - base,
        policy.network.bias(l).data() - base, static_cast<int>(spec.layer_activation(l)), in, dst);
  }
  return out + "}\n";
}

/// The navigation data struct.
std::string nav_struct(const ExportedPolicy& policy) {
  const bool thrust = policy.task.layout == task::StateLayout::kExtendedThrust;
  return std::string(
             "/* The vehicle's navigation data, as auvrl's task::Observation (frames: NED world,\n"
             " * x north, y east, z down; body, x forward, y starboard, z down). */\n"
             "typedef struct auvrl_nav {\n"
             "  double position_ned_m[3];          /* north, east, down, m */\n"
             "  double euler_rpy_rad[3];           /* roll, pitch, yaw (ZYX Euler), rad */\n"
             "  double velocity_body_mps[3];       /* u, v, w, m/s */\n"
             "  double angular_rate_body_rad_s[3]; /* p, q, r, rad/s */\n"
             "  /* Thrust each thruster produces now (as the vehicle reports it), N; ") +
         (thrust ? "read by this layout. */\n" : "not read by this layout. */\n") +
         "  double thrust_realised_n[AUVRL_POLICY_NUM_THRUSTERS];\n"
         "} auvrl_nav;\n";
}

/// The paper layout's body of auvrl_policy_build_state.
std::string paper_state_body() {
  return "  int i;\n"
         "  for (i = 0; i < 3; ++i) {\n"
         "    const double error_ned = goal_ned_m[i] - nav->position_ned_m[i];\n"
         "    state[i] = (float)(nav->position_ned_m[i] / AUVRL_POLICY_SCALE_POSITION_M);\n"
         "    state[3 + i] = (float)(error_ned / AUVRL_POLICY_SCALE_POSITION_M);\n"
         "    state[6 + i] = (float)(nav->velocity_body_mps[i] / "
         "AUVRL_POLICY_SCALE_LINEAR_VELOCITY_MPS);\n"
         "    state[9 + i] = (float)(nav->angular_rate_body_rad_s[i] / "
         "AUVRL_POLICY_SCALE_ANGULAR_RATE_RAD_S);\n"
         "  }\n"
         "  for (i = 0; i < AUVRL_POLICY_NUM_THRUSTERS; ++i) state[12 + i] = previous_action[i];\n";
}

/// C lines that declare `e` (nav's Euler angles) and `r`, the body-to-NED rotation.
std::string rotation_lines() {
  return "  const double *e = nav->euler_rpy_rad;\n"
         "  const double cphi = cos(e[0]), sphi = sin(e[0]);\n"
         "  const double cth = cos(e[1]), sth = sin(e[1]);\n"
         "  const double cpsi = cos(e[2]), spsi = sin(e[2]);\n"
         "  /* Body-to-NED rotation R (Fossen's R(Theta), ZYX). */\n"
         "  const double r[3][3] = {\n"
         "      {cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth},\n"
         "      {spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi},\n"
         "      {-sth, cth * sphi, cth * cphi}};\n";
}

/// The extended layouts' body of auvrl_policy_build_state.
std::string extended_state_body(bool with_thrust) {
  std::string out =
      rotation_lines() +
      "  /* The body-frame error is R^T e. */\n"
      "  double error_ned[3];\n"
      "  int i;\n"
      "  for (i = 0; i < 3; ++i) error_ned[i] = goal_ned_m[i] - nav->position_ned_m[i];\n"
      "  for (i = 0; i < 3; ++i) {\n"
      "    const double body = r[0][i] * error_ned[0] + r[1][i] * error_ned[1] + r[2][i] * "
      "error_ned[2];\n"
      "    state[i] = (float)(body / AUVRL_POLICY_SCALE_POSITION_M);\n"
      "    state[4 + 2 * i] = (float)sin(e[i]);\n"
      "    state[5 + 2 * i] = (float)cos(e[i]);\n"
      "    state[10 + i] =\n"
      "        (float)(nav->velocity_body_mps[i] / AUVRL_POLICY_SCALE_LINEAR_VELOCITY_MPS);\n"
      "    state[13 + i] =\n"
      "        (float)(nav->angular_rate_body_rad_s[i] / AUVRL_POLICY_SCALE_ANGULAR_RATE_RAD_S);\n"
      "  }\n"
      "  state[3] = (float)(sqrt(error_ned[0] * error_ned[0] + error_ned[1] * error_ned[1] +\n"
      "                          error_ned[2] * error_ned[2]) /\n"
      "                     AUVRL_POLICY_SCALE_POSITION_M);\n"
      "  for (i = 0; i < AUVRL_POLICY_NUM_THRUSTERS; ++i) state[16 + i] = previous_action[i];\n"
      "  state[16 + AUVRL_POLICY_NUM_THRUSTERS] =\n"
      "      (float)(nav->position_ned_m[2] / AUVRL_POLICY_SCALE_DEPTH_M);\n";
  if (with_thrust) {
    out +=
        "  for (i = 0; i < AUVRL_POLICY_NUM_THRUSTERS; ++i) {\n"
        "    state[17 + AUVRL_POLICY_NUM_THRUSTERS + i] =\n"
        "        (float)(nav->thrust_realised_n[i] / AUVRL_POLICY_MAX_THRUST_N);\n"
        "  }\n";
  }
  return out;
}

/// auvrl_policy_build_state for the policy's layout.
std::string build_state_function(const ExportedPolicy& policy) {
  const task::StateLayout layout = policy.task.layout;
  std::string out = fmt::format(
      "/* The state vector of the {} layout (the list at the top of this file),\n"
      " * from the vehicle's navigation data, the way-point (NED, m) and the previous action\n"
      " * (zeros at the start): auvrl's task::build_state with the scales above, computed in\n"
      " * double and stored as float. */\n"
      "static inline void auvrl_policy_build_state(const auvrl_nav *nav, const double "
      "goal_ned_m[3],\n"
      "                                            const float *previous_action, float *state) "
      "{{\n",
      task::to_string(layout));
  out += layout == task::StateLayout::kPaper
             ? paper_state_body()
             : extended_state_body(layout == task::StateLayout::kExtendedThrust);
  return out + "}\n";
}

/// auvrl_policy_integrate_goal: task::advance_goal_integral in C.
std::string integrate_goal_function() {
  return "/* Integral action, as auvrl's policy controller does it (task::advance_goal_integral):\n"
         " * once per control step, before auvrl_policy_build_state, which then takes\n"
         " * moved_goal_ned_m. Within AUVRL_POLICY_INTEGRAL_RADIUS_M of the way-point the offset\n"
         " * moves by gain x control step x (way-point - position), NED, its length clamped to\n"
         " * AUVRL_POLICY_INTEGRAL_MAX_OFFSET_M; moved_goal_ned_m = way-point + offset. Zero\n"
         " * offset_ned_m at the start of a mission and keep it across way-points. */\n"
         "static inline void auvrl_policy_integrate_goal(double offset_ned_m[3], const auvrl_nav "
         "*nav,\n"
         "                                               const double goal_ned_m[3],\n"
         "                                               double moved_goal_ned_m[3]) {\n"
         "  double error_ned[3], error_sq = 0.0, offset_sq = 0.0;\n"
         "  int i;\n"
         "  for (i = 0; i < 3; ++i) {\n"
         "    error_ned[i] = goal_ned_m[i] - nav->position_ned_m[i];\n"
         "    error_sq += error_ned[i] * error_ned[i];\n"
         "  }\n"
         "  if (AUVRL_POLICY_INTEGRAL_GAIN_PER_S > 0.0 && sqrt(error_sq) <= "
         "AUVRL_POLICY_INTEGRAL_RADIUS_M) {\n"
         "    for (i = 0; i < 3; ++i) {\n"
         "      offset_ned_m[i] +=\n"
         "          AUVRL_POLICY_INTEGRAL_GAIN_PER_S * AUVRL_POLICY_CONTROL_STEP_S * "
         "error_ned[i];\n"
         "      offset_sq += offset_ned_m[i] * offset_ned_m[i];\n"
         "    }\n"
         "    if (sqrt(offset_sq) > AUVRL_POLICY_INTEGRAL_MAX_OFFSET_M) {\n"
         "      const double shrink = AUVRL_POLICY_INTEGRAL_MAX_OFFSET_M / sqrt(offset_sq);\n"
         "      for (i = 0; i < 3; ++i) offset_ned_m[i] *= shrink;\n"
         "    }\n"
         "  }\n"
         "  for (i = 0; i < 3; ++i) moved_goal_ned_m[i] = goal_ned_m[i] + offset_ned_m[i];\n"
         "}\n";
}

/// auvrl_position_filter and auvrl_policy_filter_position: task::PositionFilter in C.
std::string filter_position_function() {
  return "/* The position filter, as auvrl's policy controller runs it\n"
         " * (task::PositionFilter): once per control step, first, it replaces\n"
         " * nav->position_ned_m with the estimate that auvrl_policy_integrate_goal and\n"
         " * auvrl_policy_build_state then take. The estimate moves by the measured velocity\n"
         " * rotated into NED (trapezoidal over the step), then by\n"
         " * AUVRL_POLICY_POSITION_FILTER_GAIN of its distance to the fix; the first step\n"
         " * takes the fix. Zero the struct at the start of a mission. */\n"
         "typedef struct auvrl_position_filter {\n"
         "  double position_ned_m[3];   /* the estimate, NED, m */\n"
         "  double velocity_ned_mps[3]; /* the velocity at the last step, NED, m/s */\n"
         "  int started;                /* 0 before the first step */\n"
         "} auvrl_position_filter;\n"
         "\n"
         "static inline void auvrl_policy_filter_position(auvrl_position_filter *filter,\n"
         "                                                auvrl_nav *nav) {\n" +
         rotation_lines() +
         "  double velocity_ned_mps[3];\n"
         "  int i;\n"
         "  if (!(AUVRL_POLICY_POSITION_FILTER_GAIN > 0.0)) return;\n"
         "  for (i = 0; i < 3; ++i) {\n"
         "    velocity_ned_mps[i] = r[i][0] * nav->velocity_body_mps[0] +\n"
         "                          r[i][1] * nav->velocity_body_mps[1] +\n"
         "                          r[i][2] * nav->velocity_body_mps[2];\n"
         "    if (!filter->started) {\n"
         "      filter->position_ned_m[i] = nav->position_ned_m[i];\n"
         "    } else {\n"
         "      filter->position_ned_m[i] += 0.5 * AUVRL_POLICY_CONTROL_STEP_S *\n"
         "                                   (velocity_ned_mps[i] + filter->velocity_ned_mps[i]);\n"
         "      filter->position_ned_m[i] +=\n"
         "          AUVRL_POLICY_POSITION_FILTER_GAIN *\n"
         "          (nav->position_ned_m[i] - filter->position_ned_m[i]);\n"
         "    }\n"
         "    filter->velocity_ned_mps[i] = velocity_ned_mps[i];\n"
         "    nav->position_ned_m[i] = filter->position_ned_m[i];\n"
         "  }\n"
         "  filter->started = 1;\n"
         "}\n";
}

/// The fault accommodation's constants: the replica, the estimate, the wrench matrix B'B.
std::string fault_constants(const task::ThrusterFaultAccommodation& fa,
                            const task::TaskConfig& task) {
  const ThrusterDynamics& td = task.thruster_dynamics;
  std::string out = fmt::format(
      "#define AUVRL_POLICY_FAULT_DEAD_BELOW_ {}\n"
      "#define AUVRL_POLICY_FAULT_WEAK_BELOW_ {}\n"
      "#define AUVRL_POLICY_FAULT_ESTIMATE_GAIN_ {}\n"
      "#define AUVRL_POLICY_FAULT_MIN_SQUARED_N2_ {}\n"
      "#define AUVRL_POLICY_FAULT_DAMPING_ {}\n"
      "#define AUVRL_POLICY_THRUST_DELAY_ {}\n"
      "#define AUVRL_POLICY_THRUST_LAG_BLEND_ {}\n"
      "#define AUVRL_POLICY_THRUST_SLEW_ {}\n"
      "#define AUVRL_POLICY_THRUST_SLEW_STEP_N_ {}\n"
      "static const double auvrl_policy_wrench_gram_[AUVRL_POLICY_NUM_THRUSTERS]"
      "[AUVRL_POLICY_NUM_THRUSTERS] = {{\n",
      c_double_literal(task.fault_accommodation.dead_below),
      c_double_literal(task.fault_accommodation.weak_below), c_double_literal(fa.estimate_gain()),
      c_double_literal(task::ThrusterFaultAccommodation::kMinReplicaThrustN *
                       task::ThrusterFaultAccommodation::kMinReplicaThrustN),
      c_double_literal(fa.damping()), td.delay_enabled ? 1 : 0, c_double_literal(fa.lag_blend()),
      td.slew_enabled ? 1 : 0, c_double_literal(fa.slew_step_n()));
  const Eigen::MatrixXd& gram = fa.wrench_gram();
  for (Eigen::Index i = 0; i < gram.rows(); ++i) {
    out += "    {";
    for (Eigen::Index j = 0; j < gram.cols(); ++j) {
      out += (j ? ", " : "") + c_double_literal(gram(i, j));
    }
    out += "},\n";
  }
  return out + "};\n\n";
}

/// The estimate step of auvrl_policy_accommodate_faults (task::ThrusterFaultAccommodation's).
std::string fault_estimate_lines() {
  return "  for (i = 0; i < n; ++i) {\n"
         "    const double max = AUVRL_POLICY_MAX_THRUST_N;\n"
         "    double command_n = (double)state[16 + i] * max, target_n, change_n, f;\n"
         "    const double realised_n = (double)state[17 + n + i] * max;\n"
         "    command_n = command_n < -max ? -max : command_n > max ? max : command_n;\n"
         "    target_n = AUVRL_POLICY_THRUST_DELAY_ ? fa->replica_delayed_n[i] : command_n;\n"
         "    change_n = AUVRL_POLICY_THRUST_LAG_BLEND_ * (target_n - fa->replica_n[i]);\n"
         "    if (AUVRL_POLICY_THRUST_SLEW_) {\n"
         "      const double s = AUVRL_POLICY_THRUST_SLEW_STEP_N_;\n"
         "      change_n = change_n < -s ? -s : change_n > s ? s : change_n;\n"
         "    }\n"
         "    fa->replica_n[i] += change_n;\n"
         "    fa->replica_delayed_n[i] = command_n;\n"
         "    f = fa->replica_n[i];\n"
         "    fa->moment_realised_replica[i] +=\n"
         "        AUVRL_POLICY_FAULT_ESTIMATE_GAIN_ * (realised_n * f - "
         "fa->moment_realised_replica[i]);\n"
         "    fa->moment_replica_squared[i] +=\n"
         "        AUVRL_POLICY_FAULT_ESTIMATE_GAIN_ * (f * f - fa->moment_replica_squared[i]);\n"
         "    if (fa->moment_replica_squared[i] >= AUVRL_POLICY_FAULT_MIN_SQUARED_N2_) {\n"
         "      double e = fa->moment_realised_replica[i] / fa->moment_replica_squared[i];\n"
         "      e = e < 0.0 ? 0.0 : e > 1.0 ? 1.0 : e;\n"
         "      if (e < AUVRL_POLICY_FAULT_DEAD_BELOW_) {\n"
         "        fa->condition[i] = AUVRL_THRUSTER_DEAD;\n"
         "      } else if (fa->condition[i] == AUVRL_THRUSTER_HEALTHY &&\n"
         "                 e < AUVRL_POLICY_FAULT_WEAK_BELOW_) {\n"
         "        fa->condition[i] = AUVRL_THRUSTER_WEAK;\n"
         "      }\n"
         "      if (fa->condition[i] == AUVRL_THRUSTER_WEAK) fa->share[i] = e;\n"
         "    }\n"
         "    if (fa->condition[i] != AUVRL_THRUSTER_HEALTHY) any = 1;\n"
         "  }\n";
}

/// The redistribution step: the damped least-squares system solved by Cholesky.
std::string fault_redistribution_lines() {
  return "  if (!any) return;\n"
         "  for (i = 0; i < n; ++i) {\n"
         "    const int c = fa->condition[i];\n"
         "    const double share = c == AUVRL_THRUSTER_HEALTHY ? 1.0\n"
         "                         : c == AUVRL_THRUSTER_WEAK  ? fa->share[i]\n"
         "                                                     : 0.0;\n"
         "    shortfall[i] = (1.0 - share) * (double)action[i];\n"
         "  }\n"
         "  for (i = 0; i < n; ++i) {\n"
         "    const double healthy_i = fa->condition[i] == AUVRL_THRUSTER_HEALTHY ? 1.0 : 0.0;\n"
         "    double wrench = 0.0;\n"
         "    for (j = 0; j < n; ++j) {\n"
         "      const double healthy_j = fa->condition[j] == AUVRL_THRUSTER_HEALTHY ? 1.0 : 0.0;\n"
         "      a[i][j] = healthy_i * auvrl_policy_wrench_gram_[i][j] * healthy_j;\n"
         "      wrench += auvrl_policy_wrench_gram_[i][j] * shortfall[j];\n"
         "    }\n"
         "    a[i][i] += AUVRL_POLICY_FAULT_DAMPING_;\n"
         "    x[i] = healthy_i * wrench;\n"
         "  }\n"
         "  /* a = L L^T in place (lower triangle), then L y = x, L^T u = y. */\n"
         "  for (j = 0; j < n; ++j) {\n"
         "    for (k = 0; k < j; ++k) a[j][j] -= a[j][k] * a[j][k];\n"
         "    a[j][j] = sqrt(a[j][j]);\n"
         "    for (i = j + 1; i < n; ++i) {\n"
         "      for (k = 0; k < j; ++k) a[i][j] -= a[i][k] * a[j][k];\n"
         "      a[i][j] /= a[j][j];\n"
         "    }\n"
         "  }\n"
         "  for (i = 0; i < n; ++i) {\n"
         "    for (k = 0; k < i; ++k) x[i] -= a[i][k] * x[k];\n"
         "    x[i] /= a[i][i];\n"
         "  }\n"
         "  for (i = n - 1; i >= 0; --i) {\n"
         "    for (k = i + 1; k < n; ++k) x[i] -= a[k][i] * x[k];\n"
         "    x[i] /= a[i][i];\n"
         "  }\n"
         "  for (i = 0; i < n; ++i) {\n"
         "    const int c = fa->condition[i];\n"
         "    const double u = c == AUVRL_THRUSTER_HEALTHY ? (double)action[i] + x[i]\n"
         "                     : c == AUVRL_THRUSTER_WEAK  ? (double)action[i]\n"
         "                                                 : 0.0;\n"
         "    action[i] = (float)(u < -1.0 ? -1.0 : u > 1.0 ? 1.0 : u);\n"
         "  }\n";
}

/// auvrl_fault_accommodation and auvrl_policy_accommodate_faults:
/// task::ThrusterFaultAccommodation in C (a no-op where the policy has none).
std::string accommodate_faults_function(const ExportedPolicy& policy) {
  const std::optional<task::ThrusterFaultAccommodation> fa = fault_accommodation(policy);
  std::string out =
      "/* Thruster fault accommodation, as auvrl's policy controller runs it\n"
      " * (task::ThrusterFaultAccommodation, docs/usage.md \"Fault accommodation\"): once per\n"
      " * control step, after auvrl_policy_act, on the state the policy was given and its\n"
      " * action, rewritten in place. A replica of a healthy thruster estimates each thruster's\n"
      " * efficiency from the state's realised thrust; one below the weak threshold is weak until\n"
      " * the struct is zeroed again (it keeps its command and the healthy thrusters make up the\n"
      " * wrench it fails to deliver), one below the dead threshold is dead (it gets 0 and the\n"
      " * healthy ones take up its whole share), in damped least squares. With every thruster\n"
      " * healthy the action is untouched. Zero the struct at the start of a mission. */\n"
      "#define AUVRL_THRUSTER_HEALTHY 0 /* a zeroed struct: every thruster healthy */\n"
      "#define AUVRL_THRUSTER_WEAK 1\n"
      "#define AUVRL_THRUSTER_DEAD 2\n"
      "typedef struct auvrl_fault_accommodation {\n"
      "  double replica_delayed_n[AUVRL_POLICY_NUM_THRUSTERS]; /* a healthy thruster's command */\n"
      "  double replica_n[AUVRL_POLICY_NUM_THRUSTERS];         /* and its thrust, N */\n"
      "  double moment_realised_replica[AUVRL_POLICY_NUM_THRUSTERS];\n"
      "  double moment_replica_squared[AUVRL_POLICY_NUM_THRUSTERS];\n"
      "  int condition[AUVRL_POLICY_NUM_THRUSTERS]; /* AUVRL_THRUSTER_HEALTHY, _WEAK or _DEAD */\n"
      "  double share[AUVRL_POLICY_NUM_THRUSTERS];  /* a weak one's estimated efficiency */\n"
      "} auvrl_fault_accommodation;\n\n";
  if (!fa) {
    return out +
           "static inline void auvrl_policy_accommodate_faults(auvrl_fault_accommodation *fa,\n"
           "                                                   const float *state, float *action) "
           "{\n"
           "  (void)fa;\n  (void)state;\n  (void)action;\n}\n";
  }
  return out + fault_constants(*fa, policy.task) +
         "static inline void auvrl_policy_accommodate_faults(auvrl_fault_accommodation *fa,\n"
         "                                                   const float *state, float *action) "
         "{\n"
         "  const int n = AUVRL_POLICY_NUM_THRUSTERS;\n"
         "  double a[AUVRL_POLICY_NUM_THRUSTERS][AUVRL_POLICY_NUM_THRUSTERS];\n"
         "  double x[AUVRL_POLICY_NUM_THRUSTERS], shortfall[AUVRL_POLICY_NUM_THRUSTERS];\n"
         "  int i, j, k, any = 0;\n" +
         fault_estimate_lines() + fault_redistribution_lines() + "}\n";
}

}  // namespace

std::string policy_c_header(const ExportedPolicy& policy) {
  return opening_comment(policy) +
         "\n#ifndef AUVRL_POLICY_H\n#define AUVRL_POLICY_H\n\n#include <math.h>\n\n" +
         macros(policy) + "\n" + params_array(policy) + "\n" + act_function(policy) + "\n" +
         nav_struct(policy) + "\n" + filter_position_function() + "\n" + integrate_goal_function() +
         "\n" + build_state_function(policy) + "\n" + accommodate_faults_function(policy) +
         "\n#endif /* AUVRL_POLICY_H */\n";
}

}  // namespace auvrl::tools
