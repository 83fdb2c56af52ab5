// Vehicle files: values, derived matrices, allocation, and validation of corrupted copies.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <functional>
#include <iostream>
#include <string>

#include "sim_test_util.hpp"  // first: see the note on Eigen warnings there

namespace auvrl::sim::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(VehicleModel, NessieValuesFromTheReference) {
  const VehicleModel& m = nessie();
  EXPECT_EQ(m.name, "nessie7");
  EXPECT_DOUBLE_EQ(m.mass_kg, 60.0);
  EXPECT_NEAR(m.weight_n, 588.6, 1e-9);
  EXPECT_DOUBLE_EQ(m.buoyancy_n, 589.6);
  EXPECT_EQ(m.cog_body_m, Vector3(0, 0, 0.06));
  EXPECT_EQ(m.num_thrusters(), 6);
  EXPECT_FALSE(m.added_mass_coriolis);
  EXPECT_TRUE(nessie_munk().added_mass_coriolis);
  // Cylinder r = 0.15 m, L = 1.7 m, rho = 1025 kg/m^3 (nessie7.md).
  const double r = 0.15, length = 1.7, rho = 1025.0;
  EXPECT_NEAR(m.inertia_kg_m2(0, 0), 60.0 * r * r / 2, 1e-9);
  EXPECT_NEAR(m.inertia_kg_m2(1, 1), 60.0 * (3 * r * r + length * length) / 12, 1e-9);
  EXPECT_NEAR(m.added_mass_derivatives(1), -kPi * rho * r * r * length, 1e-6);
  EXPECT_NEAR(m.added_mass_derivatives(3), -kPi * rho * std::pow(r, 4) / 4, 1e-6);
  EXPECT_NEAR(m.added_mass_derivatives(4), -kPi * rho * r * r * std::pow(length, 3) / 12, 1e-6);
  EXPECT_EQ(m.integrator, Integrator::kRk4);
  EXPECT_EQ(m.substeps, 10);
  EXPECT_DOUBLE_EQ(m.control_step_s, 0.1);
  EXPECT_TRUE(m.thruster_dynamics.delay_enabled);
  EXPECT_NEAR(m.thruster_dynamics.lag_time_constant_s, 1.0 / (2 * kPi * 0.55), 1e-4);
  EXPECT_NEAR(m.thruster_dynamics.slew_rate_n_per_s, 0.055 * 39.24 / 0.1, 1e-9);
}

