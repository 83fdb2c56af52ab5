#include "logger/logger_process.hpp"

#include "common/listening_lines.hpp"
#include "common/signals.hpp"

namespace auvrl::logger {

void add_throttle_rules(const std::vector<std::string>& texts, LoggerConfig& config) {
  for (const std::string& text : texts) config.throttles.push_back(parse_throttle_rule(text));
}

std::unique_ptr<Schema> load_summary_schema(const std::string& types_dir, std::ostream& log) {
  try {
    return std::make_unique<Schema>(Schema::from_directories({types_dir}));
  } catch (const SchemaError& e) {
    log << "auv_logger: warning: types not loaded, the summary shows fingerprints: " << e.what()
        << "\n";
    return nullptr;
  }
}

int run_logger_process(const LoggerConfig& config,
                       const transport::TransportConfig& transport_config, const Schema* schema,
                       std::ostream& log) {
  auto transport = transport::make_transport(transport_config);
  signals::install_stop_handlers();
  Logger logger(*transport, config);
  log << listening::kLogger << config.channels << "' into " << config.dir << " ("
      << transport::describe(transport_config) << ")\n";
  while (!signals::stop_requested()) logger.poll(50);
  const std::string summary = logger.finish(schema);
  log << "auv_logger: stopped: received " << logger.received() << ", written " << logger.written()
      << ", throttled " << logger.throttled() << ", write errors " << logger.write_errors() << "; "
      << logger.writer().files().size() << " files; summary " << summary << "\n";
  return logger.write_errors() == 0 ? 0 : 1;
}

}  // namespace auvrl::logger
