// The vehicle file parser (auv_sim, the actor's evaluation): bytes as a vehicle YAML file,
// loaded with sim::load_vehicle_file; an accepted model then takes one control step. A bad
// file must be refused with VehicleFileError.
#include "fuzz/fuzz_util.hpp"
#include "sim/dynamics.hpp"
#include "sim/vehicle_model.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::scratch_dir() + "/vehicle.yaml";
  fuzz::write_file(path, data, size);
  try {
    const sim::VehicleModel model = sim::load_vehicle_file(path);
    sim::VehicleState state = sim::make_state(model, sim::ResetSettings{});
    sim::step(model, state, sim::ThrusterVector::Constant(model.num_thrusters(), 10.0));
  } catch (const sim::VehicleFileError&) {
    // Refused naming the file and the field: what a bad file must give. Any other exception
    // (a yaml-cpp one escaping, say) is a finding: libFuzzer reports it as a crash.
  }
  return 0;
}
