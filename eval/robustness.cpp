#include "eval/robustness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <ostream>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "common/csv.hpp"
#include "common/parallel.hpp"
#include "common/random.hpp"

namespace auvrl::eval {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGravityMps2 = 9.81;  ///< converts the 2 kg of extra buoyancy to N
constexpr int kCsvDigits = 9;          ///< as summary.csv

// The draws of the groups (the file comment of robustness.hpp documents them).
constexpr double kAnyStartAttitudeRad = 0.1;  ///< roll and pitch in +-this
constexpr double kAnyStartVelocityMps = 0.3;  ///< u, v, w in +-this
constexpr double kAnyStartRateRadS = 0.1;     ///< p, q, r in +-this

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

std::uint64_t fnv1a64(const std::string& text) {
  std::uint64_t h = 0xCBF29CE484222325ULL;
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001B3ULL;
  }
  return h;
}

/// Uniform in [lo, hi).
double uniform(draw::Engine& rng, double lo, double hi) { return lo + draw::unit(rng) * (hi - lo); }

RobustnessGroup group(std::string name, std::string description, GroupDraw draw = {}) {
  return {std::move(name), std::move(description), draw};
}

RobustnessGroup model_group(std::string name, std::string description,
                            const sim::ModelVariation& variation) {
  GroupDraw d;
  d.model_variation = variation;
  return group(std::move(name), std::move(description), d);
}

/// Distance from the start to the farthest corner of the training region's box, m.
double farthest_region_corner_m(const task::TaskConfig& task) {
  double farthest = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) {
      p[k] = (corner >> k) & 1 ? task.goal_max_ned_m[k] : task.goal_min_ned_m[k];
    }
    farthest = std::max(farthest, (p - task.start_position_ned_m).norm());
  }
  return farthest;
}

/// The start pose and motion of an episode (yaw already drawn).
void draw_start(const task::TaskConfig& task, StartDraw kind, double yaw_rad, draw::Engine& rng,
                agent::EpisodeStart& start) {
  start.position_ned_m = task.start_position_ned_m;
  start.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, yaw_rad);
  if (kind != StartDraw::kAnywhere) return;
  for (int k = 0; k < 3; ++k) {
    start.position_ned_m[k] = uniform(rng, task.goal_min_ned_m[k], task.goal_max_ned_m[k]);
  }
  for (int k = 0; k < 2; ++k) {
    start.euler_rpy_rad[k] = uniform(rng, -kAnyStartAttitudeRad, kAnyStartAttitudeRad);
  }
  for (int k = 0; k < 3; ++k) {
    start.velocity_body_mps[k] = uniform(rng, -kAnyStartVelocityMps, kAnyStartVelocityMps);
  }
  for (int k = 0; k < 3; ++k) {
    start.angular_rate_body_rad_s[k] = uniform(rng, -kAnyStartRateRadS, kAnyStartRateRadS);
  }
}

/// The way-point of an episode.
void draw_goal(const task::TaskConfig& task, GoalDraw kind, draw::Engine& rng,
               EvaluationEpisode& e) {
  const Eigen::Vector3d& from = e.start.position_ned_m;
  if (kind == GoalDraw::kRegion) {
    // A few redraws at most: a box of any use has room beyond 1 m of the start.
    for (int attempt = 0; attempt < 100; ++attempt) {
      e.goal_ned_m = task::sample_goal(task, rng);
      if ((e.goal_ned_m - from).norm() >= kRobustnessMinGoalDistanceM) break;
    }
    return;
  }
  const double near_m = farthest_region_corner_m(task);
  const double distance_m = uniform(rng, near_m, kRobustnessFarMaxM);
  const double depth_m = uniform(rng, task.goal_min_ned_m[2], task.goal_max_ned_m[2]);
  const double bearing_rad = uniform(rng, -kPi, kPi);
  const double dz = depth_m - from[2];
  // The farthest corner lies at the region's depth limits, so distance_m > |dz|.
  const double horizontal_m = std::sqrt(distance_m * distance_m - dz * dz);
  e.goal_ned_m = from + Eigen::Vector3d(horizontal_m * std::cos(bearing_rad),
                                        horizontal_m * std::sin(bearing_rad), dz);
}

/// What the episode changes besides start and way-point.
void draw_conditions(const GroupDraw& d, int num_thrusters, draw::Engine& rng,
                     agent::EpisodeStart& start) {
  if (d.thruster >= 0 || d.all_thrusters_efficiency != 1.0) {
    start.thruster_efficiency.assign(static_cast<std::size_t>(num_thrusters),
                                     d.all_thrusters_efficiency);
    if (d.thruster >= 0) {
      start.thruster_efficiency[static_cast<std::size_t>(d.thruster)] = d.thruster_efficiency;
    }
  }
  if (d.current_max_mps > 0.0) {
    const double speed_mps = uniform(rng, d.current_min_mps, d.current_max_mps);
    const double direction_rad = uniform(rng, -kPi, kPi);
    start.current_ned_mps =
        speed_mps * Eigen::Vector3d(std::cos(direction_rad), std::sin(direction_rad), 0.0);
  }
  if (d.varying_sigma_mps > 0.0) {
    const double direction_rad = uniform(rng, -kPi, kPi);
    start.current_ned_mps =
        d.varying_mean_mps * Eigen::Vector3d(std::cos(direction_rad), std::sin(direction_rad), 0.0);
    start.current_varying_sigma_mps = d.varying_sigma_mps;
    start.current_varying_time_constant_s = d.varying_time_constant_s;
    start.current_varying_direction_rad = direction_rad;
  }
  start.sensor_noise = d.sensor_noise;
  start.model_variation = d.model_variation;
}

