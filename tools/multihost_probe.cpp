// A listener for scripts/multihost.sh: one runs in each network namespace of the multi-host
// test, beside the processes placed there, on the same transport. It counts what reaches its
// namespace until SIGTERM/SIGINT, then prints one line per figure (key=value, easy to grep):
//   probe=A weights received=N versions=V newest=W bytes=B
//   probe=A summaries received=N newest=W
//   probe=A commands received=N          (SIM_CMD_ on the system's bus: only an intruder's)
//   probe=A experience actor=0 batches=N transitions=T seq_gaps=G
//   probe=A episodes actor=0 count=N steps=S policy_first=P policy_last=Q
//   probe=A learner stats=N updates=U transitions_received=T buffer=B weights_published=W
//       episodes=E batches_lost=L batches_dropped=D
// Beside an actor it counts the experience that actor published (local delivery, which the
// test's loss never touches); beside the learner, the learner's own figures; elsewhere, what
// crossed the links.
//   multihost_probe --label A [transport flags] [--out FILE]
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/policy_summary_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <set>

#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"

namespace {

using namespace auvrl;

/// What one actor's experience looked like here.
struct ExperienceCount {
  std::int64_t batches = 0;
  std::int64_t transitions = 0;
  std::int64_t seq_gaps = 0;  ///< batches missing between the ones received (by batch_seq)
  std::int64_t last_seq = 0;
};

/// What one actor's episode reports looked like here.
struct EpisodeCount {
  std::int64_t count = 0;
  std::int64_t steps = 0;
  std::int64_t policy_first = -1;
  std::int64_t policy_last = -1;
};

/// Everything a probe counts.
struct Counts {
  std::int64_t weights = 0;
  std::set<std::int64_t> weight_versions;
  std::int64_t weights_bytes = 0;
  std::int64_t summaries = 0;
  std::int64_t summary_newest = -1;
  std::map<int, ExperienceCount> experience;
  std::map<int, EpisodeCount> episodes;
  std::int64_t stats_received = 0;
  std::int64_t commands = 0;  ///< thruster commands on the system's bus (an intruder's)
  std::optional<auvrl_lcm::learner_stats_t> last_stats;
};

/// Subscribes the counters to the system's channels.
void subscribe_all(transport::Transport& t, Counts& c) {
  // Large queues: the probe must not be the one that loses messages.
  constexpr int kQueue = 100000;
  transport::subscribe<auvrl_lcm::policy_weights_t>(
      t, channels::kPolicyWeights,
      [&c](const std::string&, const auvrl_lcm::policy_weights_t& w) {
        ++c.weights;
        c.weight_versions.insert(w.version);
        c.weights_bytes = w.num_bytes;
      },
      nullptr, kQueue);
  transport::subscribe<auvrl_lcm::policy_summary_t>(
      t, channels::kPolicySummary,
      [&c](const std::string&, const auvrl_lcm::policy_summary_t& s) {
        ++c.summaries;
        c.summary_newest = std::max(c.summary_newest, s.version);
      },
      nullptr, kQueue);
  transport::subscribe<auvrl_lcm::experience_batch_t>(
      t, channels::kExperience,
      [&c](const std::string&, const auvrl_lcm::experience_batch_t& b) {
        ExperienceCount& e = c.experience[b.actor_id];
        ++e.batches;
        e.transitions += b.num_transitions;
        if (b.batch_seq > e.last_seq + 1) e.seq_gaps += b.batch_seq - e.last_seq - 1;
        e.last_seq = std::max(e.last_seq, b.batch_seq);
      },
      nullptr, kQueue);
  transport::subscribe<auvrl_lcm::episode_report_t>(
      t, channels::kEpisode,
      [&c](const std::string&, const auvrl_lcm::episode_report_t& r) {
        EpisodeCount& e = c.episodes[r.actor_id];
        ++e.count;
        e.steps += r.length_steps;
        if (e.policy_first < 0) e.policy_first = r.policy_version;
        e.policy_last = r.policy_version;
      },
      nullptr, kQueue);
  transport::subscribe<auvrl_lcm::learner_stats_t>(
      t, channels::kLearnerStats,
      [&c](const std::string&, const auvrl_lcm::learner_stats_t& s) {
        ++c.stats_received;
        c.last_stats = s;
      },
      nullptr, kQueue);
  // The lockstep pairs talk on domains of their own: a command here came from elsewhere.
  t.subscribe(
      channels::kSimCommandPattern, [&c](const transport::RawMessage&) { ++c.commands; }, kQueue);
}

/// Writes the figures, one line each (see the file comment).
void report(std::ostream& out, const std::string& label, const Counts& c) {
  const std::string p = "probe=" + label + " ";
  out << p << "weights received=" << c.weights << " versions=" << c.weight_versions.size()
      << " newest=" << (c.weight_versions.empty() ? -1 : *c.weight_versions.rbegin())
      << " bytes=" << c.weights_bytes << "\n";
  out << p << "commands received=" << c.commands << "\n";
  out << p << "summaries received=" << c.summaries << " newest=" << c.summary_newest << "\n";
  for (const auto& [id, e] : c.experience) {
    out << p << "experience actor=" << id << " batches=" << e.batches
        << " transitions=" << e.transitions << " seq_gaps=" << e.seq_gaps << "\n";
  }
  for (const auto& [id, e] : c.episodes) {
    out << p << "episodes actor=" << id << " count=" << e.count << " steps=" << e.steps
        << " policy_first=" << e.policy_first << " policy_last=" << e.policy_last << "\n";
  }
  if (c.last_stats) {
    const auvrl_lcm::learner_stats_t& s = *c.last_stats;
    out << p << "learner stats=" << c.stats_received << " updates=" << s.updates
        << " transitions_received=" << s.transitions_received << " buffer=" << s.buffer_size
        << " weights_published=" << s.weights_published << " episodes=" << s.episodes
        << " batches_lost=" << s.batches_lost << " batches_dropped=" << s.batches_dropped << "\n";
  } else {
    out << p << "learner stats=0\n";
  }
  out.flush();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    cli::CommandLine cmd("multihost_probe",
                         "Counts the training system's traffic that reaches this network "
                         "namespace until SIGTERM, then prints it (scripts/multihost.sh).");
    std::string label = "probe", out_path;
    transport::TransportConfig config;
    cmd.option("label", &label, "name printed on every line (the namespace)");
    cmd.option("out", &out_path, "write the figures here instead of stdout");
    transport::add_transport_options(cmd, config);
    config.dds.role = "observer";
    if (!cmd.parse(argc, argv)) return 0;
    signals::install_stop_handlers();
    auto t = transport::make_transport(config);
    Counts counts;
    subscribe_all(*t, counts);
    std::cerr << "multihost_probe " << label << ": listening" << std::endl;
    while (!signals::stop_requested()) t->handle(100);
    if (out_path.empty()) {
      report(std::cout, label, counts);
    } else {
      std::ofstream out(out_path);
      report(out, label, counts);
    }
    return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "multihost_probe: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "multihost_probe: " << e.what() << "\n";
    return 1;
  }
}
