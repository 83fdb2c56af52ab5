#include "sim/sim_server.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "common/channels.hpp"

namespace auvrl::sim {

namespace {

using Clock = std::chrono::steady_clock;

bool all_finite(const double* values, std::size_t n) {
  return std::all_of(values, values + n, [](double v) { return std::isfinite(v); });
}

Vector6 pose_vector(const double position[3], const double euler[3]) {
  Vector6 eta;
  eta << position[0], position[1], position[2], euler[0], euler[1], euler[2];
  return eta;
}

}  // namespace

std::string reset_settings_from_message(const auvrl_lcm::vehicle_reset_t& msg, int num_thrusters,
                                        ResetSettings& out) {
  const double scalars[] = {msg.current_gm_mean_speed_mps,
                            msg.current_gm_sigma_mps,
                            msg.current_gm_time_constant_s,
                            msg.current_gm_direction_rad,
                            msg.current_gm_direction_sigma_rad,
                            msg.noise_position_m,
                            msg.noise_attitude_rad,
                            msg.noise_velocity_mps,
                            msg.noise_angular_rate_rad_s};
  if (!all_finite(msg.position_ned_m, 3) || !all_finite(msg.euler_rpy_rad, 3) ||
      !all_finite(msg.velocity_body_mps, 3) || !all_finite(msg.angular_rate_body_rad_s, 3) ||
      !all_finite(msg.current_constant_ned_mps, 3) || !all_finite(scalars, std::size(scalars)) ||
      !all_finite(msg.thruster_efficiency.data(), msg.thruster_efficiency.size())) {
    return "non-finite value in vehicle_reset_t";
  }
  if (msg.num_thrusters != 0 && msg.num_thrusters != num_thrusters) {
    return "vehicle_reset_t.num_thrusters is " + std::to_string(msg.num_thrusters) +
           ", expected 0 or " + std::to_string(num_thrusters);
  }
  for (double e : msg.thruster_efficiency) {
    if (e < 0.0 || e > 1.0) return "vehicle_reset_t.thruster_efficiency outside [0, 1]";
  }
  if (msg.noise_position_m < 0 || msg.noise_attitude_rad < 0 || msg.noise_velocity_mps < 0 ||
      msg.noise_angular_rate_rad_s < 0 || msg.current_gm_sigma_mps < 0 ||
      msg.current_gm_direction_sigma_rad < 0) {
    return "vehicle_reset_t: a noise standard deviation is negative";
  }
  if (msg.current_gm_time_constant_s <= 0 &&
      (msg.current_gm_sigma_mps > 0 || msg.current_gm_mean_speed_mps != 0)) {
    return "vehicle_reset_t.current_gm_time_constant_s must be > 0 for a varying current";
  }

  out = ResetSettings{};
  out.eta = pose_vector(msg.position_ned_m, msg.euler_rpy_rad);
  out.nu << msg.velocity_body_mps[0], msg.velocity_body_mps[1], msg.velocity_body_mps[2],
      msg.angular_rate_body_rad_s[0], msg.angular_rate_body_rad_s[1],
      msg.angular_rate_body_rad_s[2];
  if (msg.num_thrusters == 0) {
    out.thruster_efficiency = ThrusterVector::Ones(num_thrusters);
  } else {
    out.thruster_efficiency =
        Eigen::Map<const Eigen::VectorXd>(msg.thruster_efficiency.data(), num_thrusters);
  }
  out.current.constant_velocity_ned_mps = Eigen::Map<const Vector3>(msg.current_constant_ned_mps);
  out.current.gauss_markov_speed_mean_mps = msg.current_gm_mean_speed_mps;
  out.current.gauss_markov_speed_sigma_mps = msg.current_gm_sigma_mps;
  if (msg.current_gm_time_constant_s > 0) {
    out.current.gauss_markov_time_constant_s = msg.current_gm_time_constant_s;
  }
  out.current.gauss_markov_direction_rad = msg.current_gm_direction_rad;
  out.current.gauss_markov_direction_sigma_rad = msg.current_gm_direction_sigma_rad;
  out.sensor_noise.position_sigma_m = msg.noise_position_m;
  out.sensor_noise.attitude_sigma_rad = msg.noise_attitude_rad;
  out.sensor_noise.linear_velocity_sigma_mps = msg.noise_velocity_mps;
  out.sensor_noise.angular_velocity_sigma_rad_s = msg.noise_angular_rate_rad_s;
  out.seed = static_cast<std::uint64_t>(msg.seed);
  return "";
}

std::string model_variation_from_message(const auvrl_lcm::vehicle_reset_t& msg,
                                         ModelVariation& out) {
  out = ModelVariation{};
  if (!msg.model_varied) return "";
  const double values[] = {msg.model_quadratic_damping_scale, msg.model_added_mass_scale,
                           msg.model_mass_scale, msg.model_thruster_lag_time_constant_s,
                           msg.model_extra_buoyancy_n};
  // Ranges are vary_model's to check (set_variation counts a refusal as out of range).
  if (!all_finite(values, std::size(values))) return "non-finite model variation";
  out.quadratic_damping_scale = msg.model_quadratic_damping_scale;
  out.added_mass_scale = msg.model_added_mass_scale;
  out.mass_scale = msg.model_mass_scale;
  out.thruster_lag_time_constant_s = msg.model_thruster_lag_time_constant_s;
  out.extra_buoyancy_n = msg.model_extra_buoyancy_n;
  return "";
}

void state_message_from_measurement(const VehicleModel& model, const Measurement& measurement,
                                    const VehicleState& state, int vehicle_id, std::int64_t seq,
                                    auvrl_lcm::vehicle_state_t& out) {
  out.utime = transport::now_utime();
  out.vehicle_id = vehicle_id;
  out.seq = seq;
  out.step_count = state.step_count;
  out.sim_time_s = measurement.time_s;
  for (int i = 0; i < 3; ++i) {
    out.position_ned_m[i] = measurement.eta[i];
    out.euler_rpy_rad[i] = measurement.eta[3 + i];
    out.velocity_body_mps[i] = measurement.nu[i];
    out.angular_rate_body_rad_s[i] = measurement.nu[3 + i];
    out.current_ned_mps[i] = state.current_velocity_ned_mps[i];
  }
  out.vehicle_name = model.name;
  out.vehicle_file_crc32 = static_cast<std::int32_t>(model.file_crc32);
  out.num_thrusters = static_cast<std::int8_t>(measurement.thrust_realised_n.size());
  out.thrust_realised_n.assign(measurement.thrust_realised_n.data(),
                               measurement.thrust_realised_n.data() + out.num_thrusters);
  out.status = static_cast<std::int8_t>(measurement.status);
}

SimServer::SimServer(const VehicleModel& model, transport::Transport& transport,
                     SimServerConfig config, transport::Transport* heartbeat_transport)
    : model_(model),
      transport_(transport),
      heartbeat_transport_(heartbeat_transport ? *heartbeat_transport : transport),
      config_(std::move(config)) {
  if (config_.num_vehicles < 1) throw std::invalid_argument("num_vehicles must be >= 1");
  if (!(config_.realtime_factor > 0)) throw std::invalid_argument("realtime_factor must be > 0");
  vehicles_.resize(static_cast<std::size_t>(config_.num_vehicles));
  if (config_.first_vehicle_id < 0) throw std::invalid_argument("first_vehicle_id must be >= 0");
  for (int i = 0; i < config_.num_vehicles; ++i) {
    Vehicle& v = vehicles_[static_cast<std::size_t>(i)];
    v.held_command_n = ThrusterVector::Zero(model_.num_thrusters());
    v.state_channel = channels::sim_state(config_.first_vehicle_id + i);
  }

  using transport::subscribe;
  subscriptions_.push_back(subscribe<auvrl_lcm::thruster_cmd_t>(
      transport_, channels::kSimCommandPattern,
      [this](const std::string& ch, const auvrl_lcm::thruster_cmd_t& m) { on_command(ch, m); },
      &decode_stats_));
  subscriptions_.push_back(subscribe<auvrl_lcm::vehicle_reset_t>(
      transport_, channels::kSimResetPattern,
      [this](const std::string& ch, const auvrl_lcm::vehicle_reset_t& m) { on_reset(ch, m); },
      &decode_stats_));
  subscriptions_.push_back(subscribe<auvrl_lcm::thruster_fault_t>(
      transport_, channels::kSimFaultPattern,
      [this](const std::string& ch, const auvrl_lcm::thruster_fault_t& m) { on_fault(ch, m); },
      &decode_stats_));
  subscriptions_.push_back(subscribe<auvrl_lcm::water_current_t>(
      transport_, channels::kSimCurrentPattern,
      [this](const std::string& ch, const auvrl_lcm::water_current_t& m) { on_current(ch, m); },
      &decode_stats_));

  const auto now = Clock::now();
  next_heartbeat_ = now;
  next_realtime_step_ = now;
  rate_window_start_ = now;
}

SimServer::~SimServer() {
  for (auto id : subscriptions_) transport_.unsubscribe(id);
}

const VehicleState* SimServer::vehicle(int id) const {
  const int i = id - config_.first_vehicle_id;
  if (i < 0 || i >= config_.num_vehicles || !vehicles_[static_cast<std::size_t>(i)].active) {
    return nullptr;
  }
  return &vehicles_[static_cast<std::size_t>(i)].state;
}

void SimServer::poll(int timeout_ms) {
  transport_.handle(timeout_ms);
  if (!config_.lockstep) realtime_tick();
  if (Clock::now() >= next_heartbeat_) publish_heartbeat();
}

SimServer::Vehicle* SimServer::addressed_vehicle(const std::string& channel, int vehicle_id) {
  const int i = vehicle_id - config_.first_vehicle_id;
  if (i < 0 || i >= config_.num_vehicles || channels::vehicle_id_of(channel) != vehicle_id) {
    ++counters_.dropped_vehicle_id;
    return nullptr;
  }
  return &vehicles_[static_cast<std::size_t>(i)];
}

bool SimServer::thrusters_valid(int num_thrusters, const std::vector<double>& values,
                                bool efficiency) {
  if (num_thrusters != model_.num_thrusters()) {
    ++counters_.dropped_thrusters;
    return false;
  }
  if (!all_finite(values.data(), values.size())) {
    ++counters_.dropped_non_finite;
    return false;
  }
  if (efficiency &&
      std::any_of(values.begin(), values.end(), [](double e) { return e < 0.0 || e > 1.0; })) {
    ++counters_.dropped_out_of_range;
    return false;
  }
  return true;
}

void SimServer::on_command(const std::string& channel, const auvrl_lcm::thruster_cmd_t& msg) {
  Vehicle* vehicle = addressed_vehicle(channel, msg.vehicle_id);
  if (vehicle == nullptr || !thrusters_valid(msg.num_thrusters, msg.thrust_n, false)) return;
  if (!vehicle->active) {
    ++counters_.dropped_not_reset;
    return;
  }
  // Sequence numbers make lockstep retries safe: a repeat gets the same answer again
  // instead of a second step; an older command is a leftover and is ignored.
  if (msg.seq == vehicle->last_seq) {
    ++counters_.duplicates_answered;
    transport_.publish(vehicle->state_channel, vehicle->last_state_bytes.data(),
                       vehicle->last_state_bytes.size());
    return;
  }
  if (msg.seq < vehicle->last_seq) {
    ++counters_.dropped_stale;
    return;
  }
  vehicle->last_seq = msg.seq;
  const ThrusterVector command_n =
      Eigen::Map<const Eigen::VectorXd>(msg.thrust_n.data(), msg.num_thrusters);
  if (config_.lockstep) {
    step_vehicle(msg.vehicle_id, *vehicle, command_n);
    publish_state(msg.vehicle_id, *vehicle);
  } else {
    vehicle->held_command_n = command_n;
  }
}

void SimServer::on_reset(const std::string& channel, const auvrl_lcm::vehicle_reset_t& msg) {
  Vehicle* vehicle = addressed_vehicle(channel, msg.vehicle_id);
  if (vehicle == nullptr) return;
  ResetSettings settings;
  ModelVariation variation;
  std::string problem = reset_settings_from_message(msg, model_.num_thrusters(), settings);
  if (problem.empty()) problem = model_variation_from_message(msg, variation);
  if (!problem.empty()) {
    if (problem.rfind("non-finite", 0) == 0) {
      ++counters_.dropped_non_finite;
    } else if (problem.find("num_thrusters") != std::string::npos) {
      ++counters_.dropped_thrusters;
    } else {
      ++counters_.dropped_out_of_range;
    }
    return;
  }
  if (!set_variation(*vehicle, variation)) return;
  vehicle->state = make_state(model_of(*vehicle), settings);
  vehicle->held_command_n.setZero();
  vehicle->active = true;
  vehicle->last_seq = msg.seq;
  ++counters_.resets_total;
  publish_state(msg.vehicle_id, *vehicle);
}

bool SimServer::set_variation(Vehicle& vehicle, const ModelVariation& variation) {
  if (variation.is_identity()) {
    vehicle.varied_model.reset();
  } else if (!vehicle.varied_model || variation != vehicle.variation) {
    try {
      vehicle.varied_model = vary_model(model_, variation);
    } catch (const std::invalid_argument&) {
      ++counters_.dropped_out_of_range;  // a variation the model cannot take
      return false;
    }
  }
  vehicle.variation = variation;
  return true;
}

void SimServer::on_fault(const std::string& channel, const auvrl_lcm::thruster_fault_t& msg) {
  Vehicle* vehicle = addressed_vehicle(channel, msg.vehicle_id);
  if (vehicle == nullptr || !thrusters_valid(msg.num_thrusters, msg.thruster_efficiency, true)) {
    return;
  }
  if (!vehicle->active) {
    ++counters_.dropped_not_reset;
    return;
  }
  set_thruster_efficiency(
      model_of(*vehicle), vehicle->state,
      Eigen::Map<const Eigen::VectorXd>(msg.thruster_efficiency.data(), msg.num_thrusters));
  ++counters_.faults_total;
}

void SimServer::on_current(const std::string& channel, const auvrl_lcm::water_current_t& msg) {
  Vehicle* vehicle = addressed_vehicle(channel, msg.vehicle_id);
  if (vehicle == nullptr) return;
  const Eigen::Vector3d current_ned_mps(msg.current_constant_ned_mps[0],
                                        msg.current_constant_ned_mps[1],
                                        msg.current_constant_ned_mps[2]);
  if (!current_ned_mps.allFinite()) {
    ++counters_.dropped_non_finite;
    return;
  }
  if (!vehicle->active) {
    ++counters_.dropped_not_reset;
    return;
  }
  set_constant_current(vehicle->state, current_ned_mps);
  ++counters_.currents_total;
}

void SimServer::step_vehicle(int /*id*/, Vehicle& vehicle, const ThrusterVector& command_n) {
  const bool was_ok = vehicle.state.status == StateStatus::kOk;
  step(model_of(vehicle), vehicle.state, command_n);
  ++counters_.steps_total;
  ++rate_window_steps_;
  if (was_ok && vehicle.state.status != StateStatus::kOk) ++counters_.blow_ups_total;
}

void SimServer::publish_state(int id, Vehicle& vehicle) {
  const VehicleModel& model = model_of(vehicle);
  const Measurement measurement = measure(model, vehicle.state);
  state_message_from_measurement(model, measurement, vehicle.state, id, vehicle.last_seq,
                                 state_msg_);
  const int size = state_msg_.getEncodedSize();
  vehicle.last_state_bytes.resize(static_cast<std::size_t>(size));
  state_msg_.encode(vehicle.last_state_bytes.data(), 0, size);
  transport_.publish(vehicle.state_channel, vehicle.last_state_bytes.data(),
                     vehicle.last_state_bytes.size());
}

void SimServer::realtime_tick() {
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(model_.control_step_s / config_.realtime_factor));
  auto now = Clock::now();
  // Catch up at most a few steps after a stall rather than bursting through a backlog.
  int budget = 5;
  while (now >= next_realtime_step_ && budget-- > 0) {
    for (int i = 0; i < config_.num_vehicles; ++i) {
      Vehicle& vehicle = vehicles_[static_cast<std::size_t>(i)];
      if (!vehicle.active) continue;
      const int id = config_.first_vehicle_id + i;
      step_vehicle(id, vehicle, vehicle.held_command_n);
      publish_state(id, vehicle);
    }
    next_realtime_step_ += period;
    now = Clock::now();
  }
  if (now >= next_realtime_step_) next_realtime_step_ = now + period;
}