TEST(VehicleModel, RigidBodyMassMatrixWithCgOffset) {
  // Fossen 2011 eq. 3.44 written out for r_g = [0, 0, z_g]: the surge-pitch and sway-roll
  // couplings are +-m z_g and the roll/pitch inertias gain m z_g^2 (parallel axes).
  const VehicleModel& m = nessie();
  const double mz = 60.0 * 0.06;
  Matrix6 expected = Matrix6::Zero();
  expected.diagonal() << 60, 60, 60, 0.675 + mz * 0.06, 14.7875 + mz * 0.06, 14.7875;
  expected(0, 4) = expected(4, 0) = mz;
  expected(1, 3) = expected(3, 1) = -mz;
  EXPECT_LT((m.mass_rigid_body - expected).cwiseAbs().maxCoeff(), 1e-12) << m.mass_rigid_body;
  EXPECT_LT((m.mass_added - Matrix6(Vector6(-m.added_mass_derivatives).asDiagonal()))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_LT((m.mass_total * m.mass_total_inverse - Matrix6::Identity()).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(VehicleModel, NessieAllocationHasFiveControllableDof) {
  const VehicleModel& m = nessie();
  ASSERT_EQ(m.allocation.cols(), 6);
  for (int i = 0; i < 6; ++i) {
    const Thruster& t = m.thrusters[static_cast<std::size_t>(i)];
    EXPECT_LT((m.allocation.col(i).head<3>() - t.direction_body).norm(), 1e-15);
    EXPECT_LT((m.allocation.col(i).tail<3>() - t.position_body_m.cross(t.direction_body)).norm(),
              1e-15);
  }
  // Surge thrusters: yaw arms -+0.185 m; vertical thrusters: pitch arms 0.625 and -0.435 m.
  EXPECT_DOUBLE_EQ(m.allocation(5, 0), 0.185);
  EXPECT_DOUBLE_EQ(m.allocation(5, 1), -0.185);
  EXPECT_DOUBLE_EQ(m.allocation(4, 4), 0.625);
  EXPECT_DOUBLE_EQ(m.allocation(4, 5), -0.435);
  // Roll row: only the lateral thrusters' 5 cm vertical offsets (0.052 and -0.053 m).
  const Eigen::RowVectorXd roll_row = m.allocation.row(3);
  EXPECT_NEAR(roll_row.cwiseAbs().maxCoeff(), 0.053, 1e-12);
  EXPECT_NEAR(roll_row(2), 0.052, 1e-12);
  EXPECT_NEAR(roll_row(3), -0.053, 1e-12);
  EXPECT_EQ(allocation_rank(m.allocation), 5);
  EXPECT_EQ(allocation_rank(bluerov().allocation), 6);
  // Five controlled DOF: every one but roll.
  EXPECT_EQ(m.controlled_axes, (AxisSet{true, true, true, false, true, true}));
  EXPECT_EQ(bluerov().controlled_axes, (AxisSet{true, true, true, true, true, true}));
}

TEST(VehicleModel, BlueRov2HeavyLoads) {
  const VehicleModel& m = bluerov();
  EXPECT_EQ(m.name, "bluerov2_heavy");
  EXPECT_EQ(m.num_thrusters(), 8);
  EXPECT_NEAR(m.weight_n, 13.5 * 9.82, 1e-9);
  EXPECT_NEAR(m.buoyancy_n, 1000.0 * 9.82 * 0.0134, 1e-9);
  // Horizontal thrusters at 45 degrees: T1 + T2 - T3 - T4 is surge (1/sqrt(2) N per N each),
  // plus the pitch moment of pushing 8.5 cm below the CG; no sway, heave, roll or yaw.
  const Vector6 surge = m.allocation * thrusts({1, 1, -1, -1, 0, 0, 0, 0});
  const double a = 1.0 / std::sqrt(2.0);
  EXPECT_NEAR(surge(0), 4.0 * a, 1e-6);
  EXPECT_NEAR(surge(4), 4.0 * a * 0.085, 1e-6);
  for (int i : {1, 2, 3, 5}) EXPECT_NEAR(surge(i), 0.0, 1e-6) << surge.transpose();
  // Vertical thrusters push up (-z) and sit on the horizontal plane of the CG: no pitch/roll.
  const Vector6 heave = m.allocation * thrusts({0, 0, 0, 0, 1, 1, 1, 1});
  EXPECT_NEAR(heave(2), -4.0, 1e-12);
  EXPECT_LT(heave.tail<3>().cwiseAbs().maxCoeff(), 1e-12);
  for (const Thruster& t : m.thrusters) EXPECT_NEAR(t.direction_body.norm(), 1.0, 1e-15);
}

/// Where `what` first occurs in a vehicle file's text outside comments (npos if nowhere): the
/// files quote keys and values in their comments, which a corruption must not hit.
std::size_t find_in_data(const std::string& text, const std::string& what) {
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    const auto line_start = text.rfind('\n', at);
    const auto begin = line_start == std::string::npos ? 0 : line_start + 1;
    if (text.find('#', begin) >= at) return at;
  }
  return std::string::npos;
}

// ---- The standard BlueROV2 (six thrusters) and the authority rule. --------------------

const VehicleModel& bluerov2_standard() {
  static const VehicleModel model = load_vehicle_file(vehicle_path("bluerov2.yaml"));
  return model;
}

TEST(VehicleModel, BlueRov2StandardLoads) {
  const VehicleModel& m = bluerov2_standard();
  EXPECT_EQ(m.name, "bluerov2");
  EXPECT_EQ(m.num_thrusters(), 6);
  // Wu 2018: m = 11.5 kg, W = 112.8 N, B = 114.8 N (2 N positively buoyant), CB 2 cm above
  // the CG (NED: smaller z is higher).
  EXPECT_DOUBLE_EQ(m.mass_kg, 11.5);
  EXPECT_NEAR(m.weight_n, 112.8, 0.05);
  EXPECT_DOUBLE_EQ(m.buoyancy_n, 114.8);
  EXPECT_GT(m.buoyancy_n - m.weight_n, 1.5);
  EXPECT_LT(m.buoyancy_n - m.weight_n, 2.5);
  EXPECT_NEAR(m.cog_body_m.z() - m.cob_body_m.z(), 0.02, 1e-12);
  // The horizontal thrusters sit where the Heavy's T1..T4 do in x and y, 1.1 cm below the CG.
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(m.thrusters[i].position_body_m.head<2>(),
              bluerov().thrusters[i].position_body_m.head<2>())
        << i;
    EXPECT_DOUBLE_EQ(m.thrusters[i].position_body_m.z(), 0.011) << i;
    EXPECT_EQ(m.thrusters[i].direction_body, bluerov().thrusters[i].direction_body) << i;
  }
  // Surge, sway, heave, roll and yaw controlled; pitch is only the surge thrusters' depth
  // (pitch row = 0.011 m x surge row), so it is left to the CB-over-CG moment.
  EXPECT_EQ(m.controlled_axes, (AxisSet{true, true, true, true, false, true}));
  EXPECT_EQ(allocation_rank(m.allocation), 5);
  EXPECT_LT((m.allocation.row(kPitch) - 0.011 * m.allocation.row(kSurge)).cwiseAbs().maxCoeff(),
            1e-12);
  // Roll from the two vertical thrusters' 0.109 m arms, heave from their sum.
  const Vector6 roll = m.allocation * thrusts({0, 0, 0, 0, -1, 1});
  EXPECT_NEAR(roll(kRoll), 2 * 0.109, 1e-12);
  EXPECT_LT(roll.head<3>().cwiseAbs().maxCoeff(), 1e-12);
  const Vector6 heave = m.allocation * thrusts({0, 0, 0, 0, 1, 1});
  EXPECT_NEAR(heave(kHeave), -2.0, 1e-12);
  EXPECT_LT(heave.tail<3>().cwiseAbs().maxCoeff(), 1e-12);
}

/// Loads text as a vehicle file and returns the VehicleFileError it raises (fails if none).
VehicleFileError load_error(const std::string& text) {
  TempDir dir;
  const std::string path = dir.file("v.yaml");
  write_text(path, text);
  try {
    load_vehicle_file(path);
  } catch (const VehicleFileError& e) {
    return e;
  }
  ADD_FAILURE() << "the vehicle file was accepted";
  return VehicleFileError(path, "", "");
}

/// The standard BlueROV2's text with its vertical thrusters turned to push forward.
std::string bluerov2_without_vertical_thrusters() {
  std::string text = read_text(vehicle_path("bluerov2.yaml"));
  const std::string up = "direction_body: [0.0, 0.0, -1.0]";
  int replaced = 0;
  for (auto at = find_in_data(text, up); at != std::string::npos;
       at = find_in_data(text, up), ++replaced) {
    text.replace(at, up.size(), "direction_body: [1.0, 0.0, 0.0]");
  }
  EXPECT_EQ(replaced, 2);
  return text;
}

TEST(VehicleAuthority, NoHeaveIsRefusedNamingHeave) {
  const VehicleFileError e = load_error(bluerov2_without_vertical_thrusters());
  EXPECT_EQ(e.field(), "thrusters") << e.what();
  EXPECT_NE(std::string(e.what()).find("no authority in heave:"), std::string::npos) << e.what();
  std::cout << "[ message  ] " << e.what() << "\n";
}

/// Points thrusters [first, last) radially: along their position's horizontal projection. Then
/// r x d has no z component: those thrusters give no yaw moment and no heave force.
void turn_radial(VehicleModel& model, std::size_t first, std::size_t last) {
  for (std::size_t i = first; i < last; ++i) {
    Thruster& t = model.thrusters[i];
    t.direction_body = Vector3(t.position_body_m.x(), t.position_body_m.y(), 0.0).normalized();
  }
}

TEST(VehicleAuthority, NoYawIsRefusedNamingYaw) {
  VehicleModel model = bluerov2_standard();
  model.source_file = "in-code";
  turn_radial(model, 0, 4);  // T1..T4; T5, T6 still push up
  try {
    finalize_vehicle_model(model);
    FAIL() << "a vehicle without yaw authority was accepted";
  } catch (const VehicleFileError& e) {
    EXPECT_EQ(e.file(), "in-code");
    EXPECT_EQ(e.field(), "thrusters") << e.what();
    EXPECT_NE(std::string(e.what()).find("no authority in yaw:"), std::string::npos) << e.what();
    std::cout << "[ message  ] " << e.what() << "\n";
  }
}

TEST(VehicleAuthority, EveryMissingAxisIsNamed) {
  VehicleModel model = bluerov2_standard();
  turn_radial(model, 0, 6);  // every thruster horizontal and radial: surge and sway only
  try {
    finalize_vehicle_model(model);
    FAIL() << "a vehicle without heave and yaw authority was accepted";
  } catch (const VehicleFileError& e) {
    EXPECT_NE(std::string(e.what()).find("no authority in heave, yaw:"), std::string::npos)
        << e.what();
  }
}

// ---- Validation: corrupted copies of nessie7.yaml. -------------------------------------

struct Corruption {
  std::string label;
  std::string from;   ///< text to find in nessie7.yaml (must occur)
  std::string to;     ///< replacement
  std::string field;  ///< expected VehicleFileError::field()
};

void PrintTo(const Corruption& c, std::ostream* os) { *os << c.label; }

class CorruptedVehicleFile : public ::testing::TestWithParam<Corruption> {};

TEST_P(CorruptedVehicleFile, NamesTheField) {
  const Corruption& c = GetParam();
  std::string text = read_text(vehicle_path("nessie7.yaml"));
  const auto at = find_in_data(text, c.from);
  ASSERT_NE(at, std::string::npos) << "corruption target not found: " << c.from;
  text.replace(at, c.from.size(), c.to);
  TempDir dir;
  const std::string path = dir.file("corrupt.yaml");
  write_text(path, text);
  try {
    load_vehicle_file(path);
    FAIL() << "no error for " << c.label;
  } catch (const VehicleFileError& e) {
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
    std::cout << "[ message  ] " << e.what() << "\n";
  }
}

const std::string kT1Direction =
    "position_body_m: [-0.325, -0.185, 0.000]\n    direction_body: [1.0, 0.0, 0.0]";

INSTANTIATE_TEST_SUITE_P(
    Validation, CorruptedVehicleFile,
    ::testing::Values(
        Corruption{"missing field", "  mass_kg: 60.0\n", "", "rigid_body.mass_kg"},
        Corruption{"missing block",
                   "blow_up_limits:\n  max_linear_speed_mps: 20.0\n"
                   "  max_angular_rate_rad_s: 20.0\n  max_position_m: 10000.0\n",
                   "", "blow_up_limits"},
        Corruption{"wrong vector size", "cog_body_m: [0.0, 0.0, 0.06]", "cog_body_m: [0.0, 0.06]",
                   "rigid_body.cog_body_m"},
        Corruption{"negative mass", "mass_kg: 60.0", "mass_kg: -60.0", "rigid_body.mass_kg"},
        Corruption{"not a number", "mass_kg: 60.0", "mass_kg: sixty", "rigid_body.mass_kg"},
        Corruption{"non-finite", "mass_kg: 60.0", "mass_kg: .nan", "rigid_body.mass_kg"},
        Corruption{"zero inertia", "[0.675, 14.7875, 14.7875]", "[0.0, 14.7875, 14.7875]",
                   "rigid_body.inertia_kg_m2"},
        Corruption{"mass matrix not positive definite", "[0.675, 14.7875, 14.7875]",
                   "[[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
                   "rigid_body.inertia_kg_m2"},
        Corruption{"asymmetric inertia", "[0.675, 14.7875, 14.7875]",
                   "[[1.0, 0.1, 0.0], [0.0, 14.0, 0.0], [0.0, 0.0, 14.0]]",
                   "rigid_body.inertia_kg_m2"},
        Corruption{"unknown key (typo)", "  mass_kg: 60.0\n", "  mass_kg: 60.0\n  mas_kg: 61.0\n",
                   "rigid_body.mas_kg"},
        Corruption{"unknown top-level key", "name: nessie7\n", "name: nessie7\ncolour: yellow\n",
                   "colour"},
        // Found by fuzz_vehicle_yaml: a complex key ended the process (uncaught yaml-cpp error).
        Corruption{"complex key", "  mass_kg: 60.0\n", "  mass_kg: 60.0\n  ? [a, b]\n  : 1\n",
                   "rigid_body"},
        Corruption{"bad integrator", "integrator: rk4", "integrator: rk5",
                   "integration.integrator"},
        Corruption{"substeps < 1", "substeps: 10", "substeps: 0", "integration.substeps"},
        Corruption{"control step <= 0", "control_step_s: 0.1", "control_step_s: 0.0",
                   "integration.control_step_s"},
        Corruption{"damping of the wrong sign", "[-31.8086,", "[31.8086,",
                   "hydrodynamics.quadratic_damping[0]"},
        Corruption{"added mass of the wrong sign", "[-6.0,", "[6.0,",
                   "hydrodynamics.added_mass_derivatives[0]"},
        Corruption{"zero thruster direction", kT1Direction,
                   "position_body_m: [-0.325, -0.185, 0.000]\n    direction_body: [0.0, 0.0, 0.0]",
                   "thrusters[0].direction_body"},
        Corruption{"thruster direction far from unit", kT1Direction,
                   "position_body_m: [-0.325, -0.185, 0.000]\n    direction_body: [2.0, 0.0, 0.0]",
                   "thrusters[0].direction_body"},
        Corruption{"boolean expected", "added_mass_coriolis: false", "added_mass_coriolis: maybe",
                   "hydrodynamics.added_mass_coriolis"},
        Corruption{"both buoyancy and volume", "buoyancy_n: 589.6",
                   "buoyancy_n: 589.6\n  displaced_volume_m3: 0.058", "hydrostatics.buoyancy_n"},
        // Surge, heave and yaw are required (controlled_axes): with the vertical thrusters
        // turned to surge, nothing drives heave.
        Corruption{"no heave authority: vertical thrusters turned to surge",
                   "    direction_body: [0.0, 0.0, 1.0]\n  - name: T6_vertical_front\n"
                   "    position_body_m: [0.435, 0.000, 0.075]\n"
                   "    direction_body: [0.0, 0.0, 1.0]",
                   "    direction_body: [1.0, 0.0, 0.0]\n  - name: T6_vertical_front\n"
                   "    position_body_m: [0.435, 0.000, 0.075]\n"
                   "    direction_body: [1.0, 0.0, 0.0]",
                   "thrusters"},
        Corruption{"negative max thrust", "max_thrust_n: 39.24", "max_thrust_n: -39.24",
                   "thruster_dynamics.max_thrust_n"}));

TEST(VehicleFileValidation, NearUnitDirectionIsNormalised) {
  std::string text = read_text(vehicle_path("nessie7.yaml"));
  const std::string from = "direction_body: [1.0, 0.0, 0.0]";
  text.replace(find_in_data(text, from), from.size(), "direction_body: [1.004, 0.0, 0.0]");
  TempDir dir;
  write_text(dir.file("v.yaml"), text);
  const VehicleModel m = load_vehicle_file(dir.file("v.yaml"));
  EXPECT_DOUBLE_EQ(m.thrusters[0].direction_body.norm(), 1.0);
  EXPECT_DOUBLE_EQ(m.allocation(0, 0), 1.0);
}

TEST(VehicleFileValidation, TooManyThrusters) {
  std::string text = read_text(vehicle_path("nessie7.yaml"));
  std::string extra;
  for (int i = 0; i < kMaxThrusters - 5; ++i) {
    extra += "  - name: extra_" + std::to_string(i) +
             "\n    position_body_m: [0.0, 0.0, 0.0]\n    direction_body: [1.0, 0.0, 0.0]\n";
  }
  const std::string anchor = "\nthruster_dynamics:";
  text.insert(text.find(anchor), "\n" + extra);
  TempDir dir;
  write_text(dir.file("v.yaml"), text);
  try {
    load_vehicle_file(dir.file("v.yaml"));
    FAIL() << "13 thrusters accepted";
  } catch (const VehicleFileError& e) {
    EXPECT_EQ(e.field(), "thrusters") << e.what();
    EXPECT_NE(std::string(e.what()).find("at most 12"), std::string::npos) << e.what();
  }
}

TEST(VehicleFileValidation, MissingFileAndSyntaxError) {
  TempDir dir;
  EXPECT_THROW(load_vehicle_file(dir.file("absent.yaml")), VehicleFileError);
  // A directory (as `vehicle: .` in a run file names): an error naming it, not a stream failure.
  try {
    load_vehicle_file(dir.file("."));
    FAIL() << "a directory accepted";
  } catch (const VehicleFileError& e) {
    EXPECT_EQ(e.field(), "(file)") << e.what();
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
  write_text(dir.file("bad.yaml"), "name: [unclosed\n");
  try {
    load_vehicle_file(dir.file("bad.yaml"));
    FAIL();
  } catch (const VehicleFileError& e) {
    EXPECT_EQ(e.field(), "(syntax)");
  }
}

TEST(VehicleFileValidation, FinalizeChecksModelsBuiltInCode) {
  VehicleModel model = nessie();
  model.source_file = "in-code";
  model.mass_kg = 0.0;
  try {
    finalize_vehicle_model(model);
    FAIL();
  } catch (const VehicleFileError& e) {
    EXPECT_EQ(e.field(), "rigid_body.mass_kg");
    EXPECT_EQ(e.file(), "in-code");
  }
  model = nessie();
  model.thrusters.clear();
  EXPECT_THROW(finalize_vehicle_model(model), VehicleFileError);
}

}  // namespace
}  // namespace auvrl::sim::test
