#include "sim/model_variation.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace auvrl::sim {

namespace {

void require_scale(double value, const char* field) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw std::invalid_argument(
        fmt::format("model variation: {} = {}: expected a finite number > 0", field, value));
  }
}

}  // namespace

bool ModelVariation::is_identity() const {
  return quadratic_damping_scale == 1.0 && added_mass_scale == 1.0 && mass_scale == 1.0 &&
         thruster_lag_time_constant_s < 0 && extra_buoyancy_n == 0.0;
}

bool ModelVariation::operator==(const ModelVariation& o) const {
  return quadratic_damping_scale == o.quadratic_damping_scale &&
         added_mass_scale == o.added_mass_scale && mass_scale == o.mass_scale &&
         thruster_lag_time_constant_s == o.thruster_lag_time_constant_s &&
         extra_buoyancy_n == o.extra_buoyancy_n;
}

VehicleModel vary_model(const VehicleModel& nominal, const ModelVariation& v) {
  require_scale(v.quadratic_damping_scale, "quadratic_damping_scale");
  require_scale(v.added_mass_scale, "added_mass_scale");
  require_scale(v.mass_scale, "mass_scale");
  if (!std::isfinite(v.thruster_lag_time_constant_s)) {
    throw std::invalid_argument("model variation: thruster_lag_time_constant_s is not finite");
  }
  if (!std::isfinite(v.extra_buoyancy_n)) {
    throw std::invalid_argument("model variation: extra_buoyancy_n is not finite");
  }
  VehicleModel model = nominal;
  model.quadratic_damping *= v.quadratic_damping_scale;
  model.added_mass_derivatives *= v.added_mass_scale;
  const double extra_weight_n = nominal.weight_n * (v.mass_scale - 1.0);
  model.mass_kg *= v.mass_scale;
  model.inertia_kg_m2 *= v.mass_scale;
  model.weight_n += extra_weight_n;
  model.buoyancy_n += extra_weight_n + v.extra_buoyancy_n;
  if (v.thruster_lag_time_constant_s >= 0) {
    model.thruster_dynamics.lag_enabled = v.thruster_lag_time_constant_s > 0;
    if (v.thruster_lag_time_constant_s > 0) {
      model.thruster_dynamics.lag_time_constant_s = v.thruster_lag_time_constant_s;
    }
  }
  try {
    finalize_vehicle_model(model);
  } catch (const VehicleFileError& e) {
    // Scales within range can still make a model unusable (a mass of 1e-300 kg weighs 0 N).
    throw std::invalid_argument(
        fmt::format("model variation: the varied model is not usable: {}", e.what()));
  }
  return model;
}

}  // namespace auvrl::sim
