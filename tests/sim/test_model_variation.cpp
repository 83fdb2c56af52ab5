// The same vehicle, differently wrong (sim::vary_model): each departure changes what it names and
// nothing else, the identity changes nothing, and bad values are refused naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "sim/dynamics.hpp"
#include "sim/model_variation.hpp"

namespace {

using namespace auvrl::sim;

VehicleModel nessie() {
  return load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
}

TEST(ModelVariation, EachDepartureChangesWhatItNames) {
  const VehicleModel nominal = nessie();
  ModelVariation v;
  EXPECT_TRUE(v.is_identity());
  const VehicleModel same = vary_model(nominal, v);
  EXPECT_EQ(same.mass_total, nominal.mass_total);
  EXPECT_EQ(same.buoyancy_n, nominal.buoyancy_n);

  v.quadratic_damping_scale = 1.5;
  v.added_mass_scale = 1.5;
  v.mass_scale = 1.2;
  v.thruster_lag_time_constant_s = 0.6;
  v.extra_buoyancy_n = 19.6;
  EXPECT_FALSE(v.is_identity());
  const VehicleModel m = vary_model(nominal, v);
  EXPECT_EQ(m.quadratic_damping, 1.5 * nominal.quadratic_damping);
  EXPECT_EQ(m.added_mass_derivatives, 1.5 * nominal.added_mass_derivatives);
  EXPECT_DOUBLE_EQ(m.mass_kg, 1.2 * nominal.mass_kg);
  EXPECT_TRUE(m.inertia_kg_m2.isApprox(1.2 * nominal.inertia_kg_m2));
  // Ballasted to the file's trim, plus the extra buoyancy.
  EXPECT_NEAR(m.buoyancy_n - m.weight_n, nominal.buoyancy_n - nominal.weight_n + 19.6, 1e-9);
  EXPECT_TRUE(m.thruster_dynamics.lag_enabled);
  EXPECT_EQ(m.thruster_dynamics.lag_time_constant_s, 0.6);
  // The derived matrices follow: more mass, more added mass.
  EXPECT_GT(m.mass_total(0, 0), nominal.mass_total(0, 0));
  EXPECT_EQ(m.name, nominal.name);
  EXPECT_EQ(m.file_crc32, nominal.file_crc32);
}

TEST(ModelVariation, MoreDragSlowsTheVehicleAndExtraBuoyancyLiftsIt) {
  const VehicleModel nominal = nessie();
  ModelVariation drag;
  drag.quadratic_damping_scale = 1.5;
  ModelVariation lift;
  lift.extra_buoyancy_n = 19.6;
  const auto run = [&](const VehicleModel& model) {
    VehicleState state = make_state(model, ResetSettings{});
    ThrusterVector thrust = ThrusterVector::Zero(model.num_thrusters());
    thrust.head(2).setConstant(model.thruster_dynamics.max_thrust_n);  // both surge thrusters
    for (int i = 0; i < 200; ++i) step(model, state, thrust);
    return state;
  };
  const VehicleState base = run(nominal), slow = run(vary_model(nominal, drag)),
                     up = run(vary_model(nominal, lift));
  EXPECT_LT(slow.nu[0], base.nu[0] * 0.9);
  EXPECT_LT(up.eta[2], base.eta[2] - 0.5) << "NED z: rising is smaller";
}

TEST(ModelVariation, BadValuesAreRefusedNamingTheField) {
  const VehicleModel nominal = nessie();
  ModelVariation v;
  v.mass_scale = 0.0;
  try {
    vary_model(nominal, v);
    FAIL() << "a zero mass scale was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mass_scale"), std::string::npos) << e.what();
  }
  v = ModelVariation{};
  v.extra_buoyancy_n = std::nan("");
  EXPECT_THROW(vary_model(nominal, v), std::invalid_argument);
  // In range, but the model it leaves weighs nothing (found by fuzz_sim_server).
  v = ModelVariation{};
  v.mass_scale = 1e-320;
  EXPECT_THROW(vary_model(nominal, v), std::invalid_argument);
  v.mass_scale = 1e308;
  EXPECT_THROW(vary_model(nominal, v), std::invalid_argument);
}

}  // namespace
