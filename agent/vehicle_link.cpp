#include "agent/vehicle_link.hpp"

#include "common/sim_client.hpp"
#include "common/unrecoverable.hpp"

namespace auvrl::agent {

VehicleReport vehicle_report(const auvrl_lcm::vehicle_state_t& s) {
  VehicleReport r;
  for (int i = 0; i < 3; ++i) {
    r.observation.position_ned_m[i] = s.position_ned_m[i];
    r.observation.euler_rpy_rad[i] = s.euler_rpy_rad[i];
    r.observation.velocity_body_mps[i] = s.velocity_body_mps[i];
    r.observation.angular_rate_body_rad_s[i] = s.angular_rate_body_rad_s[i];
  }
  r.thrust_realised_n = s.thrust_realised_n;
  r.time_s = s.sim_time_s;
  r.blown_up = s.status != auvrl_lcm::vehicle_state_t::STATUS_OK;
  return r;
}

void expect_vehicle(const VehicleFacts& expected, const auvrl_lcm::vehicle_state_t& msg,
                    const std::string& who, const std::string& sender) {
  const VehicleIdentity served{msg.vehicle_name, msg.num_thrusters,
                               static_cast<std::uint32_t>(msg.vehicle_file_crc32)};
  if (!same_vehicle(identity_of(expected), served)) {
    throw UnrecoverableFault(vehicle_mismatch_message(who, expected, sender, served));
  }
}

void apply_conditions(const task::EpisodeConditions& c, EpisodeStart& start) {
  start.thruster_efficiency = c.thruster_efficiency;
  start.current_ned_mps = c.current_ned_mps;
  start.current_varying_sigma_mps = c.varying_current_sigma_mps;
  start.current_varying_time_constant_s = c.varying_current_time_constant_s;
  start.current_varying_direction_rad = c.varying_current_direction_rad;
  start.sensor_noise.position_sigma_m = c.noise_position_m;
  start.sensor_noise.attitude_sigma_rad = c.noise_attitude_rad;
  start.sensor_noise.linear_velocity_sigma_mps = c.noise_velocity_mps;
  start.sensor_noise.angular_velocity_sigma_rad_s = c.noise_angular_rate_rad_s;
  sim::ModelVariation& v = start.model_variation;
  v.quadratic_damping_scale = c.quadratic_damping_scale;
  v.added_mass_scale = c.added_mass_scale;
  v.mass_scale = c.mass_scale;
  v.thruster_lag_time_constant_s = c.thruster_lag_time_constant_s;
  v.extra_buoyancy_n = c.extra_buoyancy_n;
}

namespace {

class InProcessLink final : public VehicleLink {
 public:
  explicit InProcessLink(const sim::VehicleModel& model) : nominal_(model), model_(&model) {}
  int num_thrusters() const override { return model_->num_thrusters(); }

  std::optional<VehicleReport> reset(const EpisodeStart& start) override {
    if (start.model_variation.is_identity()) {
      model_ = &nominal_;
    } else {
      // Varied again only when the variation changes (a suite runs many episodes on one).
      if (!varied_ || start.model_variation != variation_) {
        varied_ = sim::vary_model(nominal_, start.model_variation);
        variation_ = start.model_variation;
      }
      model_ = &*varied_;
    }
    sim::ResetSettings settings;
    settings.eta << start.position_ned_m, start.euler_rpy_rad;
    settings.nu << start.velocity_body_mps, start.angular_rate_body_rad_s;
    settings.thruster_efficiency =
        start.thruster_efficiency.empty()
            ? sim::ThrusterVector::Ones(model_->num_thrusters())
            : sim::ThrusterVector(Eigen::Map<const Eigen::VectorXd>(
                  start.thruster_efficiency.data(),
                  static_cast<Eigen::Index>(start.thruster_efficiency.size())));
    settings.current.constant_velocity_ned_mps = start.current_ned_mps;
    settings.current.gauss_markov_speed_sigma_mps = start.current_varying_sigma_mps;
    settings.current.gauss_markov_time_constant_s = start.current_varying_time_constant_s;
    settings.current.gauss_markov_direction_rad = start.current_varying_direction_rad;
    settings.sensor_noise = start.sensor_noise;
    settings.seed = start.seed;
    state_ = sim::make_state(*model_, settings);
    return report();
  }

  std::optional<VehicleReport> step(const std::vector<double>& thrust_n) override {
    if (!state_) return std::nullopt;
    command_ = Eigen::Map<const Eigen::VectorXd>(thrust_n.data(),
                                                 static_cast<Eigen::Index>(thrust_n.size()));
    sim::step(*model_, *state_, command_);
    return report();
  }

  bool set_thruster_efficiency(const std::vector<double>& efficiency) override {
    if (!state_) return false;
    sim::set_thruster_efficiency(
        *model_, *state_,
        Eigen::Map<const Eigen::VectorXd>(efficiency.data(),
                                          static_cast<Eigen::Index>(efficiency.size())));
    return true;
  }

