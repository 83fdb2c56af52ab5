// Writes the seed corpora of the fuzz targets (fuzz/corpus/<target>/) and the LCM dictionary
// (fuzz/lcm.dict) with the real encoders, so the seeds are what the processes really exchange:
//   build-fuzz/bin/fuzz_make_corpus fuzz
// Deterministic: the same build writes the same bytes.
#include <algorithm>
#include <array>
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/mission_t.hpp>
#include <auvrl_lcm/policy_summary_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>
#include <auvrl_lcm/weights_request_t.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/channels.hpp"
#include "common/nn/serialize.hpp"
#include "fuzz/fuzz_configs.hpp"
#include "fuzz/fuzz_util.hpp"
#include "learner/checkpoint.hpp"
#include "logger/event_log.hpp"
#include "sim/vehicle_model.hpp"

using namespace auvrl;
namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<std::uint8_t>;

std::string out_dir;

void write_seed(const std::string& target, const std::string& name, const Bytes& bytes) {
  const fs::path dir = fs::path(out_dir) / "corpus" / target;
  fs::create_directories(dir);
  fuzz::write_file((dir / name).string(), bytes.data(), bytes.size());
}

Bytes file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Body without the fingerprint (for records with the "prepend fingerprint" bit).
Bytes body(const Bytes& encoded) { return Bytes(encoded.begin() + 8, encoded.end()); }

auvrl_lcm::vehicle_reset_t reset_message(int vehicle_id) {
  auvrl_lcm::vehicle_reset_t m{};
  m.vehicle_id = vehicle_id;
  m.seq = 1;
  m.seed = 7;
  m.position_ned_m[2] = 5.0;
  m.num_thrusters = 6;
  m.thruster_efficiency.assign(6, 1.0);
  m.current_gm_time_constant_s = 10.0;
  m.current_gm_sigma_mps = 0.05;
  m.noise_position_m = 0.01;
  return m;
}

auvrl_lcm::thruster_cmd_t command_message(int vehicle_id, std::int64_t seq, double thrust_n) {
  auvrl_lcm::thruster_cmd_t m{};
  m.vehicle_id = vehicle_id;
  m.seq = seq;
  m.num_thrusters = 6;
  m.thrust_n.assign(6, thrust_n);
  return m;
}

auvrl_lcm::thruster_fault_t fault_message(int vehicle_id) {
  auvrl_lcm::thruster_fault_t m{};
  m.vehicle_id = vehicle_id;
  m.num_thrusters = 6;
  m.thruster_efficiency = {0.1, 1, 1, 1, 1, 1};
  return m;
}

void sim_server_seeds() {
  // Selector: kind (0 command, 1 reset, 2 fault) + 3 * id index (ids 0, 1, 2, 99999); bit 6
  // instead: a current.
  Bytes episode;
  fuzz::append_record(episode, 1, fuzz::encode(reset_message(0)));
  for (int k = 2; k < 5; ++k)
    fuzz::append_record(episode, 0, fuzz::encode(command_message(0, k, 20)));
  fuzz::append_record(episode, 2, fuzz::encode(fault_message(0)));
  fuzz::append_record(episode, 0, fuzz::encode(command_message(0, 5, -20)));
  fuzz::append_record(episode, 0, fuzz::encode(command_message(0, 5, -20)));  // a retry
  write_seed("fuzz_sim_server", "reset_steps_fault", episode);

  Bytes second;
  fuzz::append_record(second, 1 + 3, fuzz::encode(reset_message(1)));
  fuzz::append_record(second, 0 + 3, fuzz::encode(command_message(1, 2, 39.24)));
  fuzz::append_record(second, 0 + 6, fuzz::encode(command_message(2, 2, 1)));  // unknown id
  write_seed("fuzz_sim_server", "second_vehicle", second);

  Bytes bodies;  // fingerprints added by the target (selector bit 7)
  fuzz::append_record(bodies, 0x80 | 1, body(fuzz::encode(reset_message(0))));
  fuzz::append_record(bodies, 0x80 | 0, body(fuzz::encode(command_message(0, 2, NAN))));
  fuzz::append_record(bodies, 0x80 | 2, body(fuzz::encode(fault_message(0))));
  write_seed("fuzz_sim_server", "bodies", bodies);

  Bytes current;  // selector bit 6: a current
  auvrl_lcm::water_current_t flow{};
  flow.current_constant_ned_mps[0] = 0.3;
  fuzz::append_record(current, 1, fuzz::encode(reset_message(0)));
  fuzz::append_record(current, 0x40, fuzz::encode(flow));
  fuzz::append_record(current, 0, fuzz::encode(command_message(0, 2, 10)));
  flow.current_constant_ned_mps[1] = NAN;
  fuzz::append_record(current, 0x40, fuzz::encode(flow));
  write_seed("fuzz_sim_server", "reset_current_step", current);
}

