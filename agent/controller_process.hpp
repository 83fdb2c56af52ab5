// auv_controller's process logic, callable from tests: loading and checking what it is given
// (vehicle, mission, policy or PID; a file that does not fit is refused before anything
// moves, naming the file) and the control loop until the mission ends or a stop signal.
#pragma once

#include <memory>
#include <ostream>
#include <string>

#include "agent/controller_node.hpp"
#include "common/transport_options.hpp"

namespace auvrl::agent {

/// auv_controller's command line.
struct ControllerProcessOptions {
  std::string mission_path;           ///< required
  std::string policy_path;            ///< the policy's network file (or controller "pid")
  std::string controller = "policy";  ///< "policy" or "pid"
  std::string vehicle_path;           ///< "": the mission's vehicle:, else default_vehicle_file()
  std::string layout;                 ///< "": inferred from the policy's input size
  /// The policy's integral action, position filter and fault accommodation.
  task::DrivingAidOptions driving = {};
  /// An Ed25519 public key (PEM): the mission and the policy must then be signed by its
  /// private key (FILE.sig beside each, common/signature.hpp), or they are refused.
  std::string trust_key;
  int vehicle_id = 0;
  int stale_steps = 3;
  double speed = 1.0;  ///< the vehicle runs this many times faster than real time
  /// Exit once the mission is complete (after holding its last way-point for linger_s) or
  /// aborted; otherwise hold until stopped, as on a vehicle.
  bool exit_when_finished = false;
  double linger_s = 2.0;
};

/// Everything the node needs, loaded and checked.
struct ControllerSetup {
  sim::VehicleModel model;
  task::TaskConfig task;
  std::unique_ptr<Controller> controller;
  Mission mission;
};

/// Loads the mission, the vehicle and the controller. Throws std::runtime_error or
/// config::ConfigError naming the file (and field) that does not fit.
ControllerSetup load_controller_setup(const ControllerProcessOptions& options);

/// The control loop on `transport` until a stop signal, or until the mission is finished when
/// options.exit_when_finished. Returns 0 when the mission completed (or was stopped), 3 when
/// it was aborted. Throws UnrecoverableFault when the state names another vehicle.
int run_controller(ControllerSetup& setup, const ControllerProcessOptions& options,
                   transport::Transport& transport, std::ostream& log);

}  // namespace auvrl::agent
