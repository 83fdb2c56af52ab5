// How an episode reaches its vehicle: over LCM in lockstep with auv_sim (training actors), or
// directly through the dynamics library in this process (evaluation, tests). The episode code
// above it is the same either way.
#pragma once

#include <Eigen/Core>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <memory>
#include <optional>
#include <vector>

#include "common/sim_client.hpp"
#include "common/task/task.hpp"
#include "common/transport.hpp"
#include "sim/dynamics.hpp"
#include "sim/model_variation.hpp"

namespace auvrl::agent {

/// What the vehicle reports after a reset or a step.
struct VehicleReport {
  task::Observation observation;
  std::vector<double> thrust_realised_n;  ///< per thruster, N
  double time_s = 0.0;                    ///< since the reset, s
  bool blown_up = false;                  ///< the simulator flagged a numerical blow-up
  /// Where the vehicle truly is (NED, m), when the link knows it: a simulator in this process,
  /// whose sensor noise only the observation carries. The episode's figures (time to reach,
  /// hold error, final error) use it; the controller never sees it.
  std::optional<Eigen::Vector3d> true_position_ned_m;
};

/// What a vehicle_state_t message reports (the simulator's, or a real vehicle's driver's).
VehicleReport vehicle_report(const auvrl_lcm::vehicle_state_t& msg);

/// Throws UnrecoverableFault (naming `who` with `expected` and `sender` with what it names)
/// unless the state names the expected vehicle: name, thruster count, file CRC-32.
void expect_vehicle(const VehicleFacts& expected, const auvrl_lcm::vehicle_state_t& msg,
                    const std::string& who, const std::string& sender);

/// Initial conditions and faults of an episode.
struct EpisodeStart {
  Eigen::Vector3d position_ned_m{0.0, 0.0, 5.0};
  Eigen::Vector3d euler_rpy_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_body_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rate_body_rad_s = Eigen::Vector3d::Zero();
  std::vector<double> thruster_efficiency;                    ///< empty: all healthy
  Eigen::Vector3d current_ned_mps = Eigen::Vector3d::Zero();  ///< the constant part, NED
  /// The varying part of the current: a first-order Gauss-Markov speed along a heading
  /// (sim::CurrentSettings); sigma 0: none.
  double current_varying_sigma_mps = 0.0;
  double current_varying_time_constant_s = 60.0;
  double current_varying_direction_rad = 0.0;  ///< from north
  sim::SensorNoise sensor_noise;               ///< on what the vehicle reports; all zero: exact
  /// How the vehicle in the water differs from its file (default: not at all).
  sim::ModelVariation model_variation;
  std::uint64_t seed = 1;
};

/// Puts what a training episode's randomisation drew (task::sample_conditions) into its start:
/// thruster efficiencies, currents, sensor noise and model variation.
void apply_conditions(const task::EpisodeConditions& conditions, EpisodeStart& start);

/// A vehicle an episode can reset and command. Returns nothing when the vehicle did not answer.
class VehicleLink {
 public:
  virtual ~VehicleLink() = default;
  virtual int num_thrusters() const = 0;
  virtual std::optional<VehicleReport> reset(const EpisodeStart& start) = 0;
  virtual std::optional<VehicleReport> step(const std::vector<double>& thrust_n) = 0;
  /// Changes the thruster efficiencies (one per thruster, each in [0, 1]) of the vehicle now
  /// running, from the next step on (a mission's timed fault). Returns false where the link
  /// cannot (the lockstep link); throws std::invalid_argument on unusable values.
  virtual bool set_thruster_efficiency(const std::vector<double>& /*efficiency*/) { return false; }
  /// Changes the constant water current (NED, m/s) from the next step on; false where the link
  /// cannot (the lockstep link).
  virtual bool set_current(const Eigen::Vector3d& /*current_ned_mps*/) { return false; }
};

/// The dynamics library in this process (deterministic, no transport).
std::unique_ptr<VehicleLink> make_in_process_link(const sim::VehicleModel& model);

/// One vehicle of auv_sim over the transport, in lockstep; a step or reset unanswered within
/// timing.timeout_ms is sent again, up to timing.attempts times, then reported as lost. Every
/// reset reply must name `expected` (name, thruster count, file CRC-32): another vehicle throws
/// UnrecoverableFault naming both.
std::unique_ptr<VehicleLink> make_lockstep_link(transport::Transport& transport, int vehicle_id,
                                                const VehicleFacts& expected,
                                                LockstepTiming timing = {});

}  // namespace auvrl::agent