int SimServer::next_realtime_wait_ms() const {
  const auto wait =
      std::chrono::duration_cast<std::chrono::milliseconds>(next_realtime_step_ - Clock::now());
  return static_cast<int>(std::clamp<std::int64_t>(wait.count(), 0, 50));
}

void SimServer::publish_heartbeat() {
  const auto now = Clock::now();
  const double window_s = std::chrono::duration<double>(now - rate_window_start_).count();
  if (window_s > 0.2) {
    steps_per_s_ = static_cast<double>(rate_window_steps_) / window_s;
    rate_window_steps_ = 0;
    rate_window_start_ = now;
  }
  auvrl_lcm::sim_heartbeat_t hb;
  hb.utime = transport::now_utime();
  hb.pid = static_cast<std::int32_t>(getpid());
  hb.vehicle_file = config_.vehicle_file;
  hb.vehicle_name = model_.name;
  hb.num_thrusters = model_.num_thrusters();
  hb.vehicle_file_crc32 = static_cast<std::int32_t>(model_.file_crc32);
  hb.num_vehicles = config_.num_vehicles;
  hb.lockstep = config_.lockstep;
  hb.control_step_s = model_.control_step_s;
  hb.steps_total = counters_.steps_total;
  hb.steps_per_s = steps_per_s_;
  hb.resets_total = counters_.resets_total;
  hb.faults_total = counters_.faults_total;
  hb.currents_total = counters_.currents_total;
  hb.blow_ups_total = counters_.blow_ups_total;
  hb.duplicates_answered = counters_.duplicates_answered;
  hb.dropped_stale = counters_.dropped_stale;
  hb.dropped_decode = decode_stats_.failed;
  hb.dropped_vehicle_id = counters_.dropped_vehicle_id;
  hb.dropped_thrusters = counters_.dropped_thrusters;
  hb.dropped_non_finite = counters_.dropped_non_finite;
  hb.dropped_out_of_range = counters_.dropped_out_of_range;
  hb.dropped_not_reset = counters_.dropped_not_reset;
  transport::publish(heartbeat_transport_, channels::kSimHeartbeat, hb);
  next_heartbeat_ = now + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(config_.heartbeat_period_s));
}

}  // namespace auvrl::sim
