// Randomised training episodes (domain randomisation): per episode, an actor may give its vehicle
// a weak thruster, a water current (constant or slowly varying), sensor noise or a model that
// differs from the vehicle file, each kind with its own probability and ranges, so that one
// policy learns to cope with all of them. Training only: the evaluation never draws these.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace auvrl::task {

/// [low, high]: a value drawn uniformly between them (low == high: that value).
using Range = Eigen::Vector2d;

/// What an actor randomises in its training episodes (the `task.randomise` keys), per kind: the
/// share of episodes that get it and the ranges it is drawn from. The kinds are drawn
/// independently of each other; every probability is 0 by default (off).
struct EpisodeRandomisation {
  /// A thruster fault: one thruster, chosen uniformly, gives a share of its thrust drawn from
  /// fault_efficiency (1 healthy, 0 dead).
  double fault_probability = 0.0;
  Range fault_efficiency{0.0, 1.0};
  /// A constant horizontal water current (NED), its speed drawn from current_speed_mps, from a
  /// direction drawn uniformly.
  double current_probability = 0.0;
  Range current_speed_mps{0.1, 0.5};
  /// A slowly varying horizontal current: a first-order Gauss-Markov speed starting at 0
  /// (sim::CurrentSettings) along a heading drawn uniformly, its white-noise intensity and time
  /// constant drawn from these ranges.
  double varying_current_probability = 0.0;
  Range varying_current_sigma_mps{0.02, 0.06};
  Range varying_current_time_constant_s{30.0, 120.0};
  /// Gaussian noise on what the vehicle reports: each standard deviation is its level below
  /// times one factor per episode drawn from sensor_noise_scale.
  double sensor_noise_probability = 0.0;
  Range sensor_noise_scale{0.0, 1.0};
  double sensor_noise_position_m = 0.1;
  double sensor_noise_attitude_rad = 0.02;
  double sensor_noise_velocity_mps = 0.05;
  double sensor_noise_angular_rate_rad_s = 0.02;
  /// A wrong model (sim::ModelVariation): every one of these drawn at once. The thrust scale
  /// multiplies every thruster's efficiency (with a fault's).
  double model_probability = 0.0;
  Range quadratic_damping_scale{0.5, 1.6};
  Range added_mass_scale{0.8, 1.6};
  Range mass_scale{0.9, 1.3};
  Range thrust_scale{0.6, 1.0};
  /// The thrusters' lag time constant, s; [0, 0]: the vehicle file's (absolute values are the
  /// vehicle's own, so they are not guessed here).
  Range thruster_lag_time_constant_s{0.0, 0.0};
  Range extra_buoyancy_n{0.0, 0.0};  ///< added to the buoyancy, N (> 0: lighter)

  /// True when some probability is above 0.
  bool any() const;
  /// What is wrong with the first unusable key (its name in `key`); empty when all are usable.
  std::string check(std::string& key) const;
  /// Throws std::invalid_argument naming the first unusable key (task.randomise.<key>).
  void validate() const;
};

/// What the randomisation drew for one episode; the kinds not drawn keep these neutral values.
struct EpisodeConditions {
  /// Bits of `kinds` (episode_report_t's CONDITION_*).
  static constexpr unsigned kFault = 1;
  static constexpr unsigned kCurrent = 2;
  static constexpr unsigned kVaryingCurrent = 4;
  static constexpr unsigned kSensorNoise = 8;
  static constexpr unsigned kModel = 16;
  unsigned kinds = 0;  ///< which kinds were drawn
  /// Per thruster, in [0, 1] (fault and thrust scale together); empty: all healthy.
  std::vector<double> thruster_efficiency;
  int fault_thruster = -1;  ///< the weak thruster (from 0), -1: none
  Eigen::Vector3d current_ned_mps = Eigen::Vector3d::Zero();
  double varying_current_sigma_mps = 0.0;  ///< 0: no varying current
  double varying_current_time_constant_s = 60.0;
  double varying_current_direction_rad = 0.0;  ///< heading from north
  double noise_position_m = 0.0;
  double noise_attitude_rad = 0.0;
  double noise_velocity_mps = 0.0;
  double noise_angular_rate_rad_s = 0.0;
  double quadratic_damping_scale = 1.0;
  double added_mass_scale = 1.0;
  double mass_scale = 1.0;
  double thrust_scale = 1.0;
  double thruster_lag_time_constant_s = -1.0;  ///< < 0: the vehicle file's
  double extra_buoyancy_n = 0.0;
};

/// "fault 0.2, model 0.3" (each kind's probability, those above 0) or "off", for logs.
std::string describe(const EpisodeRandomisation& randomisation);

/// "fault+current+model" (or "none"): the kinds drawn, for logs.
std::string describe_kinds(unsigned kinds);

/// Draws one episode's conditions for a vehicle of num_thrusters. Takes the same number of draws
/// from rng whatever the probabilities and ranges, so that turning one kind on changes nothing
/// that the others draw. fault_thruster -1: a fault, if drawn, falls on a thruster drawn
/// uniformly; otherwise on that one (the draw still taken), so that a fixed set of episodes can
/// take the thrusters in turn. Throws std::invalid_argument if it is not a thruster.
EpisodeConditions sample_conditions(const EpisodeRandomisation& randomisation, int num_thrusters,
                                    std::mt19937_64& rng, int fault_thruster = -1);

}  // namespace auvrl::task
