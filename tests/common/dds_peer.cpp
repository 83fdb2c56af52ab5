// A second process for the DDS transport tests (started by test_transport_dds inside its network
// namespace). Modes:
//   dds_peer echo REGEX CHANNEL        republishes every message on channels matching REGEX on
//                                      CHANNEL (the same bytes) until SIGTERM
//   dds_peer latest CHANNEL TIMEOUT_MS subscribes to CHANNEL, waits up to TIMEOUT_MS for the
//                                      first message, drains for 200 ms more and prints
//                                      "first_ms=<ms from subscribing> count=<messages>
//                                      size=<bytes> version=<first 8 bytes, little-endian>"
//   dds_peer publish CHANNEL N SIZE    publishes N messages of SIZE bytes (version 1..N in the
//                                      first 8 bytes), then stays until SIGTERM (a transient-
//                                      local writer's history lives as long as its process)
//   dds_peer --dds-security DIR ...    the same as a secured participant (DDS Security)
#include <chrono>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;

std::int64_t version_of(const transport::RawMessage& m) {
  std::int64_t v = 0;
  if (m.size >= sizeof v) std::memcpy(&v, m.data, sizeof v);
  return v;
}

/// The command line of every mode (one subcommand each).
struct Args {
  std::string regex, channel;
  int timeout_ms = 0;
  std::int64_t count = 0;
  std::size_t size = 0;
};

int run_echo(transport::Transport& t, const Args& a) {
  t.subscribe(a.regex,
              [&](const transport::RawMessage& m) { t.publish(a.channel, m.data, m.size); });
  std::cout << "ready" << std::endl;
  while (!signals::stop_requested()) t.handle(50);
  return 0;
}

int run_latest(transport::Transport& t, const Args& a) {
  const auto start = Clock::now();
  double first_ms = -1;
  std::int64_t count = 0, version = 0;
  std::size_t size = 0;
  t.subscribe(a.channel, [&](const transport::RawMessage& m) {
    if (count++ == 0) {
      first_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      version = version_of(m);
      size = m.size;
    }
  });
  const auto deadline = start + std::chrono::milliseconds(a.timeout_ms);
  while (count == 0 && Clock::now() < deadline) t.handle_one(10);
  const auto settle = Clock::now() + std::chrono::milliseconds(200);
  while (Clock::now() < settle) t.handle(10);
  std::cout << "first_ms=" << first_ms << " count=" << count << " size=" << size
            << " version=" << version << std::endl;
  return count > 0 ? 0 : 1;
}

int run_publish(transport::Transport& t, const Args& a) {
  std::vector<std::uint8_t> bytes(a.size, 0x5a);
  for (std::int64_t v = 1; v <= a.count; ++v) {
    std::memcpy(bytes.data(), &v, sizeof v);
    t.publish(a.channel, bytes.data(), bytes.size());
  }
  std::cout << "published " << a.count << std::endl;
  while (!signals::stop_requested()) t.handle(50);
  return 0;
}

/// Declares the three modes on cmd, bound to a.
void declare_modes(cli::CommandLine& cmd, Args& a) {
  cli::CommandLine& echo =
      cmd.subcommand("echo", "republish what matches REGEX on CHANNEL until SIGTERM");
  echo.positional("REGEX", &a.regex, "full-match regex of the channels to echo");
  echo.positional("CHANNEL", &a.channel, "channel to republish on");
  cli::CommandLine& latest =
      cmd.subcommand("latest", "wait for the first message on CHANNEL, print what came");
  latest.positional("CHANNEL", &a.channel, "channel to subscribe to");
  latest.positional("TIMEOUT_MS", &a.timeout_ms, "how long to wait for the first message, ms");
  cli::CommandLine& publish =
      cmd.subcommand("publish", "publish N messages on CHANNEL, then stay until SIGTERM");
  publish.positional("CHANNEL", &a.channel, "channel to publish on");
  publish.positional("N", &a.count, "messages (versions 1..N in their first 8 bytes)");
  publish.positional("SIZE", &a.size, "bytes per message (at least 8: the version)");
  publish.check("SIZE", cli::at_least(8));
  cmd.require_subcommand();
}

}  // namespace

int main(int argc, char** argv) {
  cli::CommandLine cmd("dds_peer", "A second process for the DDS transport tests.");
  Args args;
  std::string security_dir;
  cmd.option("dds-security", &security_dir, "a participant's DDS Security directory");
  declare_modes(cmd, args);
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "dds_peer: " << e.what() << "\n";
    return 2;
  }
  try {
    signals::install_stop_handlers();
    transport::TransportConfig config;
    config.kind = transport::TransportKind::kDds;
    config.dds.security_dir = security_dir;
    auto t = transport::make_transport(config);
    const std::string mode = cmd.chosen();
    if (mode == "echo") return run_echo(*t, args);
    if (mode == "latest") return run_latest(*t, args);
    return run_publish(*t, args);
  } catch (const std::exception& e) {
    std::cerr << "dds_peer: " << e.what() << "\n";
    return 1;
  }
}