auvrl_lcm::experience_batch_t experience(int state_dim, int action_dim, int n, int actor_id,
                                         std::int64_t batch_seq, std::int64_t episode_id) {
  auvrl_lcm::experience_batch_t m{};
  m.actor_id = actor_id;
  m.batch_seq = batch_seq;
  m.state_dim = state_dim;
  m.action_dim = action_dim;
  m.num_transitions = n;
  for (int i = 0; i < n; ++i) {
    const float f = 0.01f * static_cast<float>(i + 1);
    m.states.emplace_back(static_cast<std::size_t>(state_dim), f);
    m.actions.emplace_back(static_cast<std::size_t>(action_dim), 0.5f - f);
    m.rewards.push_back(-1.0f - f);
    m.next_states.emplace_back(static_cast<std::size_t>(state_dim), f + 0.01f);
    m.terminal.push_back(i + 1 == n ? 1 : 0);
    m.achieved_position_ned_m.push_back({f, 2 * f, 5.0f});
    m.goal_ned_m.push_back({7.0f, 6.0f, 10.0f});
    m.episode_id.push_back(episode_id);
    m.step_index.push_back(i);
  }
  return m;
}

void learner_seeds(const learner::LearnerNodeConfig& config) {
  const int sd = config.ddpg.state_dim, ad = config.ddpg.action_dim;
  auvrl_lcm::weights_request_t request{};
  request.actor_id = 1;
  request.have_version = -1;
  auvrl_lcm::episode_report_t report{};
  report.actor_id = 1;
  report.episode_id = 1;
  report.length_steps = 6;
  report.beta_m = 1.5;
  report.goal_ned_m[0] = 7;

  Bytes run;  // selector: 0 experience, 1 weights request, 2 episode
  fuzz::append_record(run, 1, fuzz::encode(request));
  fuzz::append_record(run, 0, fuzz::encode(experience(sd, ad, 6, 1, 1, 1)));
  fuzz::append_record(run, 2, fuzz::encode(report));
  fuzz::append_record(run, 0, fuzz::encode(experience(sd, ad, 3, 2, 1, 1)));
  write_seed("fuzz_learner_node", "request_batches_episode", run);

  Bytes bodies;
  fuzz::append_record(bodies, 0x80, body(fuzz::encode(experience(sd, ad, 5, 0, 1, 3))));
  fuzz::append_record(bodies, 0x80 | 2, body(fuzz::encode(report)));
  write_seed("fuzz_learner_node", "bodies", bodies);

  // The reproducible mode (bit 6 of the first byte): round 1 from actors 1 and 0 (two batches),
  // a resend, then requests for the round's weights.
  const auto round_batch = [&](int actor, int index, int count, int n) {
    auvrl_lcm::experience_batch_t m = experience(sd, ad, n, actor, index + 1, 1);
    m.round = 1;
    m.round_batch = index;
    m.round_batches = count;
    m.round_episodes = 1;
    return m;
  };
  auvrl_lcm::weights_request_t want = request;
  want.want_round = 1;
  want.want_index = 1;
  Bytes rounds;
  // 0x42: bit 6 for the mode, and (0x42 & 0x7F) % 3 == 0: experience.
  fuzz::append_record(rounds, 0x42, fuzz::encode(round_batch(1, 0, 1, 6)));
  fuzz::append_record(rounds, 0, fuzz::encode(round_batch(0, 1, 2, 4)));
  fuzz::append_record(rounds, 0, fuzz::encode(round_batch(0, 1, 2, 4)));
  fuzz::append_record(rounds, 0, fuzz::encode(round_batch(0, 0, 2, 5)));
  fuzz::append_record(rounds, 1, fuzz::encode(want));
  write_seed("fuzz_learner_node", "reproducible_round", rounds);
}

