// `auvrl replay`: a mission run's LCM log played back on the bus by lcm-logplayer and recorded
// the way `auvrl run` recorded it live (the same MissionRecorder and MissionEventLog, fed the
// same messages in the same order), into a new directory: trajectory.csv, waypoints.csv,
// vehicle.csv, events.csv, the plots and report.md, which compares each file with the run's.
// It runs in its own private network namespace, where no simulator or controller answers the
// replayed traffic (docs/deployment.md, "Replaying a mission").
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace auvrl::launcher {

/// What `auvrl replay` was asked.
struct MissionReplayOptions {
  std::string run_dir;       ///< the `auvrl run` directory whose logs/ is replayed (required)
  std::string out_dir;       ///< "": RUN/replay-<time>
  double speed = 1.0;        ///< lcm-logplayer's playback speed multiplier
  std::string mission_path;  ///< "": RUN/mission.yaml
  /// "": RUN/vehicle.yaml, else the mission's vehicle:, else Nessie VII.
  std::string vehicle_path;
  std::string player = "/usr/bin/lcm-logplayer";  ///< the player (Debian's liblcm-bin)
  /// out_dir was prepared by this command before it entered the network namespace.
  bool prepared = false;
  std::string bin_dir;     ///< where auvrl is
  std::string source_dir;  ///< the source tree (scripts/netns.sh, scripts/plot_mission.py)
};

/// Checks the run directory (its logs, mission and vehicle), the player and the speed, then
/// creates the output directory (processes/, plots/); refuses one that exists and is not empty.
/// Fills in out_dir, mission_path and vehicle_path and makes every path absolute. Throws
/// std::invalid_argument naming what does not fit.
void prepare_mission_replay(MissionReplayOptions& options);

/// `auvrl replay` once its options are parsed: prepares (unless options.prepared), then replays
/// here when host_network is set or this process runs inside a private network namespace
/// already; otherwise runs itself again inside a new one and does not return. Returns 0 when
/// the files were written, 1 when the replay or a file failed, 130 when stopped (Ctrl-C).
int start_mission_replay(MissionReplayOptions options, bool host_network, std::ostream& out);

/// "identical" when both files hold the same bytes; otherwise where they first differ ("differs
/// at line N", "only in A", "missing: B").
std::string compare_files(const std::string& original_path, const std::string& replayed_path);

}  // namespace auvrl::launcher