EvaluationEpisode draw_episode(const EvaluationConfig& config, int num_thrusters,
                               const RobustnessGroup& g, int index, std::uint64_t group_seed) {
  draw::Engine rng(splitmix64(group_seed + static_cast<std::uint64_t>(index)));
  EvaluationEpisode e;
  e.scenario = Scenario::kRobustness;
  e.group = g.name;
  e.index = index;
  const double yaw_rad = uniform(rng, -kPi, kPi);
  draw_start(config.task, g.draw.start, yaw_rad, rng, e.start);
  draw_goal(config.task, g.draw.goal, rng, e);
  if (g.draw.facing_away) {
    const Eigen::Vector3d to_goal = e.goal_ned_m - e.start.position_ned_m;
    e.start.euler_rpy_rad[2] = std::remainder(std::atan2(to_goal[1], to_goal[0]) + kPi, 2 * kPi);
  }
  if (g.draw.start == StartDraw::kAnywhere || g.draw.goal == GoalDraw::kFar) {
    e.safety_radius_m = grown_safety_radius_m(config.task, e.start.position_ned_m, e.goal_ned_m);
  }
  draw_conditions(g.draw, num_thrusters, rng, e.start);
  e.start.seed = rng();
  return e;
}

/// The first `count` episodes of group g drawn at seed (each from its own stream).
void draw_group(const EvaluationConfig& config, int num_thrusters, const RobustnessGroup& g,
                int count, std::uint64_t seed, std::vector<EvaluationEpisode>& episodes) {
  const std::uint64_t group_seed = splitmix64(seed ^ fnv1a64(g.name));
  for (int i = 0; i < count; ++i) {
    episodes.push_back(draw_episode(config, num_thrusters, g, i, group_seed));
  }
}

/// The group facing_away (robustness_groups with with_facing_away).
RobustnessGroup facing_away_group() {
  GroupDraw away;
  away.facing_away = true;
  return group("facing_away",
               "at rest at the start position, the way-point in the region straight behind (not "
               "one of the bar's groups)",
               away);
}

double mean_or_nan(double sum, int count) {
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

/// A finite number, or an empty cell.
void cell_or_empty(csv::Writer& out, double value) {
  if (std::isfinite(value)) {
    out.cell(value);
  } else {
    out.empty();
  }
}

}  // namespace

double grown_safety_radius_m(const task::TaskConfig& task, const Eigen::Vector3d& start_ned_m,
                             const Eigen::Vector3d& goal_ned_m) {
  return (goal_ned_m - start_ned_m).norm() + task.beta_max_m;
}

std::vector<RobustnessGroup> robustness_groups(int num_thrusters,
                                               const std::vector<std::string>& thruster_names,
                                               bool with_facing_away) {
  std::vector<RobustnessGroup> groups;
  groups.push_back(group("rest_start", "at rest at the start position, way-point in the region"));
  GroupDraw any;
  any.start = StartDraw::kAnywhere;
  groups.push_back(group("any_start",
                         "start anywhere in the region, roll/pitch +-0.1 rad, velocities "
                         "+-0.3 m/s, rates +-0.1 rad/s",
                         any));
  GroupDraw far;
  far.goal = GoalDraw::kFar;
  groups.push_back(
      group("far_waypoint", "way-point beyond the region's farthest corner, <= 30 m", far));
  for (int i = 0; i < num_thrusters; ++i) {
    const std::string label = static_cast<std::size_t>(i) < thruster_names.size()
                                  ? thruster_names[static_cast<std::size_t>(i)]
                                  : fmt::format("T{}", i + 1);
    for (const double efficiency : {0.1, 0.0}) {
      GroupDraw d;
      d.thruster = i;
      d.thruster_efficiency = efficiency;
      const int percent = static_cast<int>(std::lround(100 * efficiency));
      groups.push_back(group(fmt::format("t{}_{}pct", i + 1, percent),
                             fmt::format("{} at {} % efficiency", label, percent), d));
    }
  }
  GroupDraw current;
  current.current_min_mps = 0.1;
  current.current_max_mps = 0.5;
  groups.push_back(
      group("current", "constant horizontal current 0.1-0.5 m/s, any direction", current));
  GroupDraw varying;
  varying.varying_mean_mps = 0.2;
  varying.varying_sigma_mps = 0.03;
  varying.varying_time_constant_s = 30.0;
  groups.push_back(group("varying_current",
                         "0.2 m/s plus Gauss-Markov speed (30 s, sigma 0.03 m/s/sqrt(s)), any "
                         "direction",
                         varying));
  GroupDraw noisy;
  noisy.sensor_noise = {0.1, 0.02, 0.05, 0.02};
  groups.push_back(group("sensor_noise",
                         "noise: position 0.1 m, attitude 0.02 rad, velocity 0.05 m/s, rates "
                         "0.02 rad/s",
                         noisy));
  sim::ModelVariation v;
  v.quadratic_damping_scale = 0.6;
  groups.push_back(model_group("drag_x0.6", "quadratic drag x0.6", v));
  v.quadratic_damping_scale = 1.5;
  groups.push_back(model_group("drag_x1.5", "quadratic drag x1.5", v));
  v = {};
  v.added_mass_scale = 1.5;
  groups.push_back(model_group("added_mass_x1.5", "added mass x1.5", v));
  v = {};
  v.mass_scale = 1.2;
  groups.push_back(model_group("mass_x1.2", "mass and inertia x1.2", v));
  GroupDraw weak;
  weak.all_thrusters_efficiency = 0.7;
  groups.push_back(group("thrust_x0.7", "every thruster at 70 % efficiency", weak));
  v = {};
  v.thruster_lag_time_constant_s = 0.6;
  groups.push_back(model_group("lag_0.6s", "thruster lag time constant 0.6 s", v));
  v = {};
  v.extra_buoyancy_n = 2.0 * kGravityMps2;
  groups.push_back(model_group("buoyancy_+2kg", "2 kg of extra buoyancy (19.62 N)", v));
  if (with_facing_away) groups.push_back(facing_away_group());
  return groups;
}