void checkpoint_seeds(learner::LearnerNodeConfig config) {
  const std::string dir = fuzz::scratch_dir() + "/make-checkpoint";
  config.checkpoint_dir = dir;
  fuzz::NullStream log;
  transport::Transport& t = fuzz::in_process_transport();
  learner::LearnerNode node(config, t, log);
  transport::publish(t, channels::kExperience,
                     experience(config.ddpg.state_dim, config.ddpg.action_dim, 6, 1, 1, 1));
  for (int i = 0; i < 5; ++i) node.poll(0);
  const std::string path = node.checkpoint();
  t.drain();
  if (path.empty()) throw std::runtime_error("no checkpoint written");
  write_seed("fuzz_checkpoint", "after_6_transitions", file_bytes(path));
}

nn::Mlp small_network(int in, int out, int extra, nn::Activation output) {
  nn::MlpSpec spec;
  spec.input_dim = in;
  spec.hidden = {8, 8};
  spec.output_dim = out;
  spec.extra_input_dim = extra;
  spec.extra_input_layer = extra > 0 ? 1 : 0;
  spec.output_activation = output;
  nn::Mlp net(spec, 1);
  for (Eigen::Index i = 0; i < net.num_params(); ++i) {
    net.params()[i] = 0.01f * static_cast<float>((i * 7919) % 101 - 50);
  }
  return net;
}

auvrl_lcm::policy_weights_t weights_message(const nn::Mlp& net, std::int64_t version) {
  auvrl_lcm::policy_weights_t m{};
  m.version = version;
  m.beta_m = 1.5;
  m.episodes = 3;
  m.updates_owed = 2.0;
  const Bytes bytes = nn::network_to_bytes(net);
  m.num_bytes = static_cast<std::int32_t>(bytes.size());
  m.network.assign(bytes.begin(), bytes.end());
  return m;
}

void network_and_weights_seeds(const learner::LearnerNodeConfig& config) {
  const nn::Mlp fixed = small_network(4, 2, 0, nn::Activation::kTanh);
  write_seed("fuzz_network", "fixed_4_8_8_2", nn::network_to_bytes(fixed));
  write_seed("fuzz_network", "critic_like",
             nn::network_to_bytes(small_network(5, 1, 2, nn::Activation::kIdentity)));

  const nn::Mlp actor =
      small_network(config.ddpg.state_dim, config.ddpg.action_dim, 0, nn::Activation::kTanh);
  Bytes run;
  fuzz::append_record(run, 0, fuzz::encode(weights_message(actor, 1)));
  fuzz::append_record(run, 0, fuzz::encode(weights_message(actor, 1)));  // same version
  fuzz::append_record(run, 0x80, body(fuzz::encode(weights_message(actor, 2))));
  write_seed("fuzz_actor_weights", "versions_1_1_2", run);
}

void logger_seeds(const learner::LearnerNodeConfig& config) {
  const auto seed = [](const std::string& name, const Bytes& encoded) {
    Bytes b{1};  // option byte: byte arrays as blobs
    b.insert(b.end(), encoded.begin(), encoded.end());
    write_seed("fuzz_logger_decode", name, b);
  };
  seed("thruster_cmd_t", fuzz::encode(command_message(0, 3, 12.5)));
  seed("thruster_fault_t", fuzz::encode(fault_message(0)));
  seed("vehicle_reset_t", fuzz::encode(reset_message(0)));
  auvrl_lcm::vehicle_state_t state{};
  state.num_thrusters = 6;
  state.thrust_realised_n.assign(6, 3.0);
  seed("vehicle_state_t", fuzz::encode(state));
  seed("experience_batch_t", fuzz::encode(experience(4, 2, 2, 0, 1, 1)));
  auvrl_lcm::episode_report_t report{};
  report.actor_id = 2;
  seed("episode_report_t", fuzz::encode(report));
  seed("policy_weights_t",
       fuzz::encode(weights_message(small_network(3, 2, 0, nn::Activation::kTanh), 4)));
  auvrl_lcm::policy_summary_t summary{};
  summary.architecture = "in=3 hidden=8-8 out=2 (tanh)";
  seed("policy_summary_t", fuzz::encode(summary));
  auvrl_lcm::weights_request_t request{};
  seed("weights_request_t", fuzz::encode(request));
  auvrl_lcm::learner_stats_t stats{};
  stats.algo = "ddpg";
  seed("learner_stats_t", fuzz::encode(stats));
  auvrl_lcm::sim_heartbeat_t sim_hb{};
  sim_hb.vehicle_file = "nessie7.yaml";
  seed("sim_heartbeat_t", fuzz::encode(sim_hb));
  auvrl_lcm::logger_heartbeat_t log_hb{};
  log_hb.log_dir = "runs/x";
  log_hb.num_channels = 2;
  log_hb.channel = {"EPISODE", "EXPERIENCE"};
  log_hb.received = {1, 2};
  log_hb.written = {1, 2};
  log_hb.throttled = {0, 0};
  seed("logger_heartbeat_t", fuzz::encode(log_hb));
  (void)config;
}

