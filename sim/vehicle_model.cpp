// Vehicle file loading (yaml-cpp) and model finalisation: derived matrices and validation.
//
// File layout (every key required, unknown keys rejected so that a typo cannot silently fall
// back to a default):
//
//   name: string
//   rigid_body:        mass_kg, inertia_kg_m2 ([Ix, Iy, Iz] or a 3x3 list of rows, about the
//                      CG), cog_body_m
//   hydrostatics:      gravity_mps2, cob_body_m, and either buoyancy_n or both
//                      displaced_volume_m3 and water_density_kg_m3 (B = rho g V)
//   hydrodynamics:     added_mass_derivatives, linear_damping, quadratic_damping (6 each, SNAME
//                      signs: <= 0), added_mass_coriolis (bool)
//   thrusters:         list of {name, position_body_m, direction_body}
//   thruster_dynamics: max_thrust_n, delay_enabled, lag_enabled, lag_time_constant_s,
//                      slew_enabled, slew_rate_n_per_s
//   integration:       control_step_s, integrator (rk4 | semi_implicit_euler), substeps
//   blow_up_limits:    max_linear_speed_mps, max_angular_rate_rad_s, max_position_m
//
// Errors found by finalize_vehicle_model name the field by the same dotted path, so a model
// built in code gets the same messages as a file.
// GCC 12 with -march=native on AVX-512 machines reports false maybe-uninitialized warnings
// inside Eigen's vectorised kernels (the eigen solver below); they are not in our code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "sim/vehicle_model.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <set>
#include <sstream>
#include <utility>

#include "common/config/table.hpp"

namespace auvrl::sim {
namespace {

/// Relative tolerance within which a thruster direction counts as a unit vector (and is then
/// normalised); anything further off is more likely a typo than rounding.
constexpr double kUnitDirectionTolerance = 0.01;
/// Relative asymmetry tolerated in the inertia and mass matrices (round-off only).
constexpr double kSymmetryTolerance = 1e-9;

std::string format_number(double value) {
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

Matrix3 skew(const Vector3& a) {
  Matrix3 s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

// ---- YAML reading: structure, types, sizes and unknown keys. --------------------------------

/// Reads one file; every error names the file, the dotted field path and the line.
class FileReader {
 public:
  explicit FileReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what,
                         const YAML::Node* node = nullptr) const {
    std::string where;
    if (node != nullptr && node->Mark().line >= 0) {
      where = " (line " + std::to_string(node->Mark().line + 1) + ")";
    }
    throw VehicleFileError(file_, field, what + where);
  }

  /// A map whose keys are all among `allowed` (presence is checked where each is read).
  void check_map(const YAML::Node& node, const std::string& field,
                 std::initializer_list<const char*> allowed) const {
    if (!node.IsMap()) fail(field, "expected a map of keys", &node);
    std::set<std::string> known(allowed.begin(), allowed.end());
    for (const auto& entry : node) {
      // A complex key ("? [a, b]: ...") is valid YAML but no name (found by fuzz_vehicle_yaml).
      if (!entry.first.IsScalar()) fail(field, "expected names as keys", &entry.first);
      const std::string key = entry.first.Scalar();
      if (known.count(key) == 0) {
        std::string list;
        for (const char* k : allowed) list += (list.empty() ? "" : ", ") + std::string(k);
        fail(join(field, key), "unknown key (expected one of: " + list + ")", &entry.first);
      }
    }
  }

  YAML::Node require(const YAML::Node& map, const std::string& field,
                     const std::string& key) const {
    YAML::Node child = map[key];
    if (!child.IsDefined() || child.IsNull()) {
      if (field.empty()) fail(key, "missing");
      fail(join(field, key), "missing from the block '" + field + "' starting at line " +
                                 std::to_string(map.Mark().line + 1));
    }
    return child;
  }

  double number(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(field, "expected a number", &node);
    double value = 0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(field, "expected a number, got '" + node.Scalar() + "'", &node);
    }
    if (!std::isfinite(value)) fail(field, "expected a finite number, got " + node.Scalar(), &node);
    return value;
  }

  double number(const YAML::Node& map, const std::string& field, const std::string& key) const {
    return number(require(map, field, key), join(field, key));
  }

  bool boolean(const YAML::Node& map, const std::string& field, const std::string& key) const {
    const YAML::Node node = require(map, field, key);
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail(join(field, key), "expected true or false, got '" + node.Scalar() + "'", &node);
    }
  }