std::vector<EvaluationEpisode> robustness_episodes(const EvaluationConfig& config,
                                                   int num_thrusters, int episodes_per_group,
                                                   std::uint64_t seed) {
  if (episodes_per_group < 0) {
    throw std::invalid_argument("robustness: episodes per group must be >= 0");
  }
  if (num_thrusters < 1) throw std::invalid_argument("robustness: no thrusters");
  if (farthest_region_corner_m(config.task) >= kRobustnessFarMaxM) {
    throw std::invalid_argument(fmt::format(
        "robustness: the training region reaches {:.1f} m from the start; far way-points need "
        "it within {:g} m",
        farthest_region_corner_m(config.task), kRobustnessFarMaxM));
  }
  std::vector<EvaluationEpisode> episodes;
  for (const RobustnessGroup& g :
       robustness_groups(num_thrusters, {}, config.robustness_facing_away)) {
    draw_group(config, num_thrusters, g, episodes_per_group, seed, episodes);
  }
  return episodes;
}

bool is_held(const SummaryRow& row, double reach_radius_m) {
  const bool full_length =
      row.end_reason == task::EndReason::kReached || row.end_reason == task::EndReason::kTimeLimit;
  return row.reached && full_length && row.final_error_m <= reach_radius_m;
}

std::vector<GroupMetrics> group_metrics(const std::vector<SummaryRow>& rows,
                                        double reach_radius_m) {
  struct Sums {
    GroupMetrics m;
    double time = 0, hold = 0, energy = 0, smoothness = 0;
  };
  std::vector<std::string> order;
  std::map<std::string, Sums> by_group;
  for (const SummaryRow& r : rows) {
    if (!by_group.count(r.scenario)) order.push_back(r.scenario);
    Sums& s = by_group[r.scenario];
    s.m.group = r.scenario;
    s.m.controller = r.controller;
    ++s.m.episodes;
    if (r.reached) {
      ++s.m.reached;
      s.time += r.time_to_reach_s;
      s.hold += r.mean_error_after_reach_m;
    }
    if (is_held(r, reach_radius_m)) ++s.m.held;
    if (r.end_reason == task::EndReason::kFlipped) ++s.m.flips;
    if (r.end_reason == task::EndReason::kBlowUp) ++s.m.blow_ups;
    if (r.end_reason == task::EndReason::kLeftRegion) ++s.m.left_region;
    s.energy += r.thrust_energy;
    s.smoothness += r.smoothness;
  }
  std::vector<GroupMetrics> out;
  for (const std::string& name : order) {
    Sums& s = by_group[name];
    s.m.mean_time_s = mean_or_nan(s.time, s.m.reached);
    s.m.mean_hold_m = mean_or_nan(s.hold, s.m.reached);
    s.m.mean_energy = s.energy / s.m.episodes;
    s.m.mean_smoothness = s.smoothness / s.m.episodes;
    out.push_back(s.m);
  }
  return out;
}