void event_log_seeds() {
  const std::string dir = fuzz::scratch_dir() + "/make-log";
  std::string path;
  {
    logger::RotatingLogWriter writer(dir, "seed", 1 << 20);
    const Bytes cmd = fuzz::encode(command_message(0, 3, 1.0));
    const Bytes reset = fuzz::encode(reset_message(0));
    writer.write("SIM_RESET_0", reset.data(), reset.size(), 1000);
    writer.write("SIM_CMD_0", cmd.data(), cmd.size(), 2000);
    writer.write("SIM_CMD_0", cmd.data(), cmd.size(), 3000);
    writer.close();
    path = writer.files().at(0);
  }
  Bytes log = file_bytes(path);
  write_seed("fuzz_event_log", "three_events", log);
  // Damaged: the middle event's sync word broken, and the file cut inside the last event.
  Bytes damaged = log;
  damaged[static_cast<std::size_t>(logger::kEventHeaderSize) + 11 +
          reset_message(0).getEncodedSize()] ^= 0xFF;
  damaged.resize(damaged.size() - 7);
  write_seed("fuzz_event_log", "damaged", damaged);
}

void file_seeds() {
  const std::string config_dir = AUVRL_CONFIG_DIR;
  for (const char* v : {"nessie7", "nessie7_munk", "bluerov2_heavy", "bluerov2"}) {
    write_seed("fuzz_vehicle_yaml", v, file_bytes(config_dir + "/vehicles/" + v + ".yaml"));
  }
  for (const char* p : {"paper", "fast"}) {
    write_seed("fuzz_run_config", p, file_bytes(config_dir + "/presets/" + p + ".yaml"));
  }
  for (const char* m : {"test1", "test2", "fault", "tour", "tour_fault"}) {
    write_seed("fuzz_mission_yaml", m, file_bytes(config_dir + "/missions/" + m + ".yaml"));
  }
}

/// Nessie VII's facts (its name, file CRC and thrusters: what a state must announce).
const VehicleFacts& nessie7() {
  static const VehicleFacts facts =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml").facts();
  return facts;
}

/// What Nessie VII (vehicle 0) reports at `position_ned_m`, moving forward at 1 m/s with every
/// thruster giving thrust_n.
auvrl_lcm::vehicle_state_t state_message(const VehicleFacts& vehicle, std::int64_t seq,
                                         const std::array<double, 3>& position_ned_m,
                                         double thrust_n) {
  auvrl_lcm::vehicle_state_t m{};
  m.vehicle_id = 0;
  m.seq = seq;
  m.step_count = seq;
  m.sim_time_s = 0.1 * static_cast<double>(seq);
  for (int i = 0; i < 3; ++i) m.position_ned_m[i] = position_ned_m[static_cast<std::size_t>(i)];
  m.velocity_body_mps[0] = 1.0;
  m.vehicle_name = vehicle.name;
  m.vehicle_file_crc32 = static_cast<std::int32_t>(vehicle.file_crc32);
  m.num_thrusters = static_cast<std::int8_t>(vehicle.num_thrusters());
  m.thrust_realised_n.assign(static_cast<std::size_t>(vehicle.num_thrusters()), thrust_n);
  return m;
}

/// A mission for vehicle 0: a mission file's text without its vehicle: line.
auvrl_lcm::mission_t mission_message(const std::string& file) {
  std::ifstream in(file);
  auvrl_lcm::mission_t m{};
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("vehicle:", 0) != 0) m.yaml += line + "\n";
  }
  return m;
}