  int integer(const YAML::Node& map, const std::string& field, const std::string& key) const {
    const YAML::Node node = require(map, field, key);
    try {
      return node.as<int>();
    } catch (const YAML::Exception&) {
      fail(join(field, key), "expected an integer, got '" + node.Scalar() + "'", &node);
    }
  }

  std::string text(const YAML::Node& map, const std::string& field, const std::string& key) const {
    const YAML::Node node = require(map, field, key);
    if (!node.IsScalar()) fail(join(field, key), "expected a string", &node);
    return node.Scalar();
  }

  /// A list of exactly n finite numbers.
  Eigen::VectorXd vector(const YAML::Node& map, const std::string& field, const std::string& key,
                         int n) const {
    const YAML::Node node = require(map, field, key);
    const std::string path = join(field, key);
    if (!node.IsSequence() || static_cast<int>(node.size()) != n) {
      fail(path,
           "expected a list of " + std::to_string(n) + " numbers" +
               (node.IsSequence() ? ", got " + std::to_string(node.size()) : std::string()),
           &node);
    }
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v(i) = number(node[i], path + "[" + std::to_string(i) + "]");
    return v;
  }

  /// [Ix, Iy, Iz] (principal axes) or three rows of three (full tensor about the CG).
  Matrix3 inertia(const YAML::Node& map, const std::string& field, const std::string& key) const {
    const YAML::Node node = require(map, field, key);
    const std::string path = join(field, key);
    const char* expected = "expected [Ix, Iy, Iz] or a 3x3 list of rows";
    if (!node.IsSequence() || node.size() != 3) fail(path, expected, &node);
    Matrix3 inertia = Matrix3::Zero();
    if (node[0].IsScalar()) {
      for (int i = 0; i < 3; ++i) {
        inertia(i, i) = number(node[i], path + "[" + std::to_string(i) + "]");
      }
      return inertia;
    }
    for (int r = 0; r < 3; ++r) {
      const YAML::Node row = node[r];
      if (!row.IsSequence() || row.size() != 3) fail(path, expected, &row);
      for (int c = 0; c < 3; ++c) {
        inertia(r, c) =
            number(row[c], path + "[" + std::to_string(r) + "][" + std::to_string(c) + "]");
      }
    }
    return inertia;
  }

  static std::string join(const std::string& field, const std::string& key) {
    return field.empty() ? key : field + "." + key;
  }

 private:
  std::string file_;
};

/// Reads a block through its table; errors keep VehicleFileError's field and line.
template <class T>
void read_block(const std::string& file, const YAML::Node& node, const std::string& key,
                const config::Table<T>& table, T& target) {
  try {
    table.read(config::Section(file, key, node), target);
  } catch (const config::ConfigError& e) {
    throw VehicleFileError(file, e.key().empty() ? key : e.key(), e.detail());
  }
}

config::Table<ThrusterDynamics> make_thruster_dynamics_table() {
  using C = ThrusterDynamics;
  config::Table<C> t("thruster_dynamics", "vehicle file: thruster response (all keys required)");
  t.field("max_thrust_n", &C::max_thrust_n, "N", "symmetric saturation per thruster").required();
  t.field("delay_enabled", &C::delay_enabled, "", "one control-step delay of the command")
      .required();
  t.field("lag_enabled", &C::lag_enabled, "", "first-order low-pass on the realised thrust")
      .required();
  t.field("lag_time_constant_s", &C::lag_time_constant_s, "s", "that low-pass's time constant")
      .required();
  t.field("slew_enabled", &C::slew_enabled, "", "rate limit on the realised thrust").required();
  t.field("slew_rate_n_per_s", &C::slew_rate_n_per_s, "N/s", "that rate limit").required();
  return t;
}

config::Table<BlowUpLimits> make_blow_up_limits_table() {
  using C = BlowUpLimits;
  config::Table<C> t("blow_up_limits",
                     "vehicle file: beyond these the state is declared blown up (all required)");
  t.field("max_linear_speed_mps", &C::max_linear_speed_mps, "m/s", "body speed").required();
  t.field("max_angular_rate_rad_s", &C::max_angular_rate_rad_s, "rad/s", "body rate").required();
  t.field("max_position_m", &C::max_position_m, "m", "distance from the origin").required();
  return t;
}

// ---- Model-level validation (shared by files and models built in code). ---------------------

class ModelChecker {
 public:
  explicit ModelChecker(const VehicleModel& model) : file_(model.source_file) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw VehicleFileError(file_.empty() ? std::string("(vehicle model)") : file_, field, what);
  }
  void finite(double value, const std::string& field) const {
    if (!std::isfinite(value)) fail(field, "expected a finite number, got " + format_number(value));
  }
  void positive(double value, const std::string& field) const {
    finite(value, field);
    if (!(value > 0)) fail(field, "expected a positive number, got " + format_number(value));
  }
  template <typename Derived>
  void finite(const Eigen::MatrixBase<Derived>& m, const std::string& field) const {
    if (!m.allFinite()) fail(field, "expected finite numbers");
  }
  /// SNAME hydrodynamic derivatives oppose motion: each must be <= 0.
  void non_positive(const Vector6& v, const std::string& field) const {
    finite(v, field);
    for (int i = 0; i < 6; ++i) {
      if (v(i) > 0) {
        fail(
            field + "[" + std::to_string(i) + "]",
            "expected <= 0 (SNAME sign: the force opposes the motion), got " + format_number(v(i)));
      }
    }
  }