std::vector<GroupComparison> compare_robustness(const std::vector<GroupMetrics>& policy,
                                                const std::vector<GroupMetrics>& reference,
                                                const RobustnessBar& bar) {
  std::vector<GroupComparison> out;
  for (const GroupMetrics& p : policy) {
    const GroupMetrics* ref = nullptr;
    for (const GroupMetrics& r : reference) {
      if (r.group == p.group) ref = &r;
    }
    if (!ref) {
      throw std::invalid_argument("robustness comparison: the reference has no group '" + p.group +
                                  "'");
    }
    GroupComparison c{p, *ref};
    const double held_rate = p.episodes > 0 ? static_cast<double>(p.held) / p.episodes : 0.0;
    const double ref_rate =
        ref->episodes > 0 ? static_cast<double>(ref->held) / ref->episodes : 0.0;
    c.held = held_rate >= ref_rate;
    c.no_flip = p.flips == 0;
    // A mean over reached episodes: none reached passes only where the reference reached none.
    const auto no_worse = [](double mine, double theirs, double margin) {
      if (std::isnan(mine)) return std::isnan(theirs);
      return std::isnan(theirs) || mine <= theirs + margin;
    };
    c.time = no_worse(p.mean_time_s, ref->mean_time_s, 1e-9);
    c.hold = no_worse(p.mean_hold_m, ref->mean_hold_m, bar.hold_margin_m);
    c.energy = p.mean_energy <= ref->mean_energy;
    c.smoothness = p.mean_smoothness <= bar.smoothness_ratio * ref->mean_smoothness;
    out.push_back(c);
  }
  return out;
}

std::string robustness_comparison_markdown(const std::vector<GroupComparison>& comparisons,
                                           const RobustnessBar& bar) {
  const auto mark = [](bool pass) { return pass ? "pass" : "**FAIL**"; };
  const auto num = [](double v, int digits) {
    return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : std::string("-");
  };
  std::string out = fmt::format(
      "| group | held (policy vs PID) | flips | time to reach [s] | thrust energy | hold error "
      "[m] (+{:g}) | smoothness (x{:g}) | all |\n|---|---|---|---|---|---|---|---|\n",
      bar.hold_margin_m, bar.smoothness_ratio);
  int passing = 0;
  for (const GroupComparison& c : comparisons) {
    const GroupMetrics& p = c.policy;
    const GroupMetrics& r = c.reference;
    passing += c.passes() ? 1 : 0;
    out += fmt::format("| {} | {}/{} vs {}/{} {} | {} vs {} {} | {} vs {} {} | {} vs {} {} | ",
                       p.group, p.held, p.episodes, r.held, r.episodes, mark(c.held), p.flips,
                       r.flips, mark(c.no_flip), num(p.mean_time_s, 1), num(r.mean_time_s, 1),
                       mark(c.time), num(p.mean_energy, 1), num(r.mean_energy, 1), mark(c.energy));
    out += fmt::format("{} vs {} {} | {} vs {} {} | {} |\n", num(p.mean_hold_m, 3),
                       num(r.mean_hold_m, 3), mark(c.hold), num(p.mean_smoothness, 3),
                       num(r.mean_smoothness, 3), mark(c.smoothness), mark(c.passes()));
  }
  out += fmt::format(
      "\n{} of {} groups pass every criterion. Each cell: policy vs PID. Held: reached and "
      "within 0.5 m at 70 s; time and hold error: means over the reached episodes; energy and "
      "smoothness: means over all.\n",
      passing, comparisons.size());
  return out;
}

PairedDifference bootstrap_mean(const std::vector<double>& differences, std::uint64_t seed,
                                int resamples) {
  if (resamples < 100) {
    throw std::invalid_argument("bootstrap_mean: at least 100 resamples, got " +
                                std::to_string(resamples));
  }
  PairedDifference out;
  out.pairs = static_cast<int>(differences.size());
  if (differences.empty()) return out;
  double sum = 0.0;
  for (double d : differences) {
    if (!std::isfinite(d)) throw std::invalid_argument("bootstrap_mean: a non-finite difference");
    sum += d;
  }
  const std::size_t n = differences.size();
  out.mean = sum / static_cast<double>(n);
  draw::Engine rng(seed);
  std::vector<double> means(static_cast<std::size_t>(resamples));
  for (double& m : means) {
    double s = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = std::min(n - 1, static_cast<std::size_t>(draw::unit(rng) * n));
      s += differences[k];
    }
    m = s / static_cast<double>(n);
  }
  std::sort(means.begin(), means.end());
  // Nearest-rank percentiles; the interval always holds the mean (it may not, by rounding, when
  // every difference is the same).
  const auto rank = [&](double q) {
    return means[std::min(means.size() - 1, static_cast<std::size_t>(q * means.size()))];
  };
  out.low = std::min(out.mean, rank(0.025));
  out.high = std::max(out.mean, rank(0.975));
  return out;
}

