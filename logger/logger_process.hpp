// auv_logger's process logic, callable from tests: the --throttle rules, the types that name
// channels in the summary, and the logger's lifecycle (log until stopped, then the summary).
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "common/transport.hpp"
#include "logger/logger.hpp"
#include "logger/schema.hpp"

namespace auvrl::logger {

/// Appends one rule per "REGEX=SECONDS" text to config.throttles, in order. Throws
/// std::invalid_argument (parse_throttle_rule) for a malformed one.
void add_throttle_rules(const std::vector<std::string>& texts, LoggerConfig& config);

/// The schema of the .lcm files in `types_dir`, which only names channels in the summary: when
/// it cannot be loaded, a warning on `log` and null (logging needs no type).
std::unique_ptr<Schema> load_summary_schema(const std::string& types_dir, std::ostream& log);

/// The logger's lifecycle: transport, stop handlers, a start line, logging until a stop signal,
/// then the summary (types named with `schema` when not null) and a line of counts. Returns the
/// exit status: 0, or 1 after write errors. Throws on transport or file errors.
int run_logger_process(const LoggerConfig& config,
                       const transport::TransportConfig& transport_config, const Schema* schema,
                       std::ostream& log);

}  // namespace auvrl::logger
