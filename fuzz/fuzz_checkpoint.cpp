// The checkpoint loader: bytes as the only checkpoint file of a learner's directory, restored
// by LearnerNode::resume() (the code auv_learner --resume runs: learner state, both networks
// and their targets, Adam, the replay buffer, the hindsight index). A damaged file must be
// refused with std::runtime_error; a restored learner then polls once (updates sample the
// restored buffer and relabel with the restored index).
#include <filesystem>

#include "fuzz/fuzz_configs.hpp"
#include "fuzz/fuzz_util.hpp"
#include "learner/learner_node.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const learner::LearnerNodeConfig config = [] {
    learner::LearnerNodeConfig c = fuzz::small_learner_config();
    c.checkpoint_dir = fuzz::scratch_dir() + "/checkpoints";
    c.checkpoint_period_s = 1e9;
    std::filesystem::create_directories(c.checkpoint_dir);
    return c;
  }();
  static fuzz::NullStream log;
  fuzz::write_file(config.checkpoint_dir + "/checkpoint-000000000001.ckpt", data, size);
  learner::LearnerNode node(config, fuzz::in_process_transport(), log);
  try {
    node.resume();
  } catch (const std::runtime_error&) {
    return 0;
  }
  node.poll(0);
  fuzz::in_process_transport().drain();
  return 0;
}
