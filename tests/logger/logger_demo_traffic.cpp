// Demo traffic for looking at a live system with lcm-spy (and for logging it): drives the
// vehicles of a real-time auv_sim (a reset per --episode seconds, and whenever a vehicle has
// not answered for a second or has blown up; thrust commands at --rate; a T1 fault toggled
// every 10 s) and publishes, once per --sample-period, a sample message of every other type in
// the types directory on channel DEMO_<TYPE> (types that no process publishes yet).
//   scripts/netns.sh --pidfile RUN/netns.pid sh -c 'build/bin/auv_sim --realtime --vehicles 2 &
//     build/bin/logger_demo_traffic --vehicles 2'
#include <algorithm>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <set>
#include <vector>

#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "logger/sample.hpp"
#include "logger/schema.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  int vehicles = 2;
  double rate_hz = 10.0;
  double sample_period_s = 1.0;
  double duration_s = 0.0;
  double episode_s = 30.0;
  std::string types_dir = logger::default_types_dir();
  transport::TransportConfig transport_config;
  cli::CommandLine cmd("logger_demo_traffic",
                       "Drives a real-time auv_sim and publishes a sample of every other type.");
  cmd.option("vehicles", &vehicles, "vehicles of auv_sim to drive (ids 0..K-1)");
  cmd.option("rate", &rate_hz, "thrust commands per second per vehicle");
  cmd.option("sample-period", &sample_period_s, "period of the sample messages, s");
  cmd.option("duration", &duration_s, "stop after this many seconds (0: at SIGINT/SIGTERM)");
  cmd.option("episode", &episode_s, "reset each vehicle this often, s");
  cmd.option("types-dir", &types_dir, "directory of the .lcm files");
  cmd.option("lcm-url", &transport_config.lcm_url, "LCM URL");
  cmd.check("vehicles", cli::at_least(0));
  for (const char* name : {"rate", "sample-period", "episode"}) cmd.check(name, cli::positive());
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "logger_demo_traffic: " << e.what() << "\n";
    return 2;
  }
  try {
    const logger::Schema schema = logger::Schema::from_directories({types_dir});
    // Types a running auv_sim, auv_logger or this program's driving already publishes.
    const std::set<std::string> live = {
        "auvrl_lcm.vehicle_state_t", "auvrl_lcm.sim_heartbeat_t", "auvrl_lcm.logger_heartbeat_t",
        "auvrl_lcm.thruster_cmd_t",  "auvrl_lcm.vehicle_reset_t", "auvrl_lcm.thruster_fault_t"};
    auto transport = transport::make_transport(transport_config);
    signals::install_stop_handlers();
    using Clock = std::chrono::steady_clock;
    // Per vehicle: when it was reset and when it last answered (a reset sent before auv_sim
    // subscribed is lost, and a blown-up vehicle answers with a non-zero status).
    std::vector<Clock::time_point> reset_at(static_cast<std::size_t>(vehicles));
    std::vector<Clock::time_point> answered_at(static_cast<std::size_t>(vehicles));
    std::vector<bool> blown_up(static_cast<std::size_t>(vehicles), true);
    transport::subscribe<auvrl_lcm::vehicle_state_t>(
        *transport, "SIM_STATE_[0-9]+",
        [&](const std::string&, const auvrl_lcm::vehicle_state_t& state) {
          if (state.vehicle_id < 0 || state.vehicle_id >= vehicles) return;
          const auto id = static_cast<std::size_t>(state.vehicle_id);
          answered_at[id] = Clock::now();
          blown_up[id] = state.status != 0;
        });
    std::int64_t reset_seq = 0;
    auto reset_vehicle = [&](int id) {
      auvrl_lcm::vehicle_reset_t reset{};
      reset.utime = transport::now_utime();
      reset.vehicle_id = id;
      reset.seq = ++reset_seq;
      reset.seed = reset_seq;
      reset.position_ned_m[2] = 5.0;
      reset.euler_rpy_rad[2] = 0.5 * id;
      transport::publish(*transport, channels::sim_reset(id), reset);
      reset_at[static_cast<std::size_t>(id)] = Clock::now();
      blown_up[static_cast<std::size_t>(id)] = false;
    };
    const auto start = Clock::now();
    auto next_command = start;
    auto next_sample = start;
    auto next_fault = start + std::chrono::seconds(10);
    bool faulted = false;
    std::int64_t seq = 1;
    std::uint64_t seed = 1;
    while (!signals::stop_requested()) {
      const auto now = Clock::now();
      const double t = std::chrono::duration<double>(now - start).count();
      if (duration_s > 0.0 && t >= duration_s) break;
      for (int id = 0; id < vehicles; ++id) {
        const auto i = static_cast<std::size_t>(id);
        const bool silent = now - std::max(answered_at[i], reset_at[i]) > std::chrono::seconds(1);
        const bool episode_over = now - reset_at[i] > std::chrono::duration<double>(episode_s);
        if (silent || episode_over || blown_up[i]) reset_vehicle(id);
      }
      if (now >= next_command) {
        ++seq;
        for (int id = 0; id < vehicles; ++id) {
          auvrl_lcm::thruster_cmd_t command{};
          command.utime = transport::now_utime();
          command.vehicle_id = id;
          command.seq = seq;
          command.num_thrusters = 6;
          for (int i = 0; i < 6; ++i) command.thrust_n.push_back(15.0 * std::sin(0.3 * t + i));
          transport::publish(*transport, channels::sim_command(id), command);
        }
        next_command += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(1.0 / rate_hz));
      }
      if (now >= next_fault) {
        faulted = !faulted;
        for (int id = 0; id < vehicles; ++id) {
          auvrl_lcm::thruster_fault_t fault{};
          fault.utime = transport::now_utime();
          fault.vehicle_id = id;
          fault.num_thrusters = 6;
          fault.thruster_efficiency.assign(6, 1.0);
          fault.thruster_efficiency[0] = faulted ? 0.1 : 1.0;
          transport::publish(*transport, channels::sim_fault(id), fault);
        }
        next_fault += std::chrono::seconds(10);
      }
      if (now >= next_sample) {
        for (const auto& type : schema.types()) {
          if (live.count(type->full_name) != 0) continue;
          std::string channel = "DEMO_" + type->short_name;
          if (channel.size() > 2 && channel.compare(channel.size() - 2, 2, "_t") == 0) {
            channel.resize(channel.size() - 2);
          }
          for (char& c : channel)
            c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
          const auto bytes = logger::make_sample_message(*type, ++seed);
          transport->publish(channel, bytes.data(), bytes.size());
        }
        next_sample += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(sample_period_s));
      }
      transport->handle(5);  // states; also paces the loop
    }
  } catch (const std::exception& e) {
    std::cerr << "logger_demo_traffic: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
