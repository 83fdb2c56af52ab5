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

/// The command line: duration and the mix's rates and sizes.
struct Options {
  double seconds = 5.0;
  double state_rate = 20000.0;  ///< vehicle states, all vehicles together
  double batch_rate = 100.0;    ///< experience batches of batch_transitions
  int batch_transitions = 64;
  double weights_rate = 2.0;  ///< 0.5 MB policy weights (logged every one: throttle off)
  int weights_bytes = 500000;
};

/// What the paced publication did.
struct Published {
  double elapsed_s = 0.0;
  std::uint64_t bytes = 0;
};

/// The traffic mix: eight vehicles' states and commands, experience, weights and summaries.
std::vector<Stream> make_streams(const Options& o) {
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
                       o.state_rate / 8,
                       0,
                       {}});
    streams.push_back({"SIM_CMD_" + std::to_string(v),
                       sample("auvrl_lcm.thruster_cmd_t", 6),
                       o.state_rate / 8,
                       0,
                       {}});
  }
  // experience_batch_t: every variable dimension gets the transition count (state and action
  // sizes too): a heavier batch than the real one, on the safe side.
  streams.push_back({"EXPERIENCE",
                     sample("auvrl_lcm.experience_batch_t", o.batch_transitions),
                     o.batch_rate,
                     0,
                     {}});
  streams.push_back({channels::kPolicyWeights,
                     sample("auvrl_lcm.policy_weights_t", o.weights_bytes),
                     o.weights_rate,
                     0,
                     {}});
  streams.push_back(
      {channels::kPolicySummary, sample("auvrl_lcm.policy_summary_t", 1), o.weights_rate, 0, {}});
  return streams;
}

/// Waits up to 10 s for auv_logger's first heartbeat; whether it came.
bool wait_for_logger(transport::Transport& transport) {
  transport::Latest<auvrl_lcm::logger_heartbeat_t> heartbeat(transport, channels::kLoggerHeartbeat);
  const auto up_deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < up_deadline && !heartbeat.has_value()) transport.handle(50);
  return heartbeat.has_value();
}

/// Paced publication: each stream at its rate, no bursts beyond one period's worth.
Published publish_paced(transport::Transport& transport, std::vector<Stream>& streams,
                        double seconds) {
  const auto start = Clock::now();
  for (Stream& s : streams) s.next = start;
  const auto end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  Published result;
  while (Clock::now() < end) {
    const auto now = Clock::now();
    auto soonest = end;
    for (Stream& s : streams) {
      if (s.rate_hz <= 0.0) continue;
      const auto period = std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / s.rate_hz));
      while (s.next <= now) {
        transport.publish(s.channel, s.bytes.data(), s.bytes.size());
        ++s.sent;
        result.bytes += s.bytes.size();
        s.next += period;
      }
      soonest = std::min(soonest, s.next);
    }
    const auto wait = soonest - Clock::now();
    if (wait > std::chrono::microseconds(100)) std::this_thread::sleep_for(wait);
  }
  result.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

/// Events per channel in the logs under `log_dir`.
std::map<std::string, std::int64_t> count_logged(const std::string& log_dir) {
  std::map<std::string, std::int64_t> logged;
  for (const std::string& file : logger::expand_log_paths({log_dir})) {
    logger::LogReader reader(file);
    logger::LogEvent event;
    while (reader.next(event)) ++logged[event.channel];
  }
  return logged;
}

/// Prints the per-channel table and the total line; whether nothing was lost.
bool print_results(const std::vector<Stream>& streams, std::map<std::string, std::int64_t>& logged,
                   const Published& published, int logger_status) {
  const double elapsed = published.elapsed_s;
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
            << published.bytes / elapsed / 1e6 << " MB/s) in " << std::setprecision(2) << elapsed
            << " s; logged " << total_logged << "; lost " << total_sent - total_logged
            << "; auv_logger exit status "
            << (WIFEXITED(logger_status) ? WEXITSTATUS(logger_status) : -1) << "\n";
  return total_sent == total_logged;
}

/// Starts auv_logger, publishes the mix, stops the logger and compares; the exit status.
int run(const Options& options) {
  const std::string dir = test_support::make_temp_dir("auvrl_bench_logger_");
  std::vector<Stream> streams = make_streams(options);
  test_support::ChildProcess logger({test_support::bin_path("auv_logger"), "--dir", dir + "/logs",
                                     "--throttle", "POLICY_WEIGHTS=0", "--heartbeat-period", "0.5"},
                                    dir + "/auv_logger.log");
  auto transport = transport::make_transport({});
  if (!wait_for_logger(*transport)) {
    std::cerr << "bench_logger_load: auv_logger did not start\n" << logger.log();
    return 1;
  }
  const Published published = publish_paced(*transport, streams, options.seconds);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int status = logger.terminate(std::chrono::seconds(20));
  auto logged = count_logged(dir + "/logs");
  const bool complete = print_results(streams, logged, published, status);
  std::cout << logger.log();
  std::filesystem::remove_all(dir);
  return complete ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  cli::CommandLine cmd("bench_logger_load", "auv_logger under a paced traffic mix.");
  cmd.option("seconds", &o.seconds, "how long to publish, s");
  cmd.option("state-rate", &o.state_rate, "vehicle_state_t and thruster_cmd_t per second (each)");
  cmd.option("batch-rate", &o.batch_rate, "experience_batch_t per second");
  cmd.option("batch-transitions", &o.batch_transitions, "transitions per batch");
  cmd.option("weights-rate", &o.weights_rate, "policy_weights_t (and summaries) per second");
  cmd.option("weights-bytes", &o.weights_bytes, "size of the network in a policy_weights_t, bytes");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "bench_logger_load: " << e.what() << "\n";
    return 2;
  }
  return run(o);
}
