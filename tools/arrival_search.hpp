// How soon could this vehicle reach a scenario's way-point at all? An open-loop search over
// thrust commands (the cross-entropy method) for the soonest arrival within the evaluation's
// reach radius, started from the PID baseline's own commands, so that a learned policy and the
// PID can be compared with what the plant allows (its thrust limits, thruster lag and slew,
// drag), not only with each other. `auvrl fastest` is its command-line front end.
//
// With `--stay-within M` an arrival counts only if the vehicle then stays within M of the
// way-point for 3 s under the searched commands: the bound for arriving and stopping, which is
// what the PID does and what the learned policies are trained to do.
//
// The search knows the scenario exactly (no noise, no feedback), so its time is a bound that
// a controller which reacts to what it measures can approach but not be expected to beat; the
// search is local (started from the PID's way), so a still sooner way may exist.
//
// Files written to DIR by run_arrival_search_request:
//   commands.csv     the found commands in auv_sim's open-loop format (`t,f1,...,fN`, thrust in
//                    N, one row per 0.1 s step up to the arrival, then a row of zeros at the
//                    arrival time that ends the run): for test1, whose start is auv_sim's
//                    default (at rest at [0, 0, 5], facing north, no fault or current),
//                    `auv_sim --vehicle FILE --open-loop commands.csv --out OUT.csv` replays
//                    them;
//   summary.csv      the evaluation's summary rows (eval/evaluation.hpp) of the PID and of
//                    the found commands with the PID taking over on arrival (so the hold error
//                    after such an arrival is measured too), controller "open_loop+pid";
//   trajectories/<controller>_<scenario>.csv   both runs, in the evaluation's trajectory format;
//   search.csv       per iteration: iteration, best arrival step so far, the best sample's.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "agent/controller.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::tools {

/// Settings of the cross-entropy search. Commands are normalised ([-1, 1] of maximum thrust)
/// and piecewise constant over segments of steps_per_segment control steps.
struct ArrivalSearchConfig {
  int steps_per_segment = 2;
  int population = 300;  ///< samples per iteration
  int elites = 30;       ///< the best this many set the next mean and spread
  int iterations = 1000;
  double initial_sigma = 0.3;  ///< spread of the first samples around the PID's commands
  double min_sigma = 0.02;     ///< floor of the spread, so the search never freezes
  double smoothing = 0.3;      ///< weight kept of the previous mean and spread
  /// Control steps simulated beyond the PID's arrival before a sample counts as not arriving.
  int extra_steps = 20;
  /// Arrive and stay: when positive, an arrival counts only if the vehicle, still under the
  /// searched commands, stays within this distance of the way-point for stay_steps control
  /// steps after it (the evaluation's criterion alone lets a fast arrival overshoot by
  /// metres and come back). Negative: arriving is enough.
  double stay_within_m = -1.0;
  int stay_steps = 30;
  std::uint64_t seed = 1;

  /// Throws std::invalid_argument naming the first setting out of range.
  void validate() const;
};

/// What the search found.
struct ArrivalSearchResult {
  int pid_arrival_step = -1;  ///< the PID baseline, closed loop (the evaluation's figure)
  /// Arrival steps count only where the arrival counts (and the vehicle stayed, with
  /// stay_within_m); -1 where none did.
  int start_arrival_step = -1;  ///< the PID's commands replayed open loop (the search's start)
  int best_arrival_step = -1;   ///< the found commands
  /// Farthest from the way-point in the stay_steps after the found arrival (with
  /// stay_within_m), m; negative without.
  double best_farthest_after_m = -1.0;
  /// The found commands (normalised), one row per control step up to best_arrival_step, and
  /// with stay_within_m the stay_steps after it.
  std::vector<Eigen::VectorXd> commands;
  /// Per iteration: the best arrival step so far, and the best of that iteration's samples
  /// (-1 where none of them arrived).
  std::vector<int> best_so_far_step;
  std::vector<int> iteration_best_step;
};

/// Searches the commands that bring the vehicle within config.reach_radius_m of the episode's
/// way-point soonest. The PID baseline must reach the way-point (it sets the start and the
/// horizon); throws std::runtime_error otherwise. progress (may be empty) is called after each
/// iteration with the iteration and the best step so far.
ArrivalSearchResult search_fastest_arrival(
    const sim::VehicleModel& model, const eval::EvaluationConfig& config,
    const eval::EvaluationEpisode& episode, const ArrivalSearchConfig& search,
    const std::function<void(int iteration, int best_step)>& progress = {});

/// Plays fixed commands, one per control step, then hands over to another controller (the
/// PID baseline: the vehicle holds station after an open-loop arrival).
class OpenLoopController final : public agent::Controller {
 public:
  /// Throws std::invalid_argument if a command is not of size num_thrusters or after is null.
  OpenLoopController(std::vector<Eigen::VectorXd> commands, int num_thrusters,
                     std::unique_ptr<agent::Controller> after);
  void reset() override;
  void act(const task::Observation& observation, const Eigen::Vector3d& goal_ned_m,
           const task::StateVector& state, task::ActionVector& action) override;
  std::string name() const override { return "open_loop+" + after_->name(); }

 private:
  std::vector<Eigen::VectorXd> commands_;
  int num_thrusters_;
  std::unique_ptr<agent::Controller> after_;
  std::size_t next_ = 0;
};

/// Writes commands (normalised) as auv_sim's open-loop input: `t,f1,...,fN`, thrust in N, one
/// row per control step, then a row of zeros at the end time. Throws std::runtime_error naming the
/// path on failure.
void write_open_loop_commands_csv(const std::string& path,
                                  const std::vector<Eigen::VectorXd>& commands,
                                  double control_step_s, double max_thrust_n);

/// What `auvrl fastest` was asked to do.
struct ArrivalSearchRequest {
  std::string scenario = "test1";  ///< test1, test2, fault or current
  std::string out_dir;             ///< required
  std::string vehicle_path;        ///< vehicle file
  ArrivalSearchConfig search;
};

/// The whole `auvrl fastest`: runs the search, evaluates the PID and the found commands
/// (PID after arrival) with the evaluation, writes DIR (see the file comment), prints a few
/// lines to `out`. Throws std::invalid_argument for a bad request, std::runtime_error for
/// unreadable or unwritable files.
ArrivalSearchResult run_arrival_search_request(const ArrivalSearchRequest& request,
                                               std::ostream& out);

}  // namespace auvrl::tools