 private:
  std::string file_;
};

}  // namespace

int allocation_rank(const AllocationMatrix& allocation) {
  // Fixed sizes only (no heap, no dynamic GEMM kernels): zero columns pad B to 6 x kMax without
  // changing its singular values, which are the square roots of the eigenvalues of B B^T.
  Eigen::Matrix<double, 6, kMaxThrusters> padded = Eigen::Matrix<double, 6, kMaxThrusters>::Zero();
  padded.leftCols(allocation.cols()) = allocation;
  const Matrix6 gram = padded * padded.transpose();
  const Eigen::SelfAdjointEigenSolver<Matrix6> eigen(gram, Eigen::EigenvaluesOnly);
  int rank = 0;
  for (int i = 0; i < 6; ++i) {
    if (std::sqrt(std::max(eigen.eigenvalues()(i), 0.0)) >= kAllocationMinSingularValue) ++rank;
  }
  return rank;
}

void finalize_vehicle_model(VehicleModel& model) {
  const ModelChecker check(model);

  // Rigid body and hydrostatics.
  check.positive(model.mass_kg, "rigid_body.mass_kg");
  check.positive(model.weight_n, "weight_n (rigid_body.mass_kg * hydrostatics.gravity_mps2)");
  check.positive(model.buoyancy_n, "hydrostatics.buoyancy_n");
  check.finite(model.cog_body_m, "rigid_body.cog_body_m");
  check.finite(model.cob_body_m, "hydrostatics.cob_body_m");
  check.finite(model.inertia_kg_m2, "rigid_body.inertia_kg_m2");
  for (int i = 0; i < 3; ++i) {
    if (!(model.inertia_kg_m2(i, i) > 0)) {
      check.fail("rigid_body.inertia_kg_m2", "expected positive moments of inertia, got " +
                                                 format_number(model.inertia_kg_m2(i, i)) +
                                                 " on axis " + "xyz"[i]);
    }
  }
  const Matrix3& inertia = model.inertia_kg_m2;
  if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() >
      kSymmetryTolerance * inertia.cwiseAbs().maxCoeff()) {
    check.fail("rigid_body.inertia_kg_m2", "expected a symmetric inertia tensor");
  }
  // The rigid-body inertia itself must be positive definite (M = M_RB + M_A can be positive
  // definite even when it is not, the added mass hiding an impossible body).
  if (Eigen::LLT<Matrix3>(inertia).info() != Eigen::Success) {
    check.fail("rigid_body.inertia_kg_m2",
               "the inertia tensor is not positive definite, so M_RB is not (no real body has it)");
  }

  // Hydrodynamics.
  check.non_positive(model.added_mass_derivatives, "hydrodynamics.added_mass_derivatives");
  check.non_positive(model.linear_damping, "hydrodynamics.linear_damping");
  check.non_positive(model.quadratic_damping, "hydrodynamics.quadratic_damping");

  // Thrusters: count, geometry, unit directions.
  const int n = model.num_thrusters();
  if (n < 1 || n > kMaxThrusters) {
    check.fail("thrusters", "expected 1 to " + std::to_string(kMaxThrusters) + " thrusters, got " +
                                std::to_string(n));
  }
  model.allocation.resize(6, n);
  for (int i = 0; i < n; ++i) {
    Thruster& t = model.thrusters[static_cast<std::size_t>(i)];
    const std::string field = "thrusters[" + std::to_string(i) + "]";
    check.finite(t.position_body_m, field + ".position_body_m");
    check.finite(t.direction_body, field + ".direction_body");
    const double norm = t.direction_body.norm();
    if (norm < 1e-9) check.fail(field + ".direction_body", "expected a unit vector, got zero");
    if (std::abs(norm - 1.0) > kUnitDirectionTolerance) {
      check.fail(field + ".direction_body",
                 "expected a unit vector (norm 1 within 1 %), got norm " + format_number(norm));
    }
    t.direction_body /= norm;
    model.allocation.col(i).head<3>() = t.direction_body;
    model.allocation.col(i).tail<3>() = t.position_body_m.cross(t.direction_body);
  }
  const int rank = allocation_rank(model.allocation);
  if (rank < kMinControllableDof) {
    check.fail("thrusters", "the layout controls only " + std::to_string(rank) +
                                " DOF (allocation singular values >= " +
                                format_number(kAllocationMinSingularValue) +
                                "); expected at least " + std::to_string(kMinControllableDof));
  }

  const ThrusterDynamics& td = model.thruster_dynamics;
  check.positive(td.max_thrust_n, "thruster_dynamics.max_thrust_n");
  check.positive(td.lag_time_constant_s, "thruster_dynamics.lag_time_constant_s");
  check.positive(td.slew_rate_n_per_s, "thruster_dynamics.slew_rate_n_per_s");

  // Integration and limits.
  check.positive(model.control_step_s, "integration.control_step_s");
  if (model.substeps < 1) {
    check.fail("integration.substeps", "expected >= 1, got " + std::to_string(model.substeps));
  }
  if (model.integrator != Integrator::kRk4 && model.integrator != Integrator::kSemiImplicitEuler) {
    check.fail("integration.integrator", "unknown integrator");
  }
  check.positive(model.blow_up.max_linear_speed_mps, "blow_up_limits.max_linear_speed_mps");
  check.positive(model.blow_up.max_angular_rate_rad_s, "blow_up_limits.max_angular_rate_rad_s");
  check.positive(model.blow_up.max_position_m, "blow_up_limits.max_position_m");

  // M_RB, Fossen 2011 eq. 3.44: [m I, -m S(r_g); m S(r_g), I_b] with I_b = I_g - m S(r_g)^2
  // (eq. 3.37, parallel axes from the CG to the body origin).
  const double m = model.mass_kg;
  const Matrix3 s_rg = skew(model.cog_body_m);
  model.mass_rigid_body.setZero();
  model.mass_rigid_body.topLeftCorner<3, 3>() = m * Matrix3::Identity();
  model.mass_rigid_body.topRightCorner<3, 3>() = -m * s_rg;
  model.mass_rigid_body.bottomLeftCorner<3, 3>() = m * s_rg;
  model.mass_rigid_body.bottomRightCorner<3, 3>() = inertia - m * s_rg * s_rg;
  model.mass_added = (-model.added_mass_derivatives).asDiagonal();
  model.mass_total = model.mass_rigid_body + model.mass_added;

  const Matrix6& mass = model.mass_total;
  if ((mass - mass.transpose()).cwiseAbs().maxCoeff() >
      kSymmetryTolerance * mass.cwiseAbs().maxCoeff()) {
    check.fail("rigid_body.inertia_kg_m2", "mass matrix M = M_RB + M_A is not symmetric");
  }
  const Eigen::LLT<Matrix6> llt(mass);
  if (llt.info() != Eigen::Success) {
    check.fail("rigid_body.inertia_kg_m2",
               "mass matrix M = M_RB + M_A is not positive definite (check the inertia tensor)");
  }
  model.mass_total_inverse = llt.solve(Matrix6::Identity());
}