std::vector<GroupMargins> paired_margins(const std::vector<SummaryRow>& policy,
                                         const std::vector<SummaryRow>& reference,
                                         std::uint64_t seed, double reach_radius_m,
                                         const RobustnessBar& bar) {
  std::map<std::pair<std::string, int>, const SummaryRow*> by_episode;
  for (const SummaryRow& r : reference) by_episode[{r.scenario, r.episode}] = &r;
  struct Differences {
    int held_policy_only = 0;
    int held_reference_only = 0;
    std::vector<double> time_s, energy, hold_m, smoothness;
  };
  std::vector<std::string> order;
  std::map<std::string, Differences> groups;
  for (const SummaryRow& p : policy) {
    const auto found = by_episode.find({p.scenario, p.episode});
    if (found == by_episode.end()) {
      throw std::invalid_argument("paired_margins: group " + p.scenario + " episode " +
                                  std::to_string(p.episode) + " has no reference row");
    }
    const SummaryRow& r = *found->second;
    const auto [slot, first] = groups.try_emplace(p.scenario);
    if (first) order.push_back(p.scenario);
    Differences& d = slot->second;
    const bool policy_held = is_held(p, reach_radius_m);
    const bool reference_held = is_held(r, reach_radius_m);
    d.held_policy_only += policy_held && !reference_held ? 1 : 0;
    d.held_reference_only += reference_held && !policy_held ? 1 : 0;
    if (p.reached && r.reached) {
      d.time_s.push_back(p.time_to_reach_s - r.time_to_reach_s);
      d.hold_m.push_back(p.mean_error_after_reach_m - r.mean_error_after_reach_m -
                         bar.hold_margin_m);
    }
    d.energy.push_back(p.thrust_energy - r.thrust_energy);
    d.smoothness.push_back(p.smoothness - bar.smoothness_ratio * r.smoothness);
  }
  std::vector<GroupMargins> out;
  for (const std::string& name : order) {
    const Differences& d = groups.at(name);
    // Each criterion its own stream, so that one criterion's pairs move no other's interval.
    out.push_back({name, d.held_policy_only, d.held_reference_only, bootstrap_mean(d.time_s, seed),
                   bootstrap_mean(d.energy, seed + 1), bootstrap_mean(d.hold_m, seed + 2),
                   bootstrap_mean(d.smoothness, seed + 3)});
  }
  return out;
}

std::string robustness_margins_markdown(const std::vector<GroupMargins>& margins,
                                        const RobustnessBar& bar) {
  const auto cell = [](const PairedDifference& d, int digits) {
    if (d.pairs == 0) return std::string("-");
    const std::string text =
        fmt::format("{:+.{}f} [{:+.{}f}, {:+.{}f}]", d.mean, digits, d.low, digits, d.high, digits);
    // Bold: the whole interval on the wrong side of the threshold.
    return d.low > 0 ? "**" + text + "**" : text;
  };
  std::string out = fmt::format(
      "| group | held by one only: policy / PID | time to reach [s] | thrust energy | hold error "
      "[m] (+{:g}) | smoothness (x{:g}) |\n|---|---|---|---|---|---|\n",
      bar.hold_margin_m, bar.smoothness_ratio);
  for (const GroupMargins& m : margins) {
    out += fmt::format("| {} | {} / {} | {} | {} | {} | {} |\n", m.group, m.held_policy_only,
                       m.held_reference_only, cell(m.time_s, 2), cell(m.energy, 1),
                       cell(m.hold_m, 3), cell(m.smoothness, 4));
  }
  out += fmt::format(
      "\nHow sure each criterion is. Held by one only: the episodes that one controller held and "
      "the other did not. Then, episode by episode of the same draw, the policy minus the "
      "bar's threshold (time and energy: the PID's; hold error: the PID's plus {:g} m, episodes "
      "both reached; smoothness: {:g} times the PID's), the group's mean and its 95 % bootstrap "
      "interval. Negative is on the bar's side; bold, the whole interval on the other; an "
      "interval that spans 0 means the group's episodes do not settle that criterion.\n",
      bar.hold_margin_m, bar.smoothness_ratio);
  return out;
}

std::vector<EvaluationEpisode> facing_away_episodes(const EvaluationConfig& config,
                                                    int num_thrusters, int count,
                                                    std::uint64_t seed) {
  if (count < 0) throw std::invalid_argument("facing_away_episodes: count must be >= 0");
  std::vector<EvaluationEpisode> episodes;
  draw_group(config, num_thrusters, facing_away_group(), count, seed, episodes);
  return episodes;
}

namespace {

/// The config as the drawn episodes run it (the model's thrusters, config.episode_steps);
/// throws std::invalid_argument for a task that does not validate or a reach radius not > 0.
EvaluationConfig drawn_episodes_config(const sim::VehicleModel& model, EvaluationConfig config) {
  task::apply_vehicle(model.facts(), config.task);
  config.task.max_steps = config.episode_steps;  // checked here; each episode applies it
  config.task.validate();
  if (!(config.reach_radius_m > 0)) {
    throw std::invalid_argument("robustness: reach radius must be > 0");
  }
  return config;
}

/// Runs the suite's episodes with run_rows, then its groups and (out_dir) its files.
RobustnessResult run_robustness_with(
    const sim::VehicleModel& model, const EvaluationConfig& config, int episodes_per_group,
    std::uint64_t seed, const std::string& out_dir,
    const std::function<std::vector<SummaryRow>(const std::vector<EvaluationEpisode>&)>& run_rows) {
  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) throw std::runtime_error(out_dir + ": cannot create directory: " + ec.message());
  }
  RobustnessResult result;
  result.episodes = robustness_episodes(config, model.num_thrusters(), episodes_per_group, seed);
  const auto started = std::chrono::steady_clock::now();
  result.rows = run_rows(result.episodes);
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  result.groups = group_metrics(result.rows, config.reach_radius_m);
  if (!out_dir.empty()) {
    const std::filesystem::path dir(out_dir);
    write_robustness_episodes_csv((dir / "robustness_episodes.csv").string(), result.episodes,
                                  result.rows, model.num_thrusters());
    write_robustness_csv((dir / "robustness.csv").string(), result.groups,
                         robustness_groups(model.num_thrusters(), model.facts().thruster_names,
                                           config.robustness_facing_away));
    write_vehicle_csv((dir / "vehicle.csv").string(), model.facts());
  }
  return result;
}

}  // namespace

