// auv_learner's input: EXPERIENCE, WEIGHTS_REQUEST and EPISODE messages as raw bytes, published
// on the in-process transport and handled by LearnerNode (the code auv_learner runs): batches
// go into the replay buffer and hindsight index, updates run, weights are broadcast. Small
// networks and buffer so that an input runs in microseconds; the paper's state layout. Sound
// experience of other sizes stops the learner (UnrecoverableFault): the input ends there. Bit 6
// of the first byte picks the reproducible mode (rounds collected from two actors, weights by
// round and index, requests for a round's weights); experience of the other mode stops it too.
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/weights_request_t.hpp>

#include "common/channels.hpp"
#include "common/unrecoverable.hpp"
#include "fuzz/fuzz_configs.hpp"
#include "fuzz/fuzz_util.hpp"
#include "learner/learner_node.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const learner::LearnerNodeConfig asynchronous = fuzz::small_learner_config();
  static const learner::LearnerNodeConfig reproducible = fuzz::small_reproducible_learner_config();
  static fuzz::NullStream log;
  transport::Transport& t = fuzz::in_process_transport();
  learner::LearnerNode node(size > 0 && (data[0] & 0x40) ? reproducible : asynchronous, t, log);
  for (const fuzz::Record& r : fuzz::read_records(data, size)) {
    std::vector<std::uint8_t> bytes;
    std::string channel;
    switch ((r.selector & 0x7F) % 3) {
      case 0:
        channel = channels::kExperience;
        bytes = fuzz::message_bytes<auvrl_lcm::experience_batch_t>(r);
        break;
      case 1:
        channel = channels::kWeightsRequest;
        bytes = fuzz::message_bytes<auvrl_lcm::weights_request_t>(r);
        break;
      default:
        channel = channels::kEpisode;
        bytes = fuzz::message_bytes<auvrl_lcm::episode_report_t>(r);
        break;
    }
    t.publish(channel, bytes.data(), bytes.size());
    try {
      node.poll(0);
    } catch (const UnrecoverableFault&) {
      break;  // sound experience of other sizes: the learner stops, as designed
    }
  }
  t.drain();
  return 0;
}
