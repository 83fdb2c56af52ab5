// Open-loop validation tool (library part): a CSV of thrust commands in, the simulated
// trajectory out. The command-line front end is `auv_sim --vehicle FILE --open-loop IN.csv
// --out OUT.csv [--ideal-thrusters]`.
//
// Input CSV: header `t,f1,...,fN` (N = number of thrusters), then one row per command change:
// time in s (strictly increasing, >= 0) and the thrust command of each thruster in N. A row
// holds until the next one; it takes effect at the first control step that starts at or after
// its time; before the first row the commands are zero. Blank lines are skipped.
//
// Output CSV: header `t,x,y,z,phi,theta,psi,u,v,w,p,q,r,thrust_1,...,thrust_N`, one row per
// control step from t = 0 (the initial state) to the end: NED position (m), ZYX Euler angles
// (rad), body velocities (m/s, rad/s) and the realised thrust of each thruster (N), numbers
// written with 17 significant digits so that they read back bit for bit.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "sim/dynamics.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::sim {

/// Thrust commands read from an input CSV.
struct OpenLoopCommands {
  std::vector<double> time_s;                    ///< strictly increasing, >= 0
  std::vector<ThrusterVector> thrust_command_n;  ///< one per time, N per thruster
};

/// One output row: the true state after a control step (or the initial state).
struct OpenLoopSample {
  double time_s = 0.0;
  Vector6 eta = Vector6::Zero();  ///< NED position (m), ZYX Euler angles (rad)
  Vector6 nu = Vector6::Zero();   ///< body velocities (m/s, rad/s)
  ThrusterVector thrust_realised_n;
};

/// A simulated run: the samples and how it ended (kOk, or the blow-up that stopped it).
struct OpenLoopResult {
  std::vector<OpenLoopSample> samples;
  StateStatus status = StateStatus::kOk;
};

/// Reads and validates an input CSV for a vehicle with num_thrusters thrusters; throws
/// std::runtime_error naming the file, the line and the column.
OpenLoopCommands read_open_loop_csv(const std::string& path, int num_thrusters);

/// Runs the commands from a reset for duration_s (negative: up to the last row's time), with
/// step() or, if ideal_thrusters, step_ideal_thrusters(). Stops early if the state blows up.
OpenLoopResult run_open_loop_commands(const VehicleModel& model, const ResetSettings& reset,
                                      const OpenLoopCommands& commands, double duration_s,
                                      bool ideal_thrusters);

/// Writes the output CSV; throws std::runtime_error if the file cannot be written.
void write_open_loop_csv(const std::string& path, const OpenLoopResult& result, int num_thrusters);

/// What the command-line front end passes in.
struct OpenLoopOptions {
  std::string vehicle_path;
  std::string input_csv;
  std::string output_csv;
  bool ideal_thrusters = false;  ///< saturation only: no delay, lag or slew
  /// Initial pose: NED position (m) and ZYX Euler angles (rad); at rest, 5 m deep, by default.
  Vector6 initial_eta = (Vector6() << 0.0, 0.0, 5.0, 0.0, 0.0, 0.0).finished();
  double duration_s = -1.0;  ///< negative: up to the last input row's time
};

/// Exit codes of run_open_loop.
inline constexpr int kOpenLoopOk = 0;
inline constexpr int kOpenLoopInputError = 1;  ///< vehicle file, input CSV or output file
inline constexpr int kOpenLoopBlewUp = 3;      ///< output written up to the last valid step

/// Loads the vehicle, reads the input, runs and writes the output. Returns a process exit code
/// and prints what went wrong (file, line, field) to err.
int run_open_loop(const OpenLoopOptions& options, std::ostream& err);

}  // namespace auvrl::sim
