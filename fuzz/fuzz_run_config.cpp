// The run configuration parsers (config/presets/*.yaml): bytes as a run file, read by the
// learner's and the actor's readers (common/config, common/task/task_yaml, learner_config,
// actor_config). A bad file must be refused with config::ConfigError (file, key, line), or a
// vehicle: it names that cannot be loaded with sim::VehicleFileError (file, field); any other
// exception is a finding.
#include "agent/actor_config.hpp"
#include "fuzz/fuzz_util.hpp"
#include "learner/learner_config.hpp"
#include "sim/vehicle_model.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = fuzz::scratch_dir() + "/run.yaml";
  fuzz::write_file(path, data, size);
  try {
    learner::LearnerNodeConfig config;
    learner::read_learner_config_file(path, config);
  } catch (const config::ConfigError&) {
  } catch (const sim::VehicleFileError&) {
  }
  try {
    agent::ActorNodeConfig config;
    agent::read_actor_config_file(path, config);
  } catch (const config::ConfigError&) {
  }
  return 0;
}