void controller_seeds() {
  const std::string config_dir = AUVRL_CONFIG_DIR;
  const VehicleFacts& vehicle = nessie7();
  // Selector: 0 a state, 1 a mission.
  Bytes run;
  fuzz::append_record(run, 0, fuzz::encode(state_message(vehicle, 0, {0, 0, 5}, 0)));
  fuzz::append_record(run, 0, fuzz::encode(state_message(vehicle, 1, {0.1, 0, 5}, 20)));
  fuzz::append_record(run, 0, fuzz::encode(state_message(vehicle, 2, {0.2, 0.1, 5.1}, 0)));
  fuzz::append_record(run, 1, fuzz::encode(mission_message(config_dir + "/missions/tour.yaml")));
  fuzz::append_record(run, 0, fuzz::encode(state_message(vehicle, 3, {0.3, 0.1, 5.1}, 20)));
  write_seed("fuzz_controller_node", "states_new_mission", run);

  Bytes bodies;  // fingerprints added by the target (selector bit 7)
  fuzz::append_record(bodies, 0x80, body(fuzz::encode(state_message(vehicle, 0, {7, 6, 10}, 0))));
  fuzz::append_record(bodies, 0x80, body(fuzz::encode(state_message(vehicle, 1, {7, 6, 10}, NAN))));
  fuzz::append_record(bodies, 0x81,
                      body(fuzz::encode(mission_message(config_dir + "/missions/test2.yaml"))));
  write_seed("fuzz_controller_node", "bodies", bodies);

  // 2026-11-29: a vehicle_name length of INT32_MIN made lcm-gen's decoder read 2 GB past the
  // message (cmake/LcmBoundLengths.cmake); the length field is the 4 bytes before the name.
  Bytes state = fuzz::encode(state_message(vehicle, 0, {0, 0, 5}, 0));
  const Bytes name_length = {0, 0, 0, static_cast<std::uint8_t>(vehicle.name.size() + 1)};
  auto at = std::search(state.begin(), state.end(), name_length.begin(), name_length.end());
  if (at == state.end()) throw std::runtime_error("no vehicle_name in the state's encoding");
  const Bytes int32_min = {0x80, 0, 0, 0};
  std::copy(int32_min.begin(), int32_min.end(), at);
  Bytes regression;
  fuzz::append_record(regression, 0, state);
  write_seed("fuzz_controller_node", "regression_string_length_int32_min", regression);
}

/// The controller's MISSION_STATUS after `elapsed_s` of a mission of `count` way-points.
auvrl_lcm::mission_status_t status_message(double elapsed_s, int index, int count) {
  auvrl_lcm::mission_status_t m{};
  m.mission_name = "tour_fault";
  m.controller = "policy";
  m.waypoint_index = index;
  m.waypoint_count = count;
  m.goal_ned_m[0] = 6;
  m.goal_ned_m[1] = 4;
  m.goal_ned_m[2] = 8;
  m.elapsed_s = elapsed_s;
  m.supervisor_state = auvrl_lcm::mission_status_t::STATE_ACTIVE;
  return m;
}

void mission_record_seeds() {
  const VehicleFacts& vehicle = nessie7();
  // Selector: 0 state, 1 command, 2 status, 3 fault, 4 current. A reset state, then the
  // controller's: a command answered by a state, its status, the way to the first way-point
  // [6, 4, 8] and a hold there, the mission's fault at 40 s and a current.
  Bytes run;
  fuzz::append_record(run, 0, fuzz::encode(state_message(vehicle, 0, {0, 0, 5}, 0)));
  fuzz::append_record(run, 4, fuzz::encode(auvrl_lcm::water_current_t{}));
  for (int k = 1; k <= 8; ++k) {
    fuzz::append_record(run, 1, fuzz::encode(command_message(0, k, 20)));
    const double f = k / 8.0;
    fuzz::append_record(run, 0,
                        fuzz::encode(state_message(vehicle, k, {6 * f, 4 * f, 5 + 3 * f}, 20)));
    fuzz::append_record(run, 2, fuzz::encode(status_message(0.1 * (k - 1), 0, 6)));
  }
  fuzz::append_record(run, 0, fuzz::encode(state_message(vehicle, 400, {6, 4, 8}, 0)));
  fuzz::append_record(run, 3, fuzz::encode(fault_message(0)));
  auvrl_lcm::water_current_t flow{};
  flow.current_constant_ned_mps[1] = 0.2;
  fuzz::append_record(run, 4, fuzz::encode(flow));
  write_seed("fuzz_mission_record", "reset_way_fault_current", run);
}

