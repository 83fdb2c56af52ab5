// Vehicle file loading (config::Table per block, see common/config/table.hpp) and model
// finalisation: derived matrices and validation.
//
// File layout (every key required, unknown keys rejected so that a typo cannot silently fall
// back to a default; docs/configuration.md lists every key):
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
#include <zlib.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"

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

// ---- YAML reading: one config::Table per block (types, sizes, unknown and missing keys). ----

/// A vehicle file as written: the model plus the hydrostatic figures it is derived from.
struct VehicleFile {
  VehicleModel model;
  double gravity_mps2 = 0;
  double buoyancy_n = 0;  ///< given directly, or
  double displaced_volume_m3 = 0;
  double water_density_kg_m3 = 0;  ///< B = rho g V
  bool buoyancy_from_volume = false;
};

/// Every block of a vehicle file reads into the same VehicleFile (an identity accessor).
VehicleFile& whole(VehicleFile& f) { return f; }

Integrator parse_integrator(const std::string& text) {
  if (text == "rk4") return Integrator::kRk4;
  if (text == "semi_implicit_euler") return Integrator::kSemiImplicitEuler;
  throw std::invalid_argument("expected rk4 or semi_implicit_euler, got '" + text + "'");
}

const char* integrator_name(Integrator integrator) {
  return integrator == Integrator::kRk4 ? "rk4" : "semi_implicit_euler";
}

config::Table<VehicleFile> make_rigid_body_table() {
  using F = VehicleFile;
  config::Table<F> t("rigid_body", "mass and inertia");
  t.field(
       "mass_kg", [](F& f) -> double& { return f.model.mass_kg; }, "kg", "mass")
      .required()
      .positive();
  t.field(
       "inertia_kg_m2", [](F& f) -> Matrix3& { return f.model.inertia_kg_m2; }, "kg m^2",
       "inertia tensor about the CG: [Ix, Iy, Iz] (principal axes) or 3 rows")
      .required();
  t.field(
       "cog_body_m", [](F& f) -> Vector3& { return f.model.cog_body_m; }, "m",
       "centre of gravity r_g from the body origin (the centre of buoyancy)")
      .required();
  return t;
}

/// Buoyancy is given either directly or as rho g V, never both.
void check_buoyancy(const config::Section& s, VehicleFile& f) {
  const bool has_buoyancy = s.has("buoyancy_n");
  const bool has_volume = s.has("displaced_volume_m3") || s.has("water_density_kg_m3");
  if (has_buoyancy == has_volume) {
    s.fail("buoyancy_n",
           "give either buoyancy_n or both displaced_volume_m3 and water_density_kg_m3");
  }
  for (const char* key : {"displaced_volume_m3", "water_density_kg_m3"}) {
    if (has_volume && !s.has(key)) s.fail(key, "missing (needed with the other of the pair)");
  }
  f.buoyancy_from_volume = has_volume;
}

config::Table<VehicleFile> make_hydrostatics_table() {
  using F = VehicleFile;
  config::Table<F> t("hydrostatics",
                     "weight and buoyancy: buoyancy_n, or displaced_volume_m3 and "
                     "water_density_kg_m3 (B = rho g V)");
  t.field("gravity_mps2", &F::gravity_mps2, "m/s^2", "W = m g").required().positive();
  t.field(
       "cob_body_m", [](F& f) -> Vector3& { return f.model.cob_body_m; }, "m",
       "centre of buoyancy r_b")
      .required();
  t.field("buoyancy_n", &F::buoyancy_n, "N", "buoyancy B (or the next two)").positive();
  t.field("displaced_volume_m3", &F::displaced_volume_m3, "m^3", "displaced volume V").positive();
  t.field("water_density_kg_m3", &F::water_density_kg_m3, "kg/m^3", "water density rho").positive();
  t.validate(check_buoyancy);
  return t;
}

config::Table<VehicleFile> make_hydrodynamics_table() {
  using F = VehicleFile;
  config::Table<F> t("hydrodynamics", "added mass and damping, SNAME signs (each <= 0)");
  t.field(
       "added_mass_derivatives", [](F& f) -> Vector6& { return f.model.added_mass_derivatives; },
       "kg, kg m^2", "[X_udot Y_vdot Z_wdot K_pdot M_qdot N_rdot]")
      .required();
  t.field(
       "linear_damping", [](F& f) -> Vector6& { return f.model.linear_damping; }, "",
       "[X_u Y_v Z_w K_p M_q N_r]")
      .required();
  t.field(
       "quadratic_damping", [](F& f) -> Vector6& { return f.model.quadratic_damping; }, "",
       "[X_uu Y_vv Z_ww K_pp M_qq N_rr]")
      .required();
  t.field(
       "added_mass_coriolis", [](F& f) -> bool& { return f.model.added_mass_coriolis; }, "",
       "include C_A(nu_r) (the Munk moment)")
      .required();
  return t;
}