const config::Table<ThrusterDynamics>& thruster_dynamics_table() {
  static const config::Table<ThrusterDynamics> table = make_thruster_dynamics_table();
  return table;
}

const config::Table<BlowUpLimits>& blow_up_limits_table() {
  static const config::Table<BlowUpLimits> table = make_blow_up_limits_table();
  return table;
}

VehicleModel load_vehicle_file(const std::string& path) {
  const FileReader in(path);
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw VehicleFileError(path, "(file)", "cannot open the file");
  } catch (const YAML::ParserException& e) {
    throw VehicleFileError(path, "(syntax)", e.what());
  }

  VehicleModel model;
  model.source_file = path;
  in.check_map(root, "",
               {"name", "rigid_body", "hydrostatics", "hydrodynamics", "thrusters",
                "thruster_dynamics", "integration", "blow_up_limits"});
  model.name = in.text(root, "", "name");

  const YAML::Node body = in.require(root, "", "rigid_body");
  in.check_map(body, "rigid_body", {"mass_kg", "inertia_kg_m2", "cog_body_m"});
  model.mass_kg = in.number(body, "rigid_body", "mass_kg");
  model.inertia_kg_m2 = in.inertia(body, "rigid_body", "inertia_kg_m2");
  model.cog_body_m = in.vector(body, "rigid_body", "cog_body_m", 3);

  const YAML::Node statics = in.require(root, "", "hydrostatics");
  in.check_map(
      statics, "hydrostatics",
      {"gravity_mps2", "cob_body_m", "buoyancy_n", "displaced_volume_m3", "water_density_kg_m3"});
  const double gravity_mps2 = in.number(statics, "hydrostatics", "gravity_mps2");
  if (!(gravity_mps2 > 0)) in.fail("hydrostatics.gravity_mps2", "expected a positive number");
  model.weight_n = model.mass_kg * gravity_mps2;
  model.cob_body_m = in.vector(statics, "hydrostatics", "cob_body_m", 3);
  const bool has_buoyancy = statics["buoyancy_n"].IsDefined();
  const bool has_volume =
      statics["displaced_volume_m3"].IsDefined() || statics["water_density_kg_m3"].IsDefined();
  if (has_buoyancy == has_volume) {
    in.fail("hydrostatics.buoyancy_n",
            "give either buoyancy_n or both displaced_volume_m3 and water_density_kg_m3");
  }
  if (has_buoyancy) {
    model.buoyancy_n = in.number(statics, "hydrostatics", "buoyancy_n");
  } else {
    const double volume = in.number(statics, "hydrostatics", "displaced_volume_m3");
    const double density = in.number(statics, "hydrostatics", "water_density_kg_m3");
    if (!(volume > 0)) in.fail("hydrostatics.displaced_volume_m3", "expected a positive number");
    if (!(density > 0)) in.fail("hydrostatics.water_density_kg_m3", "expected a positive number");
    model.buoyancy_n = density * gravity_mps2 * volume;
  }

  const YAML::Node hydro = in.require(root, "", "hydrodynamics");
  in.check_map(
      hydro, "hydrodynamics",
      {"added_mass_derivatives", "linear_damping", "quadratic_damping", "added_mass_coriolis"});
  model.added_mass_derivatives = in.vector(hydro, "hydrodynamics", "added_mass_derivatives", 6);
  model.linear_damping = in.vector(hydro, "hydrodynamics", "linear_damping", 6);
  model.quadratic_damping = in.vector(hydro, "hydrodynamics", "quadratic_damping", 6);
  model.added_mass_coriolis = in.boolean(hydro, "hydrodynamics", "added_mass_coriolis");

  const YAML::Node thrusters = in.require(root, "", "thrusters");
  if (!thrusters.IsSequence() || thrusters.size() == 0) {
    in.fail("thrusters", "expected a non-empty list of thrusters", &thrusters);
  }
  if (thrusters.size() > static_cast<std::size_t>(kMaxThrusters)) {
    in.fail("thrusters",
            "expected at most " + std::to_string(kMaxThrusters) + " thrusters, got " +
                std::to_string(thrusters.size()),
            &thrusters);
  }
  for (std::size_t i = 0; i < thrusters.size(); ++i) {
    const std::string field = "thrusters[" + std::to_string(i) + "]";
    const YAML::Node t = thrusters[i];
    in.check_map(t, field, {"name", "position_body_m", "direction_body"});
    Thruster thruster;
    thruster.name = in.text(t, field, "name");
    thruster.position_body_m = in.vector(t, field, "position_body_m", 3);
    thruster.direction_body = in.vector(t, field, "direction_body", 3);
    model.thrusters.push_back(thruster);
  }

  read_block(path, in.require(root, "", "thruster_dynamics"), "thruster_dynamics",
             thruster_dynamics_table(), model.thruster_dynamics);

  const YAML::Node integration = in.require(root, "", "integration");
  in.check_map(integration, "integration", {"control_step_s", "integrator", "substeps"});
  model.control_step_s = in.number(integration, "integration", "control_step_s");
  const std::string integrator = in.text(integration, "integration", "integrator");
  if (integrator == "rk4") {
    model.integrator = Integrator::kRk4;
  } else if (integrator == "semi_implicit_euler") {
    model.integrator = Integrator::kSemiImplicitEuler;
  } else {
    const YAML::Node node = integration["integrator"];
    in.fail("integration.integrator",
            "expected rk4 or semi_implicit_euler, got '" + integrator + "'", &node);
  }
  model.substeps = in.integer(integration, "integration", "substeps");

  read_block(path, in.require(root, "", "blow_up_limits"), "blow_up_limits", blow_up_limits_table(),
             model.blow_up);

  finalize_vehicle_model(model);
  return model;
}

}  // namespace auvrl::sim