  bool set_current(const Eigen::Vector3d& current_ned_mps) override {
    if (!state_) return false;
    sim::set_constant_current(*state_, current_ned_mps);
    return true;
  }

 private:
  VehicleReport report() {
    const sim::Measurement m = sim::measure(*model_, *state_);
    VehicleReport r;
    r.observation.position_ned_m = m.eta.head<3>();
    r.observation.euler_rpy_rad = m.eta.tail<3>();
    r.observation.velocity_body_mps = m.nu.head<3>();
    r.observation.angular_rate_body_rad_s = m.nu.tail<3>();
    r.thrust_realised_n.assign(m.thrust_realised_n.data(),
                               m.thrust_realised_n.data() + m.thrust_realised_n.size());
    r.time_s = m.time_s;
    r.blown_up = m.status != sim::StateStatus::kOk;
    r.true_position_ned_m = state_->eta.head<3>();
    return r;
  }

  const sim::VehicleModel& nominal_;
  std::optional<sim::VehicleModel> varied_;  ///< this episode's vehicle, when it is varied
  sim::ModelVariation variation_;            ///< what varied_ was built with
  const sim::VehicleModel* model_;           ///< nominal_ or varied_
  std::optional<sim::VehicleState> state_;
  sim::ThrusterVector command_;
};

class LockstepLink final : public VehicleLink {
 public:
  LockstepLink(transport::Transport& transport, int vehicle_id, const VehicleFacts& expected,
               LockstepTiming timing)
      : client_(transport, vehicle_id, timing),
        vehicle_id_(vehicle_id),
        expected_(expected),
        num_thrusters_(expected.num_thrusters()) {}
  int num_thrusters() const override { return num_thrusters_; }

  std::optional<VehicleReport> reset(const EpisodeStart& start) override {
    auvrl_lcm::vehicle_reset_t msg{};
    for (int i = 0; i < 3; ++i) {
      msg.position_ned_m[i] = start.position_ned_m[i];
      msg.euler_rpy_rad[i] = start.euler_rpy_rad[i];
      msg.velocity_body_mps[i] = start.velocity_body_mps[i];
      msg.angular_rate_body_rad_s[i] = start.angular_rate_body_rad_s[i];
      msg.current_constant_ned_mps[i] = start.current_ned_mps[i];
    }
    msg.num_thrusters = static_cast<std::int8_t>(start.thruster_efficiency.size());
    msg.thruster_efficiency = start.thruster_efficiency;
    msg.noise_position_m = start.sensor_noise.position_sigma_m;
    msg.noise_attitude_rad = start.sensor_noise.attitude_sigma_rad;
    msg.noise_velocity_mps = start.sensor_noise.linear_velocity_sigma_mps;
    msg.noise_angular_rate_rad_s = start.sensor_noise.angular_velocity_sigma_rad_s;
    msg.current_gm_sigma_mps = start.current_varying_sigma_mps;
    msg.current_gm_time_constant_s = start.current_varying_time_constant_s;
    msg.current_gm_direction_rad = start.current_varying_direction_rad;
    const sim::ModelVariation& variation = start.model_variation;
    msg.model_varied = !variation.is_identity();
    if (msg.model_varied) {
      msg.model_quadratic_damping_scale = variation.quadratic_damping_scale;
      msg.model_added_mass_scale = variation.added_mass_scale;
      msg.model_mass_scale = variation.mass_scale;
      msg.model_thruster_lag_time_constant_s = variation.thruster_lag_time_constant_s;
      msg.model_extra_buoyancy_n = variation.extra_buoyancy_n;
    }
    msg.seed = static_cast<std::int64_t>(start.seed);
    const std::optional<auvrl_lcm::vehicle_state_t> reply = client_.reset(msg);
    if (reply) check_vehicle(*reply);
    return convert(reply);
  }

  std::optional<VehicleReport> step(const std::vector<double>& thrust_n) override {
    return convert(client_.step(thrust_n));
  }

 private:
  std::optional<VehicleReport> convert(const std::optional<auvrl_lcm::vehicle_state_t>& s) const {
    if (!s || s->num_thrusters != num_thrusters_) return std::nullopt;
    return vehicle_report(*s);
  }

  /// The reply must come from the vehicle this actor expects.
  void check_vehicle(const auvrl_lcm::vehicle_state_t& reply) const {
    expect_vehicle(expected_, reply, "this actor",
                   "auv_sim (vehicle id " + std::to_string(vehicle_id_) + ")");
  }

  SimClient client_;
  int vehicle_id_;
  VehicleFacts expected_;
  int num_thrusters_;
};

}  // namespace

std::unique_ptr<VehicleLink> make_in_process_link(const sim::VehicleModel& model) {
  return std::make_unique<InProcessLink>(model);
}

std::unique_ptr<VehicleLink> make_lockstep_link(transport::Transport& transport, int vehicle_id,
                                                const VehicleFacts& expected,
                                                LockstepTiming timing) {
  return std::make_unique<LockstepLink>(transport, vehicle_id, expected, timing);
}

}  // namespace auvrl::agent