config::Table<Thruster> make_thruster_table() {
  config::Table<Thruster> t("thrusters", "where each thruster sits and which way it pushes");
  t.field("name", &Thruster::name, "", "label").required();
  t.field("position_body_m", &Thruster::position_body_m, "m", "from the body origin").required();
  t.field("direction_body", &Thruster::direction_body, "", "unit vector of positive thrust")
      .required();
  return t;
}

config::Table<VehicleFile> make_integration_table() {
  using F = VehicleFile;
  config::Table<F> t("integration", "time step and integrator");
  t.field(
       "control_step_s", [](F& f) -> double& { return f.model.control_step_s; }, "s",
       "control step")
      .required()
      .positive();
  t.choice(
       "integrator", [](F& f) -> Integrator& { return f.model.integrator; }, parse_integrator,
       integrator_name, "rk4, semi_implicit_euler", "integration scheme")
      .required();
  t.field(
       "substeps", [](F& f) -> int& { return f.model.substeps; }, "",
       "integrator steps per control step")
      .required()
      .range(1);
  return t;
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

config::Table<VehicleFile> make_vehicle_file_table() {
  using F = VehicleFile;
  config::Table<F> t("vehicle file",
                     "A vehicle (config/vehicles/*.yaml): every block and key is required "
                     "(there are no defaults) and unknown keys are errors.");
  t.field(
       "name", [](F& f) -> std::string& { return f.model.name; }, "", "the vehicle's name")
      .required();
  t.section("rigid_body", make_rigid_body_table(), whole).required();
  t.section("hydrostatics", make_hydrostatics_table(), whole).required();
  t.section("hydrodynamics", make_hydrodynamics_table(), whole).required();
  t.list(
       "thrusters", make_thruster_table(),
       [](F& f) -> std::vector<Thruster>& { return f.model.thrusters; }, 1,
       static_cast<std::size_t>(kMaxThrusters))
      .required();
  t.section("thruster_dynamics", thruster_dynamics_table(), [](F& f) -> ThrusterDynamics& {
     return f.model.thruster_dynamics;
   }).required();
  t.section("integration", make_integration_table(), whole).required();
  t.section("blow_up_limits", blow_up_limits_table(), [](F& f) -> BlowUpLimits& {
     return f.model.blow_up;
   }).required();
  return t;
}

const config::Table<VehicleFile>& vehicle_file_table() {
  static const config::Table<VehicleFile> table = make_vehicle_file_table();
  return table;
}

/// The file's YAML from its text; a syntax error is a VehicleFileError.
YAML::Node parse_yaml(const std::string& path, const std::string& text) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw VehicleFileError(path, "(syntax)", e.what());
  }
}