std::vector<SummaryRow> run_drawn_episodes(const sim::VehicleModel& model, EvaluationConfig config,
                                           agent::Controller& controller,
                                           const std::vector<EvaluationEpisode>& episodes) {
  config = drawn_episodes_config(model, std::move(config));
  std::vector<SummaryRow> rows;
  for (const EvaluationEpisode& episode : episodes) {
    rows.push_back(run_evaluation_episode(model, config, controller, episode, nullptr));
  }
  return rows;
}

std::vector<SummaryRow> run_drawn_episodes(const sim::VehicleModel& model, EvaluationConfig config,
                                           const ControllerFactory& make_controller,
                                           const std::vector<EvaluationEpisode>& episodes,
                                           int threads) {
  config = drawn_episodes_config(model, std::move(config));
  const int used = std::max(1, std::min<int>(threads, static_cast<int>(episodes.size())));
  std::vector<std::unique_ptr<agent::Controller>> controllers;
  for (int w = 0; w < used; ++w) controllers.push_back(make_controller());
  std::vector<SummaryRow> rows(episodes.size());
  for_each_index(used, episodes.size(), [&](int w, std::size_t i) {
    rows[i] = run_evaluation_episode(model, config, *controllers[static_cast<std::size_t>(w)],
                                     episodes[i], nullptr);
  });
  return rows;
}

RobustnessResult run_robustness(const sim::VehicleModel& model, EvaluationConfig config,
                                agent::Controller& controller, int episodes_per_group,
                                std::uint64_t seed, const std::string& out_dir) {
  return run_robustness_with(model, config, episodes_per_group, seed, out_dir,
                             [&](const std::vector<EvaluationEpisode>& episodes) {
                               return run_drawn_episodes(model, config, controller, episodes);
                             });
}

RobustnessResult run_robustness(const sim::VehicleModel& model, EvaluationConfig config,
                                const ControllerFactory& make_controller, int threads,
                                int episodes_per_group, std::uint64_t seed,
                                const std::string& out_dir) {
  return run_robustness_with(model, config, episodes_per_group, seed, out_dir,
                             [&](const std::vector<EvaluationEpisode>& episodes) {
                               return run_drawn_episodes(model, config, make_controller, episodes,
                                                         threads);
                             });
}

namespace {

std::vector<std::string> episode_columns(int num_thrusters) {
  std::vector<std::string> c{"group",   "controller", "episode",     "start_x",        "start_y",
                             "start_z", "start_roll", "start_pitch", "start_yaw",      "start_u",
                             "start_v", "start_w",    "start_p",     "start_q",        "start_r",
                             "goal_x",  "goal_y",     "goal_z",      "goal_distance_m"};
  for (int i = 1; i <= num_thrusters; ++i) c.push_back(fmt::format("efficiency_{}", i));
  for (const char* name : {"current_n_mps",
                           "current_e_mps",
                           "current_varying_sigma_mps",
                           "current_varying_time_constant_s",
                           "current_varying_direction_rad",
                           "noise_position_m",
                           "noise_attitude_rad",
                           "noise_velocity_mps",
                           "noise_rate_rad_s",
                           "drag_scale",
                           "added_mass_scale",
                           "mass_scale",
                           "lag_time_constant_s",
                           "extra_buoyancy_n",
                           "safety_radius_m",
                           "reset_seed",
                           "reached",
                           "held",
                           "end_reason",
                           "time_to_reach_s",
                           "mean_error_after_reach_m",
                           "final_error_m",
                           "thrust_energy",
                           "smoothness"}) {
    c.push_back(name);
  }
  return c;
}

/// The draw of one episode: start, way-point, faults, current, noise, model, seed.
void write_draw(csv::Writer& out, const EvaluationEpisode& e, int num_thrusters) {
  const agent::EpisodeStart& s = e.start;
  for (const Eigen::Vector3d* v : {&s.position_ned_m, &s.euler_rpy_rad, &s.velocity_body_mps,
                                   &s.angular_rate_body_rad_s, &e.goal_ned_m}) {
    out.cell((*v)[0]).cell((*v)[1]).cell((*v)[2]);
  }
  out.cell((e.goal_ned_m - s.position_ned_m).norm());
  for (int i = 0; i < num_thrusters; ++i) {
    const auto k = static_cast<std::size_t>(i);
    out.cell(k < s.thruster_efficiency.size() ? s.thruster_efficiency[k] : 1.0);
  }
  out.cell(s.current_ned_mps[0]).cell(s.current_ned_mps[1]);
  out.cell(s.current_varying_sigma_mps);
  out.cell(s.current_varying_time_constant_s).cell(s.current_varying_direction_rad);
  out.cell(s.sensor_noise.position_sigma_m).cell(s.sensor_noise.attitude_sigma_rad);
  out.cell(s.sensor_noise.linear_velocity_sigma_mps);
  out.cell(s.sensor_noise.angular_velocity_sigma_rad_s);
  const sim::ModelVariation& m = s.model_variation;
  out.cell(m.quadratic_damping_scale).cell(m.added_mass_scale).cell(m.mass_scale);
  if (m.thruster_lag_time_constant_s >= 0) {
    out.cell(m.thruster_lag_time_constant_s);
  } else {
    out.empty();  // the file's
  }
  out.cell(m.extra_buoyancy_n);
  if (e.safety_radius_m > 0) {
    out.cell(e.safety_radius_m);
  } else {
    out.empty();  // the task's
  }
  out.cell(s.seed);
}

}  // namespace

