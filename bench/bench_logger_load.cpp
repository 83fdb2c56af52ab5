// auv_logger under load (a bench, not a test): publishes a traffic mix like the full system's
// at set rates (small vehicle states and commands, experience batches, policy weights with
// their summaries) for a while, stops the logger, and compares what was published with what
// the log holds, per channel. Run inside a namespace:
//   scripts/netns.sh build/bin/bench_logger_load [--state-rate 20000] [--seconds 5] ...
#include <sys/wait.h>

#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/transport.hpp"
#include "logger/event_log.hpp"
#include "logger/logger.hpp"
#include "logger/sample.hpp"
#include "logger/schema.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;

/// One stream of the mix: a channel, its message, its rate.
struct Stream {
  std::string channel;
  std::vector<std::uint8_t> bytes;
  double rate_hz;
  std::int64_t sent = 0;
  Clock::time_point next;
};

}  // namespace

int main(int argc, char** argv) {
  double seconds = 5.0;
  double state_rate = 20000.0;  // vehicle states, all vehicles together
  double batch_rate = 100.0;    // experience batches of --batch-transitions
  int batch_transitions = 64;
  double weights_rate = 2.0;  // 0.5 MB policy weights (logged every one: throttle off)
  int weights_bytes = 500000;
  cli::CommandLine cmd("bench_logger_load", "auv_logger under a paced traffic mix.");
  cmd.option("seconds", &seconds, "how long to publish, s");
  cmd.option("state-rate", &state_rate, "vehicle_state_t and thruster_cmd_t per second (each)");
  cmd.option("batch-rate", &batch_rate, "experience_batch_t per second");
  cmd.option("batch-transitions", &batch_transitions, "transitions per batch");
  cmd.option("weights-rate", &weights_rate, "policy_weights_t (and summaries) per second");
  cmd.option("weights-bytes", &weights_bytes, "size of the network in a policy_weights_t, bytes");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "bench_logger_load: " << e.what() << "\n";
    return 2;
  }

  const std::string dir = test_support::make_temp_dir("auvrl_bench_logger_");
  const logger::Schema schema = logger::Schema::from_directories({logger::default_types_dir()});
  auto sample = [&](const char* type, std::int64_t length) {
    logger::SampleOptions options;
    options.min_variable_length = options.max_variable_length = length;
    return logger::make_sample_message(*schema.find_by_name(type), 1, options);
  };
  std::vector<Stream> streams;
  // Eight vehicles' states and commands share the state rate.
  for (int v = 0; v < 8; ++v) {
    streams.push_back({"SIM_STATE_" + std::to_string(v),
                       sample("auvrl_lcm.vehicle_state_t", 6),
                       state_rate / 8,
                       0,
                       {}});
    streams.push_back({"SIM_CMD_" + std::to_string(v),
                       sample("auvrl_lcm.thruster_cmd_t", 6),
                       state_rate / 8,
                       0,
                       {}});
  }
  // experience_batch_t: every variable dimension gets the transition count (state and action
  // sizes too): a heavier batch than the real one, on the safe side.
  streams.push_back(
      {"EXPERIENCE", sample("auvrl_lcm.experience_batch_t", batch_transitions), batch_rate, 0, {}});
  streams.push_back({channels::kPolicyWeights,
                     sample("auvrl_lcm.policy_weights_t", weights_bytes),
                     weights_rate,
                     0,
                     {}});
  streams.push_back(
      {channels::kPolicySummary, sample("auvrl_lcm.policy_summary_t", 1), weights_rate, 0, {}});

  test_support::ChildProcess logger({test_support::bin_path("auv_logger"), "--dir", dir + "/logs",
                                     "--throttle", "POLICY_WEIGHTS=0", "--heartbeat-period", "0.5"},
                                    dir + "/auv_logger.log");
  auto transport = transport::make_transport({});
  transport::Latest<auvrl_lcm::logger_heartbeat_t> heartbeat(*transport,
                                                             channels::kLoggerHeartbeat);
  const auto up_deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < up_deadline && !heartbeat.has_value()) transport->handle(50);
  if (!heartbeat.has_value()) {
    std::cerr << "bench_logger_load: auv_logger did not start\n" << logger.log();
    return 1;
  }

  // Paced publication: each stream at its rate, no bursts beyond one period's worth.
  const auto start = Clock::now();
  for (Stream& s : streams) s.next = start;
  const auto end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::uint64_t bytes_sent = 0;
  while (Clock::now() < end) {
    const auto now = Clock::now();
    auto soonest = end;
    for (Stream& s : streams) {
      if (s.rate_hz <= 0.0) continue;
      const auto period = std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / s.rate_hz));
      while (s.next <= now) {
        transport->publish(s.channel, s.bytes.data(), s.bytes.size());
        ++s.sent;
        bytes_sent += s.bytes.size();
        s.next += period;
      }
      soonest = std::min(soonest, s.next);
    }
    const auto wait = soonest - Clock::now();
    if (wait > std::chrono::microseconds(100)) std::this_thread::sleep_for(wait);
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int status = logger.terminate(std::chrono::seconds(20));

  std::map<std::string, std::int64_t> logged;
  for (const std::string& file : logger::expand_log_paths({dir + "/logs"})) {
    logger::LogReader reader(file);
    logger::LogEvent event;
    while (reader.next(event)) ++logged[event.channel];
  }
  std::int64_t total_sent = 0, total_logged = 0;
  std::cout << std::left << std::setw(16) << "channel" << std::right << std::setw(10) << "bytes"
            << std::setw(12) << "rate_hz" << std::setw(12) << "published" << std::setw(12)
            << "logged" << std::setw(8) << "lost\n";
  for (const Stream& s : streams) {
    std::cout << std::left << std::setw(16) << s.channel << std::right << std::setw(10)
              << s.bytes.size() << std::setw(12) << std::fixed << std::setprecision(1)
              << s.sent / elapsed << std::setw(12) << s.sent << std::setw(12) << logged[s.channel]
              << std::setw(8) << s.sent - logged[s.channel] << "\n";
    total_sent += s.sent;
    total_logged += logged[s.channel];
  }
  std::cout << "total: " << total_sent << " published (" << std::setprecision(0)
            << total_sent / elapsed << " msg/s, " << std::setprecision(1)
            << bytes_sent / elapsed / 1e6 << " MB/s) in " << std::setprecision(2) << elapsed
            << " s; logged " << total_logged << "; lost " << total_sent - total_logged
            << "; auv_logger exit status " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1)
            << "\n";
  std::cout << logger.log();
  std::filesystem::remove_all(dir);
  return total_sent == total_logged ? 0 : 1;
}
