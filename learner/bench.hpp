// Update-rate benchmark of the learner (`auv_learner --bench`): DDPG or TD3 updates per second
// on random transitions, for comparison with other implementations.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "learner/ddpg.hpp"

namespace auvrl::learner {

/// One benchmark case. The defaults are the AUV task's dimensions (the extended state layout:
/// 3 + 1 + 6 + 6 + 6 + 1 = 23 values; the paper's layout [x_pos, x_e, v, u_prev] is
/// 3 + 3 + 6 + 6 = 18).
struct BenchCase {
  Algo algo = Algo::kDdpg;
  std::vector<int> hidden{256, 256};  ///< both actor and critic
  int batch = 256;
  /// Threads for the products (nn::set_num_threads). More than one pays only on an otherwise
  /// idle machine: each product ends at a barrier, and with more runnable threads than cores a
  /// descheduled worker stalls the others for a time slice.
  int threads = 1;
  int state_dim = 23;
  int action_dim = 6;
  double seconds = 2.0;  ///< measuring time, after a short warm-up
  /// Q-filtered imitation (DdpgConfig::expert_weight): > 0 labels every transition with an
  /// expert action and adds the imitation term (and its Q filter) to each actor step.
  float expert_weight = 0.0f;
  /// Smoothness terms (DdpgConfig::smooth_temporal_weight, smooth_spatial_weight): > 0 adds the
  /// next states and perturbed states to each actor step's forward and backward pass.
  float smooth_temporal_weight = 0.0f;
  float smooth_spatial_weight = 0.0f;
};

/// What a case measured.
struct BenchResult {
  BenchCase config;
  double updates_per_s = 0;
  long updates = 0;
  double seconds = 0;      ///< wall-clock time measured
  double cpu_seconds = 0;  ///< CPU time the measuring thread got in it: well below `seconds`
                           ///< means the machine was busy and the figure is low
};

/// Runs updates (minibatch sampling included) of a Ddpg built with the case's algorithm, hidden
/// sizes (actor and critic; action at the critic's input layer for TD3, after its first hidden
/// layer for DDPG, as in their papers) and batch on a replay buffer of 100,000 random
/// transitions, using `threads` threads for the matrix products, for `seconds`. A TD3 update
/// counts as one whatever its delayed actor step does, as RLtools counts it.
BenchResult run_update_benchmark(const BenchCase& c);
BenchResult run_update_benchmark(Algo algo, const std::vector<int>& hidden, int batch, int threads,
                                 int state_dim, int action_dim, double seconds);

/// The three standard cases, one thread, AUV dims: 64-64 batch 100, 256-256 batch 256,
/// 400-300 batch 64.
std::vector<BenchCase> standard_bench_cases(Algo algo);

/// The fast preset's learner: TD3, 64-64, batch 64, the extended state with the realised thrust
/// (29 values), one thread, with the preset's imitation weight (0.4) or without it (0).
BenchCase fast_preset_bench_case(float expert_weight);

/// "algo=ddpg hidden=256-256 batch=256 threads=1 updates_per_s=N"; for dims other than the AUV
/// task's (23, 6), " state_dim=S action_dim=A" is appended so the line cannot be mistaken,
/// " expert_weight=W" with imitation and " smooth_temporal_weight=T smooth_spatial_weight=S"
/// with the smoothness terms.
std::string format_bench_line(const BenchResult& r);
/// Writes format_bench_line(r) and a newline.
void print_bench_line(std::ostream& os, const BenchResult& r);

/// Parses "256-256" into {256, 256}; throws std::invalid_argument if malformed.
std::vector<int> parse_hidden(const std::string& text);

}  // namespace auvrl::learner
