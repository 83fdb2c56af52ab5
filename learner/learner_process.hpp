// auv_learner's process logic, callable from tests: completing the configuration from the
// command line's extras (and refusing bad combinations), the `--bench` mode and the learner's
// lifecycle (poll until stopped or done, then finish).
#pragma once

#include <ostream>
#include <string>

#include "common/transport.hpp"
#include "learner/learner_node.hpp"

namespace auvrl::learner {

/// auv_learner's options that are not keys of LearnerNodeConfig.
struct LearnerProcessOptions {
  std::string hidden;          ///< hidden sizes of both networks, e.g. "400-300" ("": keep)
  int threads = 1;             ///< threads for the matrix products
  bool bench = false;          ///< print update rates and exit
  bool resume = false;         ///< continue from the newest usable checkpoint
  bool keep_running = false;   ///< keep serving after training is done
  double bench_seconds = 2.0;  ///< measuring time per benchmark case
  /// The bench measures only the case --hidden/--batch-size give (see names_one_bench_case).
  bool bench_one_case = false;
};

/// Applies options.hidden to both networks of `config`. Throws cli::UsageError for --resume
/// without a checkpoint directory, std::invalid_argument for malformed hidden sizes.
void finish_learner_config(const LearnerProcessOptions& options, LearnerNodeConfig& config);

/// Whether the command line names --hidden or --batch-size: `--bench` then measures that one
/// case instead of the standard ones.
bool names_one_bench_case(int argc, const char* const* argv);

/// `--bench`: sets the threads and prints one line of update rates per case on `out` (the
/// standard cases of config's algorithm, or the one case the options give). Returns 0.
int run_learner_bench(const LearnerNodeConfig& config, const LearnerProcessOptions& options,
                      std::ostream& out);

/// The learner's lifecycle: threads, transport, stop handlers, the node (resumed if asked), a
/// start line, polling until a stop signal (or training done, unless keep_running), finish().
/// Throws on transport, checkpoint or node errors.
void run_learner_process(const LearnerNodeConfig& config, const LearnerProcessOptions& options,
                         const transport::TransportConfig& transport_config, std::ostream& log);

}  // namespace auvrl::learner
