// Clean shutdown on SIGINT/SIGTERM for every process: the handler only sets a flag that the
// process's loop checks, so nothing is interrupted half-written.
#pragma once

namespace auvrl::signals {

/// Installs SIGINT and SIGTERM handlers that request a stop (and ignores SIGPIPE).
void install_stop_handlers();

/// True once SIGINT or SIGTERM has arrived.
bool stop_requested();

/// Requests a stop from code (tests, fatal errors).
void request_stop();

}  // namespace auvrl::signals
