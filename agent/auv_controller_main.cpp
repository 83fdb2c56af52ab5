// auv_controller: the learned policy (or the PID) as a vehicle's controller, with a mission and
// a safety supervisor. Parses the command line and wires library pieces
// (agent/controller_process.hpp); nothing else.
#include <iostream>

#include "agent/controller_process.hpp"
#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/task/task_yaml.hpp"
#include "common/transport_options.hpp"
#include "common/unrecoverable.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  agent::ControllerProcessOptions options;
  transport::TransportConfig transport_config;
  cli::CommandLine cmd("auv_controller",
                       "Deployable controller: subscribes to SIM_STATE_<id>, runs the policy (or "
                       "the PID) every control step under a safety supervisor, publishes "
                       "SIM_CMD_<id> and MISSION_STATUS, and advances through the mission's "
                       "way-points (docs/deployment.md).");
  cmd.option("mission", &options.mission_path, "mission file (config/missions/*.yaml)");
  cmd.option("policy", &options.policy_path, "policy network file (the nn format)");
  cmd.option("controller", &options.controller, "policy or pid");
  cmd.choices("controller", {"policy", "pid"});
  cmd.option("vehicle", &options.vehicle_path,
             "vehicle file (default: the mission's vehicle:, else config/vehicles/nessie7.yaml)");
  cmd.option("layout", &options.layout, "state layout (default: inferred from the policy)");
  auvrl::task::add_driving_aid_options(cmd, options.driving);
  cmd.option("trust-key", &options.trust_key,
             "Ed25519 public key (PEM): the mission and the policy must be signed by its private "
             "key (FILE.sig beside each; auvrl sign), else they are refused");
  cmd.option("vehicle-id", &options.vehicle_id, "its vehicle's id (SIM_STATE_<id>)");
  cmd.option("stale-steps", &options.stale_steps,
             "control steps without a state that stop the thrusters");
  cmd.option("speed", &options.speed, "the vehicle runs this many times faster than real time");
  cmd.flag("exit-when-finished", &options.exit_when_finished,
           "exit once the mission is complete (after --linger-s) or aborted");
  cmd.option("linger-s", &options.linger_s, "vehicle seconds to hold the last way-point first");
  transport::add_transport_options(cmd, transport_config);
  transport_config.dds.role = "controller";
  agent::ControllerSetup setup;
  try {
    if (!cmd.parse(argc, argv)) return 0;
    setup = agent::load_controller_setup(options);
  } catch (const std::exception& e) {
    std::cerr << "auv_controller: " << e.what() << "\n";
    return 2;
  }
  try {
    auto transport = transport::make_transport(transport_config);
    signals::install_stop_handlers();
    return agent::run_controller(setup, options, *transport, std::cerr);
  } catch (const UnrecoverableFault& e) {
    std::cerr << "auv_controller: " << e.what() << "\n";
    return kExitUnrecoverable;
  } catch (const std::exception& e) {
    std::cerr << "auv_controller: " << e.what() << "\n";
    return 1;
  }
}
