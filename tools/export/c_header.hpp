// `auvrl export --format c`: a trained policy as one self-contained C99 header that needs
// nothing beyond <math.h> (link with -lm). It holds
//   - auvrl_policy_params[]: every parameter of the network, float32, bit for bit the network
//     file's, in nn::Mlp::params()'s layout (each layer's weight matrix, out x in,
//     column-major, layer 0 first; then each layer's bias);
//   - auvrl_policy_act(state, action): the forward pass (ReLU hidden layers, tanh output);
//   - auvrl_policy_integrate_goal(offset, nav, goal, moved_goal): the policy's integral action
//     (task::advance_goal_integral), which moves the way-point the state is built for;
//   - auvrl_nav and auvrl_policy_build_state(nav, goal, previous_action, state): the state
//     vector built from the vehicle's navigation data the way task::build_state builds it for
//     the policy's layout, with the scales baked in (computed in double, stored as float, as
//     the task does);
//   - macros for the sizes, the scales and the thrusters' names;
// and a comment that documents the layout, each input's meaning and scale, and each action's
// thruster. Every function is `static inline`, so the header can be included in several
// translation units and what a program does not call costs nothing.
#pragma once

#include <string>

#include "tools/export/exported_policy.hpp"

namespace auvrl::tools {

/// The header's text for the policy.
std::string policy_c_header(const ExportedPolicy& policy);

/// A float as a C float literal that the compiler reads back to the same bits (shortest
/// decimal form with an `f` suffix, e.g. "0.1f", "1.0f", "-2.5e-05f"). Throws
/// std::invalid_argument for an infinity or a NaN.
std::string c_float_literal(float value);

}  // namespace auvrl::tools
