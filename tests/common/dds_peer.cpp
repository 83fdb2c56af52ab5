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
#include <chrono>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

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

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << "usage: dds_peer echo REGEX CHANNEL | latest CHANNEL TIMEOUT_MS | publish "
                 "CHANNEL N SIZE\n";
    return 2;
  }
  try {
    signals::install_stop_handlers();
    transport::TransportConfig config;
    config.kind = transport::TransportKind::kDds;
    auto t = transport::make_transport(config);
    if (args[0] == "echo" && args.size() == 3) {
      const std::string out = args[2];
      t->subscribe(args[1],
                   [&](const transport::RawMessage& m) { t->publish(out, m.data, m.size); });
      std::cout << "ready" << std::endl;
      while (!signals::stop_requested()) t->handle(50);
      return 0;
    }
    if (args[0] == "latest" && args.size() == 3) {
      const auto start = Clock::now();
      double first_ms = -1;
      std::int64_t count = 0, version = 0;
      std::size_t size = 0;
      t->subscribe(args[1], [&](const transport::RawMessage& m) {
        if (count++ == 0) {
          first_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
          version = version_of(m);
          size = m.size;
        }
      });
      const auto deadline = start + std::chrono::milliseconds(std::stoi(args[2]));
      while (count == 0 && Clock::now() < deadline) t->handle_one(10);
      const auto settle = Clock::now() + std::chrono::milliseconds(200);
      while (Clock::now() < settle) t->handle(10);
      std::cout << "first_ms=" << first_ms << " count=" << count << " size=" << size
                << " version=" << version << std::endl;
      return count > 0 ? 0 : 1;
    }
    if (args[0] == "publish" && args.size() == 4) {
      const int n = std::stoi(args[2]);
      std::vector<std::uint8_t> bytes(std::stoul(args[3]), 0x5a);
      for (std::int64_t v = 1; v <= n; ++v) {
        std::memcpy(bytes.data(), &v, sizeof v);
        t->publish(args[1], bytes.data(), bytes.size());
      }
      std::cout << "published " << n << std::endl;
      while (!signals::stop_requested()) t->handle(50);
      return 0;
    }
    std::cerr << "dds_peer: bad arguments\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "dds_peer: " << e.what() << "\n";
    return 1;
  }
}
