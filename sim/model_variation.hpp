// How the vehicle in the water differs from its file: "a wrong model". The robustness suite
// (eval) runs controllers on such vehicles, and training can draw one per episode, so that a
// policy does not depend on the file being exact.
#pragma once

#include "sim/vehicle_model.hpp"

namespace auvrl::sim {

/// The departures from a vehicle file; the defaults change nothing.
struct ModelVariation {
  double quadratic_damping_scale = 1.0;  ///< x every quadratic damping coefficient, > 0
  double added_mass_scale = 1.0;         ///< x every added-mass derivative, > 0
  /// x the mass and the inertia, > 0. The buoyancy changes with the weight: the heavier vehicle
  /// is ballasted to the file's trim (extra_buoyancy_n is the trim error).
  double mass_scale = 1.0;
  /// The thrusters' first-order lag time constant, s (lag on); negative: the file's.
  double thruster_lag_time_constant_s = -1.0;
  double extra_buoyancy_n = 0.0;  ///< added to the buoyancy, N (2 kg: 19.6 N)

  /// True when it changes nothing.
  bool is_identity() const;
  /// Field by field (a simulator varies its model again only when the variation changes).
  bool operator==(const ModelVariation& o) const;
  bool operator!=(const ModelVariation& o) const { return !(*this == o); }
};

/// The nominal model with the variation applied, its derived matrices recomputed (its name,
/// file and CRC stay the file's: it is the same vehicle, differently wrong). Throws
/// std::invalid_argument naming the field for a non-positive scale or a non-finite value, and
/// for a variation that leaves the model unusable (e.g. a mass scale so small the weight is 0).
VehicleModel vary_model(const VehicleModel& nominal, const ModelVariation& variation);

}  // namespace auvrl::sim