/// CRC-32 of the file's bytes (the vehicle's identity on the wire).
std::uint32_t bytes_crc32(const std::string& bytes) {
  return static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

/// Reads every block through vehicle_file_table(); ConfigError becomes VehicleFileError with
/// the same dotted field and line.
VehicleFile read_vehicle_file(const std::string& path, const YAML::Node& root) {
  VehicleFile file;
  try {
    vehicle_file_table().read(config::Section(path, "", root), file);
  } catch (const config::ConfigError& e) {
    const std::string field = e.key().empty() ? "(top level)" : e.key();
    throw VehicleFileError(path, field, e.detail().empty() ? e.what() : e.detail());
  }
  return file;
}

/// Weight and buoyancy from the hydrostatics block (W = m g; B given or rho g V).
void apply_hydrostatics(VehicleFile& file) {
  VehicleModel& model = file.model;
  model.weight_n = model.mass_kg * file.gravity_mps2;
  model.buoyancy_n = file.buoyancy_from_volume
                         ? file.water_density_kg_m3 * file.gravity_mps2 * file.displaced_volume_m3
                         : file.buoyancy_n;
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

/// Mass, weight, buoyancy, centres and the inertia tensor (positive definite, symmetric).
void check_rigid_body(const ModelChecker& check, const VehicleModel& model) {
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
}

void check_hydrodynamics(const ModelChecker& check, const VehicleModel& model) {
  check.non_positive(model.added_mass_derivatives, "hydrodynamics.added_mass_derivatives");
  check.non_positive(model.linear_damping, "hydrodynamics.linear_damping");
  check.non_positive(model.quadratic_damping, "hydrodynamics.quadratic_damping");
}

/// Thrusters: count, geometry, unit directions (normalised), allocation B and its rank.
void build_allocation(const ModelChecker& check, VehicleModel& model) {
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
  try {
    model.controlled_axes = controlled_axes(model.allocation);
  } catch (const std::invalid_argument& e) {
    check.fail("thrusters", e.what());
  }
}

void check_thruster_dynamics_and_integration(const ModelChecker& check, const VehicleModel& model) {
  const ThrusterDynamics& td = model.thruster_dynamics;
  check.positive(td.max_thrust_n, "thruster_dynamics.max_thrust_n");
  check.positive(td.lag_time_constant_s, "thruster_dynamics.lag_time_constant_s");
  check.positive(td.slew_rate_n_per_s, "thruster_dynamics.slew_rate_n_per_s");
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
}

/// M_RB, M_A, M and its inverse; M must be symmetric positive definite.
void build_mass_matrices(const ModelChecker& check, VehicleModel& model) {
  // M_RB, Fossen 2011 eq. 3.44: [m I, -m S(r_g); m S(r_g), I_b] with I_b = I_g - m S(r_g)^2
  // (eq. 3.37, parallel axes from the CG to the body origin).
  const double m = model.mass_kg;
  const Matrix3 s_rg = skew(model.cog_body_m);
  model.mass_rigid_body.setZero();
  model.mass_rigid_body.topLeftCorner<3, 3>() = m * Matrix3::Identity();
  model.mass_rigid_body.topRightCorner<3, 3>() = -m * s_rg;
  model.mass_rigid_body.bottomLeftCorner<3, 3>() = m * s_rg;
  model.mass_rigid_body.bottomRightCorner<3, 3>() = model.inertia_kg_m2 - m * s_rg * s_rg;
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

namespace {

/// Smallest singular value of the allocation's rows in `axes` (0 when none).
double smallest_singular_value(const AllocationMatrix& allocation, const AxisSet& axes) {
  Eigen::MatrixXd rows(0, allocation.cols());
  for (int axis = 0; axis < 6; ++axis) {
    if (!axes[static_cast<std::size_t>(axis)]) continue;
    rows.conservativeResize(rows.rows() + 1, Eigen::NoChange);
    rows.row(rows.rows() - 1) = allocation.row(axis);
  }
  if (rows.rows() == 0) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(rows * rows.transpose(),
                                                             Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(eigen.eigenvalues().minCoeff(), 0.0));
}

}  // namespace

AxisSet controlled_axes(const AllocationMatrix& allocation) {
  AxisSet axes{};
  std::string missing;
  for (Axis axis : {kSurge, kHeave, kYaw}) {
    AxisSet alone{};
    alone[axis] = true;
    if (smallest_singular_value(allocation, alone) < kAllocationMinSingularValue) {
      missing += std::string(missing.empty() ? "" : ", ") + kAxisNames[axis];
    }
    axes[axis] = true;
  }
  if (!missing.empty()) {
    throw std::invalid_argument("the thrusters have no authority in " + missing +
                                ": a vehicle needs surge, heave and yaw to reach way-points");
  }
  if (smallest_singular_value(allocation, axes) < kAllocationMinSingularValue) {
    throw std::invalid_argument(
        "the thrusters cannot drive surge, heave and yaw independently of each other (the "
        "allocation's rows for them have a singular value under " +
        format_number(kAllocationMinSingularValue) + ")");
  }
  for (Axis axis : {kSway, kPitch, kRoll}) {
    AxisSet with = axes;
    with[axis] = true;
    if (smallest_singular_value(allocation, with) >= kAllocationMinSingularValue) axes = with;
  }
  return axes;
}

VehicleFacts VehicleModel::facts() const {
  VehicleFacts f;
  f.name = name;
  f.source_file = source_file;
  f.file_crc32 = file_crc32;
  for (const Thruster& t : thrusters) f.thruster_names.push_back(t.name);
  f.control_step_s = control_step_s;
  f.thruster_dynamics = thruster_dynamics;
  for (Eigen::Index i = 0; i < allocation.cols(); ++i) {
    ThrusterWrench& w = f.thruster_wrench.emplace_back();
    for (int k = 0; k < 6; ++k) w[static_cast<std::size_t>(k)] = allocation(k, i);
  }
  return f;
}

void finalize_vehicle_model(VehicleModel& model) {
  const ModelChecker check(model);
  check_rigid_body(check, model);
  check_hydrodynamics(check, model);
  build_allocation(check, model);
  check_thruster_dynamics_and_integration(check, model);
  build_mass_matrices(check, model);
}

const config::Table<ThrusterDynamics>& thruster_dynamics_table() {
  static const config::Table<ThrusterDynamics> table = make_thruster_dynamics_table();
  return table;
}

const config::Table<BlowUpLimits>& blow_up_limits_table() {
  static const config::Table<BlowUpLimits> table = make_blow_up_limits_table();
  return table;
}

config::SectionDoc vehicle_file_doc() { return config::section_doc(vehicle_file_table()); }

VehicleModel load_vehicle_file(const std::string& path) {
  // Read once: the same bytes are parsed and give the file's CRC-32.
  std::string text;
  std::string why;
  if (!config::read_text_file(path, text, why)) throw VehicleFileError(path, "(file)", why);
  VehicleFile file = read_vehicle_file(path, parse_yaml(path, text));
  file.model.source_file = path;
  file.model.file_crc32 = bytes_crc32(text);
  apply_hydrostatics(file);
  finalize_vehicle_model(file.model);
  return std::move(file.model);
}

}  // namespace auvrl::sim
