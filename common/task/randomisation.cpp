#include "common/task/randomisation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "common/random.hpp"

namespace auvrl::task {

namespace {

constexpr double kTwoPi = 6.28318530717958647692;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTiny = 1e-6;  // a scale or a time constant stays above 0

/// Collects the first problem: its key and what is wrong.
class Checker {
 public:
  bool ok() const { return key_.empty(); }
  const std::string& key() const { return key_; }
  const std::string& what() const { return what_; }

  void fail(const char* key, const std::string& what) {
    if (!ok()) return;
    key_ = key;
    what_ = what;
  }
  void probability(double p, const char* key) {
    if (!(p >= 0.0 && p <= 1.0)) fail(key, "must be in [0, 1]");
  }
  /// A finite [low, high] with low <= high, both in [min, max].
  void range(const Range& r, const char* key, double min, double max) {
    if (!r.allFinite() || r[0] > r[1]) return fail(key, "must be [low, high] with low <= high");
    if (r[0] < min || r[1] > max) {
      fail(key, "must lie in [" + show(min) + ", " + show(max) + "]");
    }
  }
  void level(double v, const char* key) {
    if (!std::isfinite(v) || v < 0.0) fail(key, "must be finite and >= 0");
  }

 private:
  static std::string show(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
  }
  std::string key_, what_;
};

double uniform(const Range& r, std::mt19937_64& rng) {
  return r[0] + draw::unit(rng) * (r[1] - r[0]);
}

}  // namespace

bool EpisodeRandomisation::any() const {
  return fault_probability > 0 || current_probability > 0 || varying_current_probability > 0 ||
         sensor_noise_probability > 0 || model_probability > 0;
}

std::string EpisodeRandomisation::check(std::string& key) const {
  Checker c;
  c.probability(fault_probability, "fault_probability");
  c.probability(current_probability, "current_probability");
  c.probability(varying_current_probability, "varying_current_probability");
  c.probability(sensor_noise_probability, "sensor_noise_probability");
  c.probability(model_probability, "model_probability");
  c.range(fault_efficiency, "fault_efficiency", 0.0, 1.0);
  c.range(current_speed_mps, "current_speed_mps", 0.0, 10.0);
  c.range(varying_current_sigma_mps, "varying_current_sigma_mps", 0.0, 10.0);
  c.range(varying_current_time_constant_s, "varying_current_time_constant_s", kTiny, kInf);
  c.range(sensor_noise_scale, "sensor_noise_scale", 0.0, kInf);
  c.level(sensor_noise_position_m, "sensor_noise_position_m");
  c.level(sensor_noise_attitude_rad, "sensor_noise_attitude_rad");
  c.level(sensor_noise_velocity_mps, "sensor_noise_velocity_mps");
  c.level(sensor_noise_angular_rate_rad_s, "sensor_noise_angular_rate_rad_s");
  c.range(quadratic_damping_scale, "quadratic_damping_scale", kTiny, 100.0);
  c.range(added_mass_scale, "added_mass_scale", kTiny, 100.0);
  c.range(mass_scale, "mass_scale", kTiny, 100.0);
  c.range(thrust_scale, "thrust_scale", kTiny, 1.0);
  c.range(thruster_lag_time_constant_s, "thruster_lag_time_constant_s", 0.0, 100.0);
  if (thruster_lag_time_constant_s[0] == 0.0 && thruster_lag_time_constant_s[1] > 0.0) {
    c.fail("thruster_lag_time_constant_s", "must be [0, 0] (the vehicle file's) or above 0");
  }
  c.range(extra_buoyancy_n, "extra_buoyancy_n", -kInf, kInf);
  key = c.key();
  return c.what();
}

void EpisodeRandomisation::validate() const {
  std::string key;
  const std::string what = check(key);
  if (!what.empty()) throw std::invalid_argument("task.randomise." + key + " " + what);
}

std::string describe(const EpisodeRandomisation& r) {
  const std::pair<const char*, double> kinds[] = {
      {"fault", r.fault_probability},
      {"current", r.current_probability},
      {"varying_current", r.varying_current_probability},
      {"sensor_noise", r.sensor_noise_probability},
      {"model", r.model_probability}};
  std::string text;
  for (const auto& [name, p] : kinds) {
    if (!(p > 0)) continue;
    char value[32];
    std::snprintf(value, sizeof value, "%g", p);
    text += (text.empty() ? "" : ", ") + std::string(name) + " " + value;
  }
  return text.empty() ? "off" : text;
}

std::string describe_kinds(unsigned kinds) {
  static const char* const kNames[] = {"fault", "current", "varying_current", "sensor_noise",
                                       "model"};
  std::string text;
  for (unsigned bit = 0; bit < 5; ++bit) {
    if ((kinds & (1u << bit)) == 0) continue;
    text += (text.empty() ? "" : "+") + std::string(kNames[bit]);
  }
  return text.empty() ? "none" : text;
}

EpisodeConditions sample_conditions(const EpisodeRandomisation& r, int num_thrusters,
                                    std::mt19937_64& rng, int fault_thruster) {
  if (fault_thruster < -1 || fault_thruster >= num_thrusters) {
    throw std::invalid_argument("sample_conditions: fault_thruster " +
                                std::to_string(fault_thruster) + " of " +
                                std::to_string(num_thrusters) + " thrusters (-1: drawn)");
  }
  EpisodeConditions c;
  // Every number is drawn, used or not: a fixed count per episode.
  const bool fault = draw::unit(rng) < r.fault_probability;
  const int drawn_thruster =
      std::min(num_thrusters - 1, static_cast<int>(draw::unit(rng) * num_thrusters));
  const int thruster = fault_thruster >= 0 ? fault_thruster : drawn_thruster;
  const double efficiency = uniform(r.fault_efficiency, rng);

  const bool current = draw::unit(rng) < r.current_probability;
  const double speed_mps = uniform(r.current_speed_mps, rng);
  const double direction_rad = kTwoPi * draw::unit(rng);

  const bool varying = draw::unit(rng) < r.varying_current_probability;
  const double sigma_mps = uniform(r.varying_current_sigma_mps, rng);
  const double time_constant_s = uniform(r.varying_current_time_constant_s, rng);
  const double varying_direction_rad = kTwoPi * draw::unit(rng);

  const bool noise = draw::unit(rng) < r.sensor_noise_probability;
  const double noise_scale = uniform(r.sensor_noise_scale, rng);

  const bool model = draw::unit(rng) < r.model_probability;
  const double damping = uniform(r.quadratic_damping_scale, rng);
  const double added_mass = uniform(r.added_mass_scale, rng);
  const double mass = uniform(r.mass_scale, rng);
  const double thrust = uniform(r.thrust_scale, rng);
  const double lag_s = uniform(r.thruster_lag_time_constant_s, rng);
  const double buoyancy_n = uniform(r.extra_buoyancy_n, rng);

  if (fault || model) c.thruster_efficiency.assign(static_cast<std::size_t>(num_thrusters), 1.0);
  if (fault) {
    c.kinds |= EpisodeConditions::kFault;
    c.fault_thruster = thruster;
    c.thruster_efficiency[static_cast<std::size_t>(thruster)] = efficiency;
  }
  if (current) {
    c.kinds |= EpisodeConditions::kCurrent;
    c.current_ned_mps = Eigen::Vector3d(speed_mps * std::cos(direction_rad),
                                        speed_mps * std::sin(direction_rad), 0.0);
  }
  if (varying) {
    c.kinds |= EpisodeConditions::kVaryingCurrent;
    c.varying_current_sigma_mps = sigma_mps;
    c.varying_current_time_constant_s = time_constant_s;
    c.varying_current_direction_rad = varying_direction_rad;
  }
  if (noise) {
    c.kinds |= EpisodeConditions::kSensorNoise;
    c.noise_position_m = noise_scale * r.sensor_noise_position_m;
    c.noise_attitude_rad = noise_scale * r.sensor_noise_attitude_rad;
    c.noise_velocity_mps = noise_scale * r.sensor_noise_velocity_mps;
    c.noise_angular_rate_rad_s = noise_scale * r.sensor_noise_angular_rate_rad_s;
  }
  if (model) {
    c.kinds |= EpisodeConditions::kModel;
    c.quadratic_damping_scale = damping;
    c.added_mass_scale = added_mass;
    c.mass_scale = mass;
    c.thrust_scale = thrust;
    for (double& e : c.thruster_efficiency) e *= thrust;
    c.thruster_lag_time_constant_s = r.thruster_lag_time_constant_s[1] > 0.0 ? lag_s : -1.0;
    c.extra_buoyancy_n = buoyancy_n;
  }
  return c;
}

}  // namespace auvrl::task
