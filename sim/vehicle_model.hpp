// The immutable description of a vehicle (MuJoCo's mjModel): rigid body, hydrodynamics,
// hydrostatics, thrusters and integrator settings, loaded and validated from a YAML file.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace auvrl::config {
template <class T>
class Table;
struct SectionDoc;
}  // namespace auvrl::config

#include "common/vehicle_facts.hpp"

namespace auvrl::sim {

/// Most thrusters a vehicle file may declare; bounds the fixed-capacity thrust vectors so the
/// physics step never allocates.
inline constexpr int kMaxThrusters = 12;

using Vector3 = Eigen::Vector3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix3 = Eigen::Matrix3d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
/// Per-thruster quantities (N or unitless); size = number of thrusters, capacity kMaxThrusters.
using ThrusterVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxThrusters, 1>;
/// Thruster allocation matrix B (6 x n): tau_body = B * thrust_n, rows X, Y, Z, K, M, N.
using AllocationMatrix = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxThrusters>;

/// Error in a vehicle file: names the file and the field and says what was expected.
class VehicleFileError : public std::runtime_error {
 public:
  VehicleFileError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(file + ": field '" + field + "': " + what), file_(file), field_(field) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_;
  std::string field_;
};

/// One thruster: where it sits and which way it pushes, in the body frame.
struct Thruster {
  std::string name;
  Vector3 position_body_m = Vector3::Zero();  ///< from the body origin (= centre of buoyancy)
  Vector3 direction_body = Vector3::UnitX();  ///< unit vector of positive thrust
};

/// Thruster response (common/vehicle_facts.hpp: the task models a healthy thruster with it).
using ThrusterDynamics = auvrl::ThrusterDynamics;

/// The body DOF in the allocation's row order.
enum Axis : int { kSurge = 0, kSway = 1, kHeave = 2, kRoll = 3, kPitch = 4, kYaw = 5 };
/// Their names, for messages: "surge", "sway", "heave", "roll", "pitch", "yaw".
inline constexpr const char* kAxisNames[6] = {"surge", "sway", "heave", "roll", "pitch", "yaw"};
/// One flag per body DOF (Axis order).
using AxisSet = std::array<bool, 6>;

/// Integration scheme for one control step.
enum class Integrator { kRk4, kSemiImplicitEuler };

/// Limits beyond which the state is declared blown up (reported, never propagated).
struct BlowUpLimits {
  double max_linear_speed_mps = 20.0;
  double max_angular_rate_rad_s = 20.0;
  double max_position_m = 1.0e4;
};

/// The whole vehicle model. Immutable once loaded; derived matrices are precomputed.
struct VehicleModel {
  std::string name;
  std::string source_file;
  std::uint32_t file_crc32 = 0;  ///< CRC-32 of the file's bytes (0 for a model built in code)

  // Rigid body.
  double mass_kg = 0;
  double weight_n = 0;                      ///< W = m g
  double buoyancy_n = 0;                    ///< B = rho g V
  Vector3 cog_body_m = Vector3::Zero();     ///< centre of gravity r_g
  Vector3 cob_body_m = Vector3::Zero();     ///< centre of buoyancy r_b
  Matrix3 inertia_kg_m2 = Matrix3::Zero();  ///< about the body origin's axes, at the CG

  // Hydrodynamics (SNAME signs: added-mass and damping derivatives are negative numbers).
  Vector6 added_mass_derivatives =
      Vector6::Zero();                          ///< [X_udot Y_vdot Z_wdot K_pdot M_qdot N_rdot]
  Vector6 linear_damping = Vector6::Zero();     ///< [X_u Y_v Z_w K_p M_q N_r], <= 0
  Vector6 quadratic_damping = Vector6::Zero();  ///< [X_uu Y_vv Z_ww K_pp M_qq N_rr], <= 0
  bool added_mass_coriolis = false;             ///< include C_A(nu_r) (Munk moment)

  // Thrusters.
  std::vector<Thruster> thrusters;
  AllocationMatrix allocation;  ///< column i = [d_i; r_i x d_i]
  ThrusterDynamics thruster_dynamics;

  // Integration.
  double control_step_s = 0.1;
  Integrator integrator = Integrator::kRk4;
  int substeps = 10;  ///< integrator steps per control step
  BlowUpLimits blow_up;

  // Derived at load time.
  Matrix6 mass_rigid_body = Matrix6::Zero();  ///< M_RB with the CG offset
  Matrix6 mass_added = Matrix6::Zero();       ///< M_A = -diag(added_mass_derivatives)
  Matrix6 mass_total = Matrix6::Zero();       ///< M = M_RB + M_A
  Matrix6 mass_total_inverse = Matrix6::Zero();
  /// The DOF the thrusters drive independently (controlled_axes(allocation)); the others are
  /// left to the vehicle's own stability (Nessie VII's roll, BlueROV2's pitch).
  AxisSet controlled_axes{};

  int num_thrusters() const { return static_cast<int>(thrusters.size()); }
  /// The facts every process takes from the vehicle file (identity, thrusters, limits).
  VehicleFacts facts() const;
};

/// Singular values of the allocation matrix below this do not count as control authority. The
/// unit is N (or N m) of generalised force per N of thrust along a unit-norm thrust vector:
/// 0.1 is a 10 cm lever arm. Nessie VII's lateral thrusters sit about 5 cm above and below the
/// centre of buoyancy, so its roll authority falls under it: five controllable DOF.
inline constexpr double kAllocationMinSingularValue = 0.1;

/// Number of singular values of the allocation matrix at or above kAllocationMinSingularValue:
/// how many independent body-frame DOF the thrusters can drive.
int allocation_rank(const AllocationMatrix& allocation);

/// Which DOF the thrusters drive independently of each other. Surge, heave and yaw come first
/// (without them no way-point is reachable); then sway, pitch and roll, each kept only if the
/// allocation's rows of the chosen set still have every singular value at or above
/// kAllocationMinSingularValue. A DOF left out is one the thrusters cannot move without also
/// moving a chosen one (BlueROV2's pitch, made only by the surge thrusters' depth offset).
/// Throws std::invalid_argument naming the missing DOF when surge, heave and yaw are not all
/// independently controlled.
AxisSet controlled_axes(const AllocationMatrix& allocation);

/// Loads and validates a vehicle file; throws VehicleFileError naming file and field.
VehicleModel load_vehicle_file(const std::string& path);

/// The keys of a vehicle file's thruster_dynamics: and blow_up_limits: blocks (all required).
const config::Table<ThrusterDynamics>& thruster_dynamics_table();
const config::Table<BlowUpLimits>& blow_up_limits_table();
/// Every block and key of a vehicle file (one section of docs/configuration.md).
config::SectionDoc vehicle_file_doc();

/// Fills the derived members (allocation, mass matrices) and validates the whole model;
/// throws VehicleFileError with model.source_file. Called by load_vehicle_file; public so
/// tests and tools can build a model in code.
void finalize_vehicle_model(VehicleModel& model);

}  // namespace auvrl::sim