void write_robustness_episodes_csv(const std::string& path,
                                   const std::vector<EvaluationEpisode>& episodes,
                                   const std::vector<SummaryRow>& rows, int num_thrusters) {
  if (episodes.size() != rows.size()) {
    throw std::invalid_argument(path + ": " + std::to_string(rows.size()) + " rows for " +
                                std::to_string(episodes.size()) + " episodes");
  }
  csv::Writer out(path, episode_columns(num_thrusters), csv::Mode::kTruncate, kCsvDigits);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const SummaryRow& r = rows[i];
    out.cell(r.scenario).cell(r.controller).cell(r.episode);
    write_draw(out, episodes[i], num_thrusters);
    out.cell(r.reached).cell(is_held(r)).cell(end_reason_name(r.end_reason));
    if (r.reached) {
      out.cell(r.time_to_reach_s).cell(r.mean_error_after_reach_m);
    } else {
      out.empty().empty();  // never reached, as in summary.csv
    }
    out.cell(r.final_error_m).cell(r.thrust_energy).cell(r.smoothness);
    out.end_row();
  }
  out.flush();
}

void write_robustness_csv(const std::string& path, const std::vector<GroupMetrics>& groups,
                          const std::vector<RobustnessGroup>& definitions) {
  csv::Writer out(path,
                  {"group", "controller", "episodes", "reached", "held", "flips", "blow_ups",
                   "left_region", "mean_time_to_reach_s", "mean_hold_error_m", "mean_thrust_energy",
                   "mean_smoothness", "description"},
                  csv::Mode::kTruncate, kCsvDigits);
  for (const GroupMetrics& g : groups) {
    out.cell(g.group).cell(g.controller).cell(g.episodes).cell(g.reached).cell(g.held);
    out.cell(g.flips).cell(g.blow_ups).cell(g.left_region);
    cell_or_empty(out, g.mean_time_s);
    cell_or_empty(out, g.mean_hold_m);
    out.cell(g.mean_energy).cell(g.mean_smoothness);
    std::string description;
    for (const RobustnessGroup& d : definitions) {
      if (d.name == g.group) description = d.description;
    }
    out.cell(description);
    out.end_row();
  }
  out.flush();
}

void write_robustness_comparison_csv(const std::string& path,
                                     const std::vector<GroupComparison>& comparisons) {
  // The columns as docs/usage.md lists them.
  static const std::vector<std::string> columns = {"group",
                                                   "passes",
                                                   "held",
                                                   "no_flip",
                                                   "time",
                                                   "energy",
                                                   "hold",
                                                   "smoothness",
                                                   "episodes",
                                                   "held_policy",
                                                   "held_pid",
                                                   "flips_policy",
                                                   "flips_pid",
                                                   "time_to_reach_policy_s",
                                                   "time_to_reach_pid_s",
                                                   "thrust_energy_policy",
                                                   "thrust_energy_pid",
                                                   "hold_error_policy_m",
                                                   "hold_error_pid_m",
                                                   "smoothness_policy",
                                                   "smoothness_pid"};
  csv::Writer out(path, columns, csv::Mode::kTruncate, kCsvDigits);
  for (const GroupComparison& c : comparisons) {
    out.cell(c.policy.group).cell(c.passes()).cell(c.held).cell(c.no_flip).cell(c.time);
    out.cell(c.energy).cell(c.hold).cell(c.smoothness);
    out.cell(c.policy.episodes).cell(c.policy.held).cell(c.reference.held);
    out.cell(c.policy.flips).cell(c.reference.flips);
    cell_or_empty(out, c.policy.mean_time_s);
    cell_or_empty(out, c.reference.mean_time_s);
    out.cell(c.policy.mean_energy).cell(c.reference.mean_energy);
    cell_or_empty(out, c.policy.mean_hold_m);
    cell_or_empty(out, c.reference.mean_hold_m);
    out.cell(c.policy.mean_smoothness).cell(c.reference.mean_smoothness);
    out.end_row();
  }
  out.flush();
}

