// auv_sim's input: SIM_CMD_<id>, SIM_RESET_<id>, SIM_FAULT_<id> and SIM_CURRENT_<id> messages
// as raw bytes, published on the in-process transport and handled by SimServer (the code auv_sim
// runs), for two vehicles (ids 0 and 1) of the real Nessie VII model in lockstep mode.
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>

#include "common/channels.hpp"
#include "fuzz/fuzz_util.hpp"
#include "sim/sim_server.hpp"
#include "sim/vehicle_model.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const sim::VehicleModel model =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
  transport::Transport& t = fuzz::in_process_transport();
  sim::SimServerConfig config;
  config.num_vehicles = 2;
  config.heartbeat_period_s = 3600.0;
  sim::SimServer server(model, t, config);
  // Vehicle ids a channel may name: served, served, just past the range, far out.
  static const int kIds[4] = {0, 1, 2, 99999};
  for (const fuzz::Record& r : fuzz::read_records(data, size)) {
    // Selector: bit 6 a current, else kind (0 command, 1 reset, 2 fault) + 3 * id index.
    const int kind = (r.selector & 0x40) != 0 ? 3 : (r.selector & 0x3F) % 3;
    const int id = kIds[((r.selector & 0x3F) / 3) % 4];
    std::vector<std::uint8_t> bytes;
    std::string channel;
    if (kind == 3) {
      channel = channels::sim_current(id);
      bytes = fuzz::message_bytes<auvrl_lcm::water_current_t>(r);
    } else if (kind == 0) {
      channel = channels::sim_command(id);
      bytes = fuzz::message_bytes<auvrl_lcm::thruster_cmd_t>(r);
    } else if (kind == 1) {
      channel = channels::sim_reset(id);
      bytes = fuzz::message_bytes<auvrl_lcm::vehicle_reset_t>(r);
    } else {
      channel = channels::sim_fault(id);
      bytes = fuzz::message_bytes<auvrl_lcm::thruster_fault_t>(r);
    }
    t.publish(channel, bytes.data(), bytes.size());
    server.poll(0);
  }
  t.drain();  // the states and heartbeats it published (nobody subscribes)
  return 0;
}
