// Helpers shared by the vehicle dynamics tests.
#pragma once

// GCC 12 with -march=native on AVX-512 machines reports false maybe-uninitialized and
// array-bounds warnings inside Eigen's vectorised kernels; include this header first in every
// test file.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Warray-bounds"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/dynamics.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::sim::test {

inline std::string vehicle_path(const std::string& file_name) {
  return std::string(AUVRL_CONFIG_DIR) + "/vehicles/" + file_name;
}

inline const VehicleModel& nessie() {
  static const VehicleModel model = load_vehicle_file(vehicle_path("nessie7.yaml"));
  return model;
}

inline const VehicleModel& nessie_munk() {
  static const VehicleModel model = load_vehicle_file(vehicle_path("nessie7_munk.yaml"));
  return model;
}

inline const VehicleModel& bluerov() {
  static const VehicleModel model = load_vehicle_file(vehicle_path("bluerov2_heavy.yaml"));
  return model;
}

inline ThrusterVector thrusts(std::initializer_list<double> values) {
  // Through a std::vector: GCC 12.2 with -march=native on this CPU miscompiles the direct loop
  // over the initializer_list into the vector (SLP vectoriser: {a, a, 0, 0} stored as a splat).
  const std::vector<double> copy(values);
  return Eigen::Map<const Eigen::VectorXd>(copy.data(), static_cast<Eigen::Index>(copy.size()));
}

/// Reset at rest, level, heading north, at the given depth (deep enough that a slow rise or
/// sink never reaches the surface, which the model does not represent).
inline ResetSettings reset_at_depth(double depth_m) {
  ResetSettings reset;
  reset.eta << 0.0, 0.0, depth_m, 0.0, 0.0, 0.0;
  return reset;
}

/// Total mechanical energy (J): kinetic 1/2 nu^T M nu plus the potential of weight and
/// buoyancy, V = (B - W) z - W (R r_g)_z + B (R r_b)_z (z down). Without thrust it can only
/// decrease: the Coriolis matrices are skew-symmetric and the damping dissipates.
inline double mechanical_energy_j(const VehicleModel& model, const VehicleState& state) {
  const double phi = state.eta(3), theta = state.eta(4);
  const Vector3 down_row(-std::sin(theta), std::cos(theta) * std::sin(phi),
                         std::cos(theta) * std::cos(phi));  // third row of R_b^n
  const double kinetic = 0.5 * state.nu.dot(model.mass_total * state.nu);
  const double potential = (model.buoyancy_n - model.weight_n) * state.eta(2) -
                           model.weight_n * down_row.dot(model.cog_body_m) +
                           model.buoyancy_n * down_row.dot(model.cob_body_m);
  return kinetic + potential;
}

/// A scratch directory for one test, removed at the end.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info->name();
    std::replace(name.begin(), name.end(), '/', '_');  // parameterised tests: "Name/3"
    std::random_device rd;
    path_ =
        std::filesystem::temp_directory_path() / ("auvrl_sim_" + name + "_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

}  // namespace auvrl::sim::test
