// auv_controller's input: SIM_STATE_0 states and MISSION_0 missions as raw bytes, published on
// the in-process transport and handled by a ControllerNode (the code auv_controller runs) that
// drives the committed policy with its driving aids (integral action, position filter, fault
// accommodation) through config/missions/test1.yaml. A state that names another vehicle must
// end the input with UnrecoverableFault (the process exits naming it); a bad mission must be
// refused, the current one kept; any other exception, crash or undefined behaviour is a
// finding.
#include <auvrl_lcm/mission_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>

#include "agent/controller_node.hpp"
#include "agent/controller_process.hpp"
#include "common/channels.hpp"
#include "common/unrecoverable.hpp"
#include "fuzz/fuzz_util.hpp"

using namespace auvrl;

namespace {

/// The vehicle, task, mission and policy auv_controller loads for the committed policy.
const agent::ControllerSetup& setup() {
  static const agent::ControllerSetup* loaded = [] {
    agent::ControllerProcessOptions options;
    options.mission_path = std::string(AUVRL_CONFIG_DIR) + "/missions/test1.yaml";
    options.policy_path = std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn";
    return new agent::ControllerSetup(agent::load_controller_setup(options));
  }();
  return *loaded;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const agent::ControllerSetup& base = setup();
  const auto& policy = static_cast<const agent::PolicyController&>(*base.controller);
  transport::Transport& t = fuzz::in_process_transport();
  static fuzz::NullStream log;
  agent::ControllerNode node(base.model, base.task,
                             std::make_unique<agent::PolicyController>(policy.network(), base.task),
                             base.mission, agent::ControllerNodeOptions{}, t, log);
  for (const fuzz::Record& r : fuzz::read_records(data, size)) {
    // Selector bit 0: a state (0) or a mission (1).
    if ((r.selector & 1) == 0) {
      const auto bytes = fuzz::message_bytes<auvrl_lcm::vehicle_state_t>(r);
      t.publish(channels::sim_state(0), bytes.data(), bytes.size());
    } else {
      const auto bytes = fuzz::message_bytes<auvrl_lcm::mission_t>(r);
      t.publish(channels::mission(0), bytes.data(), bytes.size());
    }
    try {
      node.poll(0);
    } catch (const UnrecoverableFault&) {
      break;  // auv_controller exits here, naming the vehicle it met
    }
  }
  t.drain();  // nothing left for the next input
  return 0;
}
