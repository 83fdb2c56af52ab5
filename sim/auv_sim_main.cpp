// auv_sim: serves K simulated vehicles over the transport (lockstep or real time), or runs the
// open-loop validation tool. Parses the command line and wires library pieces; nothing else.
#include <iostream>

#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"
#include "sim/open_loop.hpp"
#include "sim/sim_server.hpp"

namespace {

using namespace auvrl;

/// Serves the vehicles until a stop signal: the transports (and the lockstep bus if
/// configured), the server, a start line and a final line of counts. Throws on errors.
void serve(const std::string& vehicle_path, sim::SimServerConfig server, bool realtime,
           const transport::TransportConfig& transport_config,
           const transport::LockstepBusOptions& lockstep_bus) {
  const sim::VehicleModel model = sim::load_vehicle_file(vehicle_path);
  server.lockstep = !realtime;
  server.vehicle_file = vehicle_path;
  auto transport = transport::make_transport(transport_config);
  const auto lockstep_config = transport::lockstep_bus_config(transport_config, lockstep_bus);
  std::unique_ptr<transport::Transport> lockstep;
  if (lockstep_config) lockstep = transport::make_transport(*lockstep_config);
  signals::install_stop_handlers();
  sim::SimServer sim_server(model, lockstep ? *lockstep : *transport, server, transport.get());
  std::cerr << "auv_sim: " << server.num_vehicles << " x " << model.name << " (" << vehicle_path
            << "), " << (realtime ? "real time" : "lockstep") << ", "
            << transport::describe(lockstep_config ? *lockstep_config : transport_config) << "\n";
  sim_server.run([] { return signals::stop_requested(); });
  const auto counters = sim_server.counters();
  std::cerr << "auv_sim: stopped after " << counters.steps_total << " steps, "
            << counters.resets_total << " resets\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string vehicle_path = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
  sim::SimServerConfig server;
  transport::TransportConfig transport_config;
  bool realtime = false;
  std::string open_loop_in, open_loop_out;
  bool ideal_thrusters = false;

  cli::CommandLine cmd(
      "auv_sim",
      "Simulates K vehicles served over the transport (lockstep for training, real time for "
      "demos), or runs thrust commands open loop from a CSV file.");
  cmd.option("vehicle", &vehicle_path, "vehicle file (YAML)");
  cmd.option("vehicles", &server.num_vehicles, "number of vehicles K");
  cmd.option("first-vehicle-id", &server.first_vehicle_id,
             "ids served: this .. this + K - 1 (several simulators on one bus)");
  cmd.flag("realtime", &realtime, "step at wall-clock rate with the latest command");
  cmd.option("realtime-factor", &server.realtime_factor, "real-time mode: sim seconds per second");
  cmd.option("heartbeat-period", &server.heartbeat_period_s, "heartbeat period, s");
  transport::add_transport_options(cmd, transport_config);
  transport_config.dds.role = "simulator";
  transport::LockstepBusOptions lockstep_bus;
  transport::add_lockstep_options(cmd, lockstep_bus);
  cmd.option("open-loop", &open_loop_in, "open-loop tool: input CSV t,f1..fN (N)");
  cmd.option("out", &open_loop_out, "open-loop tool: output CSV");
  cmd.flag("ideal-thrusters", &ideal_thrusters, "open-loop tool: no thruster delay, lag or slew");
  cmd.app().get_option("--open-loop")->needs("--out");
  cmd.app().get_option("--out")->needs("--open-loop");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "auv_sim: " << e.what() << "\n";
    return 2;
  }

  if (!open_loop_in.empty() || !open_loop_out.empty()) {
    sim::OpenLoopOptions options;
    options.vehicle_path = vehicle_path;
    options.input_csv = open_loop_in;
    options.output_csv = open_loop_out;
    options.ideal_thrusters = ideal_thrusters;
    return sim::run_open_loop(options, std::cerr);
  }

  try {
    serve(vehicle_path, server, realtime, transport_config, lockstep_bus);
  } catch (const std::exception& e) {
    std::cerr << "auv_sim: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
