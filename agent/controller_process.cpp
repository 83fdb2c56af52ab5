#include "agent/controller_process.hpp"

#include <fmt/format.h>

#include <chrono>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "agent/pid_gains.hpp"
#include "common/signals.hpp"
#include "common/signature.hpp"
#include "common/vehicle_facts.hpp"

namespace auvrl::agent {

ControllerSetup load_controller_setup(const ControllerProcessOptions& options) {
  if (options.mission_path.empty()) throw std::invalid_argument("--mission FILE is required");
  if (!options.trust_key.empty()) {
    // Before anything of them is read: an unsigned or altered file is refused, named.
    signature::verify_file(options.mission_path, options.trust_key);
    if (options.controller == "policy" && !options.policy_path.empty()) {
      signature::verify_file(options.policy_path, options.trust_key);
    }
  }
  ControllerSetup setup{{}, {}, nullptr, read_mission_file(options.mission_path)};
  const std::string vehicle = !options.vehicle_path.empty()         ? options.vehicle_path
                              : !setup.mission.vehicle_path.empty() ? setup.mission.vehicle_path
                                                                    : default_vehicle_file();
  setup.model = sim::load_vehicle_file(vehicle);
  task::apply_vehicle(setup.model.facts(), setup.task);
  if (options.controller == "pid") {
    if (!options.policy_path.empty()) {
      throw std::invalid_argument("--policy and --controller pid exclude each other");
    }
    setup.controller =
        std::make_unique<PidController>(setup.model, pid_gains_for(setup.model).gains);
  } else if (options.controller == "policy") {
    if (options.policy_path.empty()) {
      throw std::invalid_argument("--policy FILE is required (or --controller pid)");
    }
    std::optional<task::StateLayout> layout;
    if (!options.layout.empty()) layout = task::parse_layout(options.layout);
    options.driving.apply(setup.task);
    setup.controller = load_policy(options.policy_path, setup.model.name,
                                   setup.model.num_thrusters(), layout, setup.task);
  } else {
    throw std::invalid_argument("--controller '" + options.controller +
                                "': expected policy or pid");
  }
  return setup;
}

int run_controller(ControllerSetup& setup, const ControllerProcessOptions& options,
                   transport::Transport& transport, std::ostream& log) {
  ControllerNodeOptions node_options;
  node_options.vehicle_id = options.vehicle_id;
  node_options.stale_steps = options.stale_steps;
  node_options.speed = options.speed;
  node_options.name = options.controller;
  ControllerNode node(setup.model, setup.task, std::move(setup.controller), setup.mission,
                      node_options, transport, log);
  log << fmt::format(
      "auv_controller: vehicle {} {}, {} ({} layout), mission '{}' of {} way-points, x{:g}\n",
      options.vehicle_id, describe(setup.model.facts()), options.controller,
      task::to_string(setup.task.layout), setup.mission.name, setup.mission.waypoints.size(),
      options.speed);
  using Clock = std::chrono::steady_clock;
  std::optional<Clock::time_point> finished_at;
  while (!signals::stop_requested()) {
    node.poll(20);
    if (!options.exit_when_finished || !node.finished()) continue;
    if (!finished_at) finished_at = Clock::now();
    if (std::chrono::duration<double>(Clock::now() - *finished_at).count() * options.speed >=
        options.linger_s) {
      break;
    }
  }
  const bool aborted = node.supervisor().state() == SupervisorState::kAborted;
  log << fmt::format(
      "auv_controller: {} after {:.1f} s: way-point {} of {}, supervisor {}{}\n",
      aborted           ? "aborted"
      : node.finished() ? "mission complete"
                        : "stopped",
      node.tracker().elapsed_s(), node.tracker().index(), node.tracker().count(),
      to_string(node.supervisor().state()),
      node.supervisor().reason().empty() ? "" : " (" + node.supervisor().reason() + ")");
  return aborted ? 3 : 0;
}

}  // namespace auvrl::agent