void actor_lockstep_seeds() {
  const VehicleFacts& vehicle = nessie7();
  // Selector bit 0 clear: the state made the answer (seq and vehicle id filled in); bit 1 set:
  // its own vehicle identity kept. A reset answered, then steps down towards 8 m depth.
  Bytes episode;
  for (int k = 0; k <= 20; ++k) {
    const double f = k / 20.0;
    fuzz::append_record(episode, 0,
                        fuzz::encode(state_message(vehicle, k, {f, f, 5 + 3 * f}, 10 * f)));
  }
  write_seed("fuzz_actor_lockstep", "reset_and_steps", episode);
  // The simulator blows up mid-episode; then one naming another vehicle, kept as it is.
  Bytes blow_up;
  fuzz::append_record(blow_up, 0, fuzz::encode(state_message(vehicle, 0, {0, 0, 5}, 0)));
  auvrl_lcm::vehicle_state_t broken = state_message(vehicle, 1, {0, 0, 5}, 0);
  broken.status = auvrl_lcm::vehicle_state_t::STATUS_NON_FINITE;
  broken.velocity_body_mps[0] = std::nan("");
  fuzz::append_record(blow_up, 0, fuzz::encode(broken));
  write_seed("fuzz_actor_lockstep", "blow_up", blow_up);
  Bytes other;
  auvrl_lcm::vehicle_state_t stranger = state_message(vehicle, 0, {0, 0, 5}, 0);
  stranger.vehicle_name = "another";
  fuzz::append_record(other, 2, fuzz::encode(stranger));
  write_seed("fuzz_actor_lockstep", "another_vehicle", other);
}

void training_monitor_seeds() {
  // Selector: 0 episode, 1 learner statistics, 2 simulator heartbeat, 3 logger heartbeat,
  // 4 a role restarted, 5 the clock advanced. The run's roles are processes 10..15 (logger,
  // learner, sim0, sim1, actor0, actor1): a few seconds of a run, actor 1 discarding its
  // episodes, sim0 restarted as process 20 (a late heartbeat of its former process 12), and a
  // heartbeat and an episode from outside the run.
  const int pid = fuzz::kMonitorFirstPid;
  const auto heartbeat = [](int from, double steps_per_s) {
    auvrl_lcm::sim_heartbeat_t h{};
    h.pid = from;
    h.vehicle_name = "nessie7";
    h.num_vehicles = 1;
    h.lockstep = true;
    h.steps_per_s = steps_per_s;
    return fuzz::encode(h);
  };
  const auto report = [](int actor, bool success, std::int8_t reason) {
    auvrl_lcm::episode_report_t e{};
    e.actor_id = actor;
    e.success = success;
    e.beta_m = 0.5;
    e.end_reason = reason;
    return fuzz::encode(e);
  };
  Bytes run;
  auvrl_lcm::logger_heartbeat_t logger{};
  logger.pid = pid;
  fuzz::append_record(run, 3, fuzz::encode(logger));
  auvrl_lcm::learner_stats_t stats{};
  stats.pid = pid + 1;
  stats.algo = "td3";
  stats.updates = 1000;
  stats.updates_per_s = 900;
  for (int second = 0; second < 4; ++second) {
    fuzz::append_record(run, 2, heartbeat(pid + 2, 1500));
    fuzz::append_record(run, 2, heartbeat(pid + 3, 1400));
    fuzz::append_record(run, 1, fuzz::encode(stats));
    fuzz::append_record(run, 0,
                        report(0, second % 2 == 0, auvrl_lcm::episode_report_t::END_REACHED));
    fuzz::append_record(run, 0, report(1, false, auvrl_lcm::episode_report_t::END_BLOW_UP));
    fuzz::append_record(run, 5, Bytes{10});
  }
  fuzz::append_record(run, 4, Bytes{2, 20, 0});  // sim0 restarted as process 20
  fuzz::append_record(run, 2, heartbeat(pid + 2, 1500));
  fuzz::append_record(run, 2, heartbeat(20, 1300));
  fuzz::append_record(run, 2, heartbeat(99, 1e9));
  fuzz::append_record(run, 0, report(7, true, auvrl_lcm::episode_report_t::END_REACHED));
  fuzz::append_record(run, 5, Bytes{255});
  fuzz::append_record(run, 2, heartbeat(pid + 3, 1400));
  fuzz::append_record(run, 0, report(1, false, auvrl_lcm::episode_report_t::END_SIM_TIMEOUT));
  write_seed("fuzz_training_monitor", "run_restart_foreign", run);
}

