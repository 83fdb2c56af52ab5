// What `auvrl train` hears from a training run (episode reports, learner statistics,
// simulator and logger heartbeats) as raw bytes, decoded as its subscriptions decode them and
// fed to a TrainingMonitor for a run of two actors, between restarts of its roles and
// advances of its clock. Besides crashes and undefined behaviour, a finding is a monitor that
// keeps more than the run's size allows or a figure that is not a finite number in its range.
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <cmath>

#include "common/transport.hpp"
#include "fuzz/fuzz_configs.hpp"
#include "fuzz/fuzz_util.hpp"
#include "launcher/training_monitor.hpp"
#include "tests/launcher/manual_clock.hpp"

using namespace auvrl;

namespace {

/// A control record: restart role bytes[0] as process bytes[1..2] (little-endian).
void restart(const fuzz::Record& r, launcher::TrainingMonitor& monitor) {
  fuzz::InputReader in(r.bytes.data(), r.bytes.size());
  const std::size_t roles = std::size(fuzz::kMonitorRoles);
  const char* role = fuzz::kMonitorRoles[in.u8() % roles];
  monitor.started(role, in.u16());
}

/// What the monitor keeps and says must stay within the run's size and be finite.
void check(const launcher::TrainingMonitor& monitor) {
  // Roles, former processes, simulators, discarding actors, the recent outcomes.
  using Monitor = launcher::TrainingMonitor;
  const std::size_t bound = std::size(fuzz::kMonitorRoles) + Monitor::kMaxFormerPids +
                            fuzz::kMonitorActors * 2 + Monitor::kRecentEpisodes;
  const double rate = monitor.success_rate();
  if (monitor.entries() > bound || !std::isfinite(monitor.env_steps_per_s()) ||
      monitor.env_steps_per_s() < 0 || !(rate >= 0 && rate <= 1) ||
      !std::isfinite(monitor.beta_m())) {
    __builtin_trap();
  }
  if (const auto& stats = monitor.learner_stats(); stats && !std::isfinite(stats->updates_per_s)) {
    __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  launcher::ManualClock clock;  // moves only when the input says so
  launcher::TrainingMonitor monitor(fuzz::kMonitorActors, clock);
  int pid = fuzz::kMonitorFirstPid;
  for (const char* role : fuzz::kMonitorRoles) monitor.started(role, pid++);
  for (const fuzz::Record& r : fuzz::read_records(data, size)) {
    // Selector: 0 episode, 1 learner statistics, 2 simulator heartbeat, 3 logger heartbeat,
    // 4 a role restarted, 5 the clock advanced by bytes[0] tenths of a second.
    switch ((r.selector & 0x7F) % 6) {
      case 0:
        if (auvrl_lcm::episode_report_t m; fuzz::decode_record(r, m)) monitor.take_episode(m);
        break;
      case 1:
        if (auvrl_lcm::learner_stats_t m; fuzz::decode_record(r, m)) monitor.take_learner_stats(m);
        break;
      case 2:
        if (auvrl_lcm::sim_heartbeat_t m; fuzz::decode_record(r, m)) monitor.take_sim_heartbeat(m);
        break;
      case 3:
        if (auvrl_lcm::logger_heartbeat_t m; fuzz::decode_record(r, m))
          monitor.take_logger_heartbeat(m);
        break;
      case 4:
        restart(r, monitor);
        break;
      default:
        clock.t_s += 0.1 * (r.bytes.empty() ? 1 : r.bytes[0]);
    }
    monitor.discarding_actor(30.0);
    check(monitor);
  }
  return 0;
}
