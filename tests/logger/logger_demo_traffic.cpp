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

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;

/// What the demo sends, and how often.
struct DemoSettings {
  int vehicles = 2;
  double rate_hz = 10.0;
  double sample_period_s = 1.0;
  double duration_s = 0.0;
  double episode_s = 30.0;
  std::string types_dir = logger::default_types_dir();
};

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

/// Drives auv_sim's vehicles and publishes the sample messages (see the top of this file).
class DemoTraffic {
 public:
  DemoTraffic(const DemoSettings& settings, transport::Transport& transport)
      : settings_(settings),
        transport_(transport),
        schema_(logger::Schema::from_directories({settings.types_dir})),
        reset_at_(static_cast<std::size_t>(settings.vehicles)),
        answered_at_(static_cast<std::size_t>(settings.vehicles)),
        blown_up_(static_cast<std::size_t>(settings.vehicles), true) {
    transport::subscribe<auvrl_lcm::vehicle_state_t>(
        transport_, "SIM_STATE_[0-9]+",
        [this](const std::string&, const auvrl_lcm::vehicle_state_t& state) {
          if (state.vehicle_id < 0 || state.vehicle_id >= settings_.vehicles) return;
          const auto id = static_cast<std::size_t>(state.vehicle_id);
          answered_at_[id] = Clock::now();
          blown_up_[id] = state.status != 0;
        });
  }

  /// Until a stop signal or the duration is over.
  void run() {
    const auto start = Clock::now();
    auto next_command = start;
    auto next_sample = start;
    auto next_fault = start + std::chrono::seconds(10);
    while (!signals::stop_requested()) {
      const auto now = Clock::now();
      const double t = std::chrono::duration<double>(now - start).count();
      if (settings_.duration_s > 0.0 && t >= settings_.duration_s) break;
      reset_where_needed(now);
      if (now >= next_command) {
        publish_commands(t);
        next_command += seconds(1.0 / settings_.rate_hz);
      }
      if (now >= next_fault) {
        toggle_fault();
        next_fault += std::chrono::seconds(10);
      }
      if (now >= next_sample) {
        publish_samples();
        next_sample += seconds(settings_.sample_period_s);
      }
      transport_.handle(5);  // states; also paces the loop
    }
  }

 private:
  /// A vehicle is reset when its episode is over, when it has not answered for a second (a
  /// reset sent before auv_sim subscribed is lost) and when it has blown up.
  void reset_where_needed(Clock::time_point now) {
    for (int id = 0; id < settings_.vehicles; ++id) {
      const auto i = static_cast<std::size_t>(id);
      const bool silent = now - std::max(answered_at_[i], reset_at_[i]) > std::chrono::seconds(1);
      const bool episode_over = now - reset_at_[i] > seconds(settings_.episode_s);
      if (silent || episode_over || blown_up_[i]) reset_vehicle(id);
    }
  }

  void reset_vehicle(int id) {
    auvrl_lcm::vehicle_reset_t reset{};
    reset.utime = transport::now_utime();
    reset.vehicle_id = id;
    reset.seq = ++reset_seq_;
    reset.seed = reset_seq_;
    reset.position_ned_m[2] = 5.0;
    reset.euler_rpy_rad[2] = 0.5 * id;
    transport::publish(transport_, channels::sim_reset(id), reset);
    reset_at_[static_cast<std::size_t>(id)] = Clock::now();
    blown_up_[static_cast<std::size_t>(id)] = false;
  }

  void publish_commands(double t) {
    ++command_seq_;
    for (int id = 0; id < settings_.vehicles; ++id) {
      auvrl_lcm::thruster_cmd_t command{};
      command.utime = transport::now_utime();
      command.vehicle_id = id;
      command.seq = command_seq_;
      command.num_thrusters = 6;
      for (int i = 0; i < 6; ++i) command.thrust_n.push_back(15.0 * std::sin(0.3 * t + i));
      transport::publish(transport_, channels::sim_command(id), command);
    }
  }

  /// T1 at 10 % on every vehicle, then healthy again, in turn.
  void toggle_fault() {
    faulted_ = !faulted_;
    for (int id = 0; id < settings_.vehicles; ++id) {
      auvrl_lcm::thruster_fault_t fault{};
      fault.utime = transport::now_utime();
      fault.vehicle_id = id;
      fault.num_thrusters = 6;
      fault.thruster_efficiency.assign(6, 1.0);
      fault.thruster_efficiency[0] = faulted_ ? 0.1 : 1.0;
      transport::publish(transport_, channels::sim_fault(id), fault);
    }
  }

  /// A sample of every type that no running process publishes, on DEMO_<TYPE>.
  void publish_samples() {
    // Types a running auv_sim, auv_logger or this program's driving already publishes.
    static const std::set<std::string> live = {
        "auvrl_lcm.vehicle_state_t", "auvrl_lcm.sim_heartbeat_t", "auvrl_lcm.logger_heartbeat_t",
        "auvrl_lcm.thruster_cmd_t",  "auvrl_lcm.vehicle_reset_t", "auvrl_lcm.thruster_fault_t"};
    for (const auto& type : schema_.types()) {
      if (live.count(type->full_name) != 0) continue;
      std::string channel = "DEMO_" + type->short_name;
      if (channel.size() > 2 && channel.compare(channel.size() - 2, 2, "_t") == 0) {
        channel.resize(channel.size() - 2);
      }
      for (char& c : channel) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      const auto bytes = logger::make_sample_message(*type, ++sample_seed_);
      transport_.publish(channel, bytes.data(), bytes.size());
    }
  }

  DemoSettings settings_;
  transport::Transport& transport_;
  logger::Schema schema_;
  std::vector<Clock::time_point> reset_at_;     // per vehicle: when it was last reset
  std::vector<Clock::time_point> answered_at_;  // and when it last answered
  std::vector<bool> blown_up_;                  // a non-zero status in its last state
  std::int64_t reset_seq_ = 0;
  std::int64_t command_seq_ = 1;
  std::uint64_t sample_seed_ = 1;
  bool faulted_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  DemoSettings settings;
  transport::TransportConfig transport_config;
  cli::CommandLine cmd("logger_demo_traffic",
                       "Drives a real-time auv_sim and publishes a sample of every other type.");
  cmd.option("vehicles", &settings.vehicles, "vehicles of auv_sim to drive (ids 0..K-1)");
  cmd.option("rate", &settings.rate_hz, "thrust commands per second per vehicle");
  cmd.option("sample-period", &settings.sample_period_s, "period of the sample messages, s");
  cmd.option("duration", &settings.duration_s,
             "stop after this many seconds (0: at SIGINT/SIGTERM)");
  cmd.option("episode", &settings.episode_s, "reset each vehicle this often, s");
  cmd.option("types-dir", &settings.types_dir, "directory of the .lcm files");
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
    auto transport = transport::make_transport(transport_config);
    signals::install_stop_handlers();
    DemoTraffic(settings, *transport).run();
  } catch (const std::exception& e) {
    std::cerr << "logger_demo_traffic: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
