// auv_logger: logs every channel (or a pattern) into rotating LCM event logs until SIGINT or
// SIGTERM, then flushes, writes a summary of counts and exits. Parses the command line and
// wires library pieces; the logic is in logger/logger.cpp.
#include <iostream>
#include <memory>

#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"
#include "logger/logger.hpp"
#include "logger/schema.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  logger::LoggerConfig config;
  transport::TransportConfig transport_config;
  std::vector<std::string> throttles;
  std::string types_dir = logger::default_types_dir();

  cli::CommandLine cmd(
      "auv_logger",
      "Writes the traffic of the transport (LCM or DDS; every channel, or those matching "
      "--channels) into LCM event logs "
      "(lcm-logger's format) in --dir, rotating by size, and publishes counts on " +
          channels::kLoggerHeartbeat + ".");
  cmd.option("dir", &config.dir, "directory of the log files (created if missing)");
  cmd.require("dir");
  cmd.option("prefix", &config.prefix, "log files are PREFIX-NNNN.lcmlog");
  cmd.option("channels", &config.channels, "full-match regex of the channels to log");
  cmd.option("max-file-mb", &config.max_file_mb, "start a new file before one exceeds this, MB");
  cmd.option("flush-period", &config.flush_period_s, "flush buffered events at least every, s");
  cmd.option("heartbeat-period", &config.heartbeat_period_s, "heartbeat period, s");
  cmd.repeatable("throttle", &throttles,
                 "REGEX=SECONDS: log those channels at most once per interval (built in: " +
                     logger::kDefaultPolicyThrottle.pattern + "=10; =0 turns a rule off)");
  cmd.option("types-dir", &types_dir, "directory of the .lcm files (names types in the summary)");
  cmd.option("queue-capacity", &config.queue_capacity,
             "messages the transport may hold between polls");
  transport::add_transport_options(cmd, transport_config);
  try {
    if (!cmd.parse(argc, argv)) return 0;
    for (const std::string& text : throttles) {
      config.throttles.push_back(logger::parse_throttle_rule(text));
    }
  } catch (const std::exception& e) {
    std::cerr << "auv_logger: " << e.what() << "\n";
    return 2;
  }

  // The types only name channels in the summary: a missing or broken types directory is
  // reported but does not stop logging, which needs no type.
  std::unique_ptr<logger::Schema> schema;
  try {
    schema = std::make_unique<logger::Schema>(logger::Schema::from_directories({types_dir}));
  } catch (const logger::SchemaError& e) {
    std::cerr << "auv_logger: warning: types not loaded, the summary shows fingerprints: "
              << e.what() << "\n";
  }

  try {
    auto transport = transport::make_transport(transport_config);
    signals::install_stop_handlers();
    logger::Logger logger(*transport, config);
    std::cerr << "auv_logger: logging '" << config.channels << "' into " << config.dir << " ("
              << transport::describe(transport_config) << ")\n";
    while (!signals::stop_requested()) logger.poll(50);
    const std::string summary = logger.finish(schema.get());
    std::cerr << "auv_logger: stopped: received " << logger.received() << ", written "
              << logger.written() << ", throttled " << logger.throttled() << ", write errors "
              << logger.write_errors() << "; " << logger.writer().files().size()
              << " files; summary " << summary << "\n";
    return logger.write_errors() == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "auv_logger: " << e.what() << "\n";
    return 1;
  }
}
