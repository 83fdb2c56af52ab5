// auv_bridge: forwards chosen channels from one transport to another (typically a system run
// over DDS shown to lcm-spy: --from dds --to lcm). Parses the command line and wires the
// library piece (logger/bridge.hpp); nothing else.
#include <chrono>
#include <iostream>

#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport_options.hpp"
#include "logger/bridge.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  transport::TransportConfig transport_config;
  std::string from = "dds", to = "lcm";
  logger::BridgeConfig config;
  double report_period_s = 10.0;

  cli::CommandLine cmd(
      "auv_bridge",
      "Forwards the channels matching --channels from one transport to the other, the same "
      "bytes on the same channel names (DDS to LCM: lcm-spy and lcm-logger watch a DDS run). "
      "The transport flags configure both sides: --dds-* the DDS one, --lcm-url the LCM one.");
  cmd.option("from", &from, "source transport: dds or lcm");
  cmd.option("to", &to, "destination transport: lcm or dds");
  cmd.option("channels", &config.channels, "full-match regex of the channels to forward");
  cmd.option("queue-capacity", &config.queue_capacity,
             "messages the source may hold between polls");
  cmd.option("report-period", &report_period_s, "a count line every this many seconds");
  transport::add_transport_options(cmd, transport_config);
  transport_config.dds.role = "observer";  // DDS to LCM: reads, publishes nothing on DDS
  transport::TransportConfig source, destination;
  try {
    if (!cmd.parse(argc, argv)) return 0;
    source = destination = transport_config;
    source.kind = transport::parse_transport_kind(from);
    destination.kind = transport::parse_transport_kind(to);
    if (source.kind == destination.kind) {
      throw cli::UsageError("--from and --to name the same transport");
    }
  } catch (const std::exception& e) {
    std::cerr << "auv_bridge: " << e.what() << "\n";
    return 2;
  }

  try {
    auto in = transport::make_transport(source);
    auto out = transport::make_transport(destination);
    signals::install_stop_handlers();
    logger::Bridge bridge(*in, *out, config);
    std::cerr << "auv_bridge: '" << config.channels << "' from " << transport::describe(source)
              << " to " << transport::describe(destination) << "\n";
    const auto period = std::chrono::milliseconds(static_cast<int>(report_period_s * 1000));
    auto next_report = std::chrono::steady_clock::now() + period;
    while (!signals::stop_requested()) {
      bridge.poll(50);
      if (report_period_s > 0 && std::chrono::steady_clock::now() >= next_report) {
        next_report += period;
        std::cerr << "auv_bridge: forwarded " << bridge.forwarded() << " ("
                  << bridge.bytes_forwarded() << " bytes), failed " << bridge.failed() << "\n";
      }
    }
    std::cerr << "auv_bridge: stopped: forwarded " << bridge.forwarded() << ", failed "
              << bridge.failed() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "auv_bridge: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