template <class Msg>
void dict_entry(std::ostream& out, const char* name) {
  const auto hash = static_cast<std::uint64_t>(Msg::getHash());
  out << "fp_" << name << "=\"";
  for (int i = 0; i < 8; ++i) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned>((hash >> (56 - 8 * i)) & 0xFF));
    out << hex;
  }
  out << "\"\n";
}

void lcm_dictionary() {
  std::ofstream out(fs::path(out_dir) / "lcm.dict");
  out << "# LCM fingerprints of the project's types (big-endian, as on the wire) and values that\n"
         "# make decoders and handlers take their edge paths. Written by fuzz_make_corpus.\n";
  dict_entry<auvrl_lcm::thruster_cmd_t>(out, "thruster_cmd_t");
  dict_entry<auvrl_lcm::thruster_fault_t>(out, "thruster_fault_t");
  dict_entry<auvrl_lcm::vehicle_reset_t>(out, "vehicle_reset_t");
  dict_entry<auvrl_lcm::vehicle_state_t>(out, "vehicle_state_t");
  dict_entry<auvrl_lcm::experience_batch_t>(out, "experience_batch_t");
  dict_entry<auvrl_lcm::episode_report_t>(out, "episode_report_t");
  dict_entry<auvrl_lcm::policy_weights_t>(out, "policy_weights_t");
  dict_entry<auvrl_lcm::policy_summary_t>(out, "policy_summary_t");
  dict_entry<auvrl_lcm::weights_request_t>(out, "weights_request_t");
  dict_entry<auvrl_lcm::learner_stats_t>(out, "learner_stats_t");
  dict_entry<auvrl_lcm::sim_heartbeat_t>(out, "sim_heartbeat_t");
  dict_entry<auvrl_lcm::logger_heartbeat_t>(out, "logger_heartbeat_t");
  dict_entry<auvrl_lcm::mission_t>(out, "mission_t");
  dict_entry<auvrl_lcm::water_current_t>(out, "water_current_t");
  out << "i32_max=\"\\x7f\\xff\\xff\\xff\"\n"
         "i32_min=\"\\x80\\x00\\x00\\x00\"\n"
         "i32_minus1=\"\\xff\\xff\\xff\\xff\"\n"
         "i64_max=\"\\x7f\\xff\\xff\\xff\\xff\\xff\\xff\\xff\"\n"
         "f64_nan=\"\\x7f\\xf8\\x00\\x00\\x00\\x00\\x00\\x00\"\n"
         "f64_inf=\"\\x7f\\xf0\\x00\\x00\\x00\\x00\\x00\\x00\"\n"
         "f64_big=\"\\x7f\\xef\\xff\\xff\\xff\\xff\\xff\\xff\"\n"
         "f32_nan=\"\\x7f\\xc0\\x00\\x00\"\n"
         "f32_inf=\"\\x7f\\x80\\x00\\x00\"\n"
         "nn_magic=\"AUVRLNN\\x00\"\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr
        << "usage: fuzz_make_corpus FUZZ_DIR   (writes FUZZ_DIR/corpus/*, FUZZ_DIR/lcm.dict)\n";
    return 2;
  }
  out_dir = argv[1];
  const learner::LearnerNodeConfig config = fuzz::small_learner_config();
  try {
    sim_server_seeds();
    learner_seeds(config);
    checkpoint_seeds(config);
    network_and_weights_seeds(config);
    logger_seeds(config);
    event_log_seeds();
    file_seeds();
    controller_seeds();
    mission_record_seeds();
    training_monitor_seeds();
    actor_lockstep_seeds();
    lcm_dictionary();
  } catch (const std::exception& e) {
    std::cerr << "fuzz_make_corpus: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