std::string write_robustness_comparison(const std::string& dir,
                                        const std::vector<GroupComparison>& comparisons,
                                        const std::vector<GroupMargins>& margins) {
  std::string table = robustness_comparison_markdown(comparisons);
  if (!margins.empty()) table += "\n" + robustness_margins_markdown(margins);
  const std::string path = (std::filesystem::path(dir) / "robustness_comparison.md").string();
  std::ofstream file(path);
  file << table;
  file.flush();
  if (!file) throw std::runtime_error(path + ": cannot write");
  write_robustness_comparison_csv(
      (std::filesystem::path(dir) / "robustness_comparison.csv").string(), comparisons);
  return table;
}

std::string format_robustness_table(const std::vector<GroupMetrics>& groups) {
  std::string out = fmt::format("{:<17}{:<11}{:>8}{:>8}{:>7}{:>9}{:>10}{:>10}{:>9}{:>8}\n", "group",
                                "controller", "reached", "held", "flips", "blow-ups", "time [s]",
                                "hold [m]", "energy", "smooth");
  const auto num = [](double v, int width, int digits) {
    return std::isfinite(v) ? fmt::format("{:>{}.{}f}", v, width, digits)
                            : fmt::format("{:>{}}", "-", width);
  };
  for (const GroupMetrics& g : groups) {
    out += fmt::format("{:<17}{:<11}{:>8}{:>8}{:>7}{:>9}", g.group, g.controller,
                       fmt::format("{}/{}", g.reached, g.episodes),
                       fmt::format("{}/{}", g.held, g.episodes), g.flips, g.blow_ups);
    out += num(g.mean_time_s, 10, 1) + num(g.mean_hold_m, 10, 3) + num(g.mean_energy, 9, 1) +
           num(g.mean_smoothness, 8, 3) + "\n";
  }
  out +=
      "held: reached and within 0.5 m at 70 s; time and hold error: means over the reached\n"
      "episodes; energy and smoothness (mean |change of the normalised command| per step and\n"
      "thruster): means over all episodes.\n";
  return out;
}

RobustnessResult run_robustness_request(const EvalRequest& request, std::ostream& out) {
  if (request.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
  if (request.vehicle_path.empty()) throw std::invalid_argument("--vehicle FILE is required");
  if (request.robustness_episodes < 1) {
    throw std::invalid_argument("--robustness-episodes must be >= 1");
  }
  if (request.robustness_with_pid && request.controller != "policy") {
    throw std::invalid_argument("--with-pid compares a policy (--policy FILE) with the PID");
  }
  const sim::VehicleModel model = sim::load_vehicle_file(request.vehicle_path);
  EvaluationConfig config;
  config.seed = request.seed;
  config.robustness_facing_away = request.robustness_facing_away;
  std::unique_ptr<agent::Controller> controller = make_eval_controller(request, model, config);
  out << "vehicle " << describe(model.facts()) << "\n";
  if (request.controller == "pid" || request.robustness_with_pid) {
    const agent::VehiclePidGains gains = agent::pid_gains_for(model);
    out << "PID gains: "
        << (gains.from_file ? gains.file : "the compiled defaults (no " + gains.file + ")") << "\n";
  }
  const auto run = [&](agent::Controller& c, const EvaluationConfig& cfg, const std::string& dir) {
    RobustnessResult r =
        run_robustness(model, cfg, c, request.robustness_episodes, request.seed, dir);
    out << format_robustness_table(r.groups)
        << fmt::format("robustness suite ({}): {} episodes of 70 s in {:.1f} s; wrote {}\n",
                       c.name(), r.rows.size(), r.elapsed_s,
                       (std::filesystem::path(dir) / "robustness.csv").string());
    return r;
  };
  RobustnessResult result = run(*controller, config, request.out_dir);
  if (request.robustness_with_pid) {
    EvalRequest pid_request = request;
    pid_request.controller = "pid";
    pid_request.policy_path.clear();
    EvaluationConfig pid_config = config;
    std::unique_ptr<agent::Controller> pid = make_eval_controller(pid_request, model, pid_config);
    const RobustnessResult reference =
        run(*pid, pid_config, (std::filesystem::path(request.out_dir) / "pid").string());
    const std::filesystem::path dir(request.out_dir);
    out << "\n"
        << write_robustness_comparison(
               request.out_dir, compare_robustness(result.groups, reference.groups),
               paired_margins(result.rows, reference.rows, request.seed, config.reach_radius_m))
        << "wrote " << (dir / "robustness_comparison.md").string() << " and "
        << (dir / "robustness_comparison.csv").string() << "\n";
  }
  return result;
}

}  // namespace auvrl::eval
