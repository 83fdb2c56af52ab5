// auv_actor's lockstep input: the states its simulator answers with. An ActorNode (the code
// auv_actor runs, before any weights: exploration noise only) runs one episode on the
// in-process bus against a stand-in simulator that answers each reset and command from the
// input's records, in order: a record with selector bit 0 set, or one that does not decode as
// a vehicle_state_t, is published as it is (a stray or broken datagram) and the next one is
// taken; the first that decodes is made the answer (the request's vehicle id and sequence
// number; with selector bit 1 clear, also the expected vehicle's name, thruster count and file
// CRC-32). When the records run out the answer is a blow-up, which ends the episode. A state that
// names another vehicle must end the input with UnrecoverableFault (auv_actor exits naming it); any
// other exception, crash or undefined behaviour is a finding.
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "agent/actor_node.hpp"
#include "common/channels.hpp"
#include "common/unrecoverable.hpp"
#include "fuzz/fuzz_util.hpp"
#include "sim/vehicle_model.hpp"

using namespace auvrl;

namespace {

/// auv_actor for vehicle 0 of Nessie VII with the preset's state layout and reward, exploring
/// with Gaussian noise; episodes of at most 100 steps.
agent::ActorNodeConfig lockstep_actor_config() {
  agent::ActorNodeConfig c;
  c.vehicle =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml").facts();
  task::apply_vehicle(c.vehicle, c.task);
  c.task.layout = task::StateLayout::kExtendedThrust;
  c.task.reward = task::RewardKind::kShaped;
  c.task.max_steps = 100;
  c.noise = agent::ExplorationNoise::Kind::kGaussian;
  c.weights_request_period_s = 3600;
  return c;
}

/// Answers the actor's requests from the input's records, in order.
class StandInSimulator {
 public:
  StandInSimulator(transport::Transport& bus, const VehicleFacts& facts,
                   const std::vector<fuzz::Record>& records)
      : bus_(bus), facts_(facts), records_(records) {
    subscriptions_.push_back(transport::subscribe<auvrl_lcm::vehicle_reset_t>(
        bus, channels::sim_reset(0),
        [this](const std::string&, const auvrl_lcm::vehicle_reset_t& m) { answer(m.seq); }));
    subscriptions_.push_back(transport::subscribe<auvrl_lcm::thruster_cmd_t>(
        bus, channels::sim_command(0),
        [this](const std::string&, const auvrl_lcm::thruster_cmd_t& m) { answer(m.seq); }));
  }
  ~StandInSimulator() {
    for (const transport::SubscriptionId id : subscriptions_) bus_.unsubscribe(id);
  }
  StandInSimulator(const StandInSimulator&) = delete;
  StandInSimulator& operator=(const StandInSimulator&) = delete;

 private:
  /// Publishes the records up to the first that decodes as a state not marked stray, made the
  /// answer to request seq; when the records run out, a state with a blow-up status (the
  /// episode ends without waiting for a timeout).
  void answer(std::int64_t seq) {
    while (next_ < records_.size()) {
      const fuzz::Record& r = records_[next_++];
      const std::vector<std::uint8_t> bytes = fuzz::message_bytes<auvrl_lcm::vehicle_state_t>(r);
      auvrl_lcm::vehicle_state_t state;
      if ((r.selector & 1) != 0 || !transport::decode_exact(bytes.data(), bytes.size(), state)) {
        bus_.publish(channels::sim_state(0), bytes.data(), bytes.size());
        continue;
      }
      publish_answer(state, seq, (r.selector & 2) != 0);
      return;
    }
    auvrl_lcm::vehicle_state_t end{};
    end.status = auvrl_lcm::vehicle_state_t::STATUS_POSITION_LIMIT;
    publish_answer(end, seq, false);
  }

  void publish_answer(auvrl_lcm::vehicle_state_t& state, std::int64_t seq, bool keep_identity) {
    state.vehicle_id = 0;
    state.seq = seq;
    if (!keep_identity) {
      state.vehicle_name = facts_.name;
      state.num_thrusters = static_cast<std::int8_t>(facts_.num_thrusters());
      state.vehicle_file_crc32 = static_cast<std::int32_t>(facts_.file_crc32);
      state.thrust_realised_n.resize(static_cast<std::size_t>(state.num_thrusters));
    }
    const std::vector<std::uint8_t> bytes = fuzz::encode(state);
    bus_.publish(channels::sim_state(0), bytes.data(), bytes.size());
  }

  transport::Transport& bus_;
  const VehicleFacts& facts_;
  const std::vector<fuzz::Record>& records_;
  std::size_t next_ = 0;
  std::vector<transport::SubscriptionId> subscriptions_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const agent::ActorNodeConfig config = lockstep_actor_config();
  transport::Transport& bus = fuzz::in_process_transport();
  static fuzz::NullStream log;
  const std::vector<fuzz::Record> records = fuzz::read_records(data, size);
  StandInSimulator simulator(bus, config.vehicle, records);
  agent::ActorNode actor(config, bus, log);
  try {
    actor.run_one_episode();
  } catch (const UnrecoverableFault&) {
    // auv_actor exits here, naming the vehicle it met
  }
  bus.drain();  // nothing left for the next input
  return 0;
}
