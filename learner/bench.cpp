#include "learner/bench.hpp"

#include <time.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/nn/mlp.hpp"
#include "common/nn/random.hpp"

namespace auvrl::learner {
namespace {

constexpr std::size_t kReplaySize = 100000;

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Restores the thread setting on every exit path.
class ThreadScope {
 public:
  explicit ThreadScope(int n) : saved_(nn::num_threads()) { nn::set_num_threads(n); }
  ~ThreadScope() { nn::set_num_threads(saved_); }
  ThreadScope(const ThreadScope&) = delete;
  ThreadScope& operator=(const ThreadScope&) = delete;

 private:
  int saved_;
};

void fill_random(ReplayBuffer& replay, nn::Rng& rng, bool expert_labels) {
  nn::Vector s(replay.state_dim()), s1(replay.state_dim()), a(replay.action_dim()),
      expert(replay.action_dim());
  for (std::size_t i = 0; i < replay.capacity(); ++i) {
    for (Eigen::Index k = 0; k < s.size(); ++k) s[k] = nn::uniform(rng, -1.0f, 1.0f);
    for (Eigen::Index k = 0; k < s1.size(); ++k) s1[k] = nn::uniform(rng, -1.0f, 1.0f);
    for (Eigen::Index k = 0; k < a.size(); ++k) a[k] = nn::uniform(rng, -1.0f, 1.0f);
    for (Eigen::Index k = 0; k < expert.size(); ++k) expert[k] = nn::uniform(rng, -1.0f, 1.0f);
    TransitionView t{s,
                     a,
                     nn::uniform(rng, -1.0f, 0.0f),
                     s1,
                     (i % 97) == 0,
                     Eigen::Vector3f::Zero(),
                     Eigen::Vector3f::Zero(),
                     i / 700,
                     static_cast<std::uint32_t>(i % 700)};
    if (expert_labels) t.expert_action = expert.data();
    replay.add(t);
  }
}

}  // namespace

BenchResult run_update_benchmark(const BenchCase& c) {
  ThreadScope threads(c.threads);
  DdpgConfig config;
  config.algo = c.algo;
  config.state_dim = c.state_dim;
  config.action_dim = c.action_dim;
  config.actor_hidden = c.hidden;
  config.critic_hidden = c.hidden;
  config.critic_action_layer = c.algo == Algo::kTd3 ? 0 : 1;
  config.batch_size = c.batch;
  config.expert_weight = c.expert_weight;
  config.smooth_temporal_weight = c.smooth_temporal_weight;
  config.smooth_spatial_weight = c.smooth_spatial_weight;
  Ddpg learner(config);
  nn::Rng rng(12345);
  ReplayBuffer replay(c.state_dim, c.action_dim, kReplaySize);
  fill_random(replay, rng, c.expert_weight > 0.0f);

  using Clock = std::chrono::steady_clock;
  // Warm-up: caches, page faults of the workspaces, CPU frequency.
  const auto warm_end = Clock::now() + std::chrono::duration<double>(std::min(0.3, c.seconds));
  while (Clock::now() < warm_end) learner.update(replay);

  BenchResult result;
  result.config = c;
  const double cpu_start = thread_cpu_seconds();
  const auto start = Clock::now();
  const auto end = start + std::chrono::duration<double>(c.seconds);
  auto now = start;
  while (now < end) {
    learner.update(replay);
    ++result.updates;
    now = Clock::now();
  }
  result.seconds = std::chrono::duration<double>(now - start).count();
  result.cpu_seconds = thread_cpu_seconds() - cpu_start;
  result.updates_per_s = static_cast<double>(result.updates) / result.seconds;
  return result;
}

BenchResult run_update_benchmark(Algo algo, const std::vector<int>& hidden, int batch, int threads,
                                 int state_dim, int action_dim, double seconds) {
  BenchCase c;
  c.algo = algo;
  c.hidden = hidden;
  c.batch = batch;
  c.threads = threads;
  c.state_dim = state_dim;
  c.action_dim = action_dim;
  c.seconds = seconds;
  return run_update_benchmark(c);
}

std::vector<BenchCase> standard_bench_cases(Algo algo) {
  std::vector<BenchCase> cases(3);
  cases[0].hidden = {64, 64};
  cases[0].batch = 100;
  cases[1].hidden = {256, 256};
  cases[1].batch = 256;
  cases[2].hidden = {400, 300};
  cases[2].batch = 64;
  for (BenchCase& c : cases) c.algo = algo;
  return cases;
}

BenchCase fast_preset_bench_case(float expert_weight) {
  BenchCase c;
  c.algo = Algo::kTd3;
  c.hidden = {64, 64};
  c.batch = 64;
  c.state_dim = 29;
  c.expert_weight = expert_weight;
  return c;
}

std::string format_bench_line(const BenchResult& r) {
  std::ostringstream os;
  os << "algo=" << to_string(r.config.algo) << " hidden=";
  for (std::size_t i = 0; i < r.config.hidden.size(); ++i) {
    os << (i ? "-" : "") << r.config.hidden[i];
  }
  os << " batch=" << r.config.batch << " threads=" << r.config.threads
     << " updates_per_s=" << static_cast<long>(std::lround(r.updates_per_s));
  if (r.config.state_dim != 23 || r.config.action_dim != 6) {
    os << " state_dim=" << r.config.state_dim << " action_dim=" << r.config.action_dim;
  }
  if (r.config.expert_weight > 0.0f) os << " expert_weight=" << r.config.expert_weight;
  if (r.config.smooth_temporal_weight > 0.0f || r.config.smooth_spatial_weight > 0.0f) {
    os << " smooth_temporal_weight=" << r.config.smooth_temporal_weight
       << " smooth_spatial_weight=" << r.config.smooth_spatial_weight;
  }
  return os.str();
}

void print_bench_line(std::ostream& os, const BenchResult& r) {
  os << format_bench_line(r) << '\n';
}

std::vector<int> parse_hidden(const std::string& text) {
  std::vector<int> sizes;
  std::istringstream is(text);
  std::string part;
  while (std::getline(is, part, '-')) {
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != part.size() || part.empty() || v < 1) {
      throw std::invalid_argument("hidden sizes '" + text + "': expected e.g. 256-256");
    }
    sizes.push_back(v);
  }
  if (sizes.empty()) throw std::invalid_argument("hidden sizes '" + text + "' are empty");
  return sizes;
}

}  // namespace auvrl::learner
