// Checkpoint files of the learner: written atomically (temporary file, fsync, rename), sealed
// with a CRC-32, numbered by update count; the newest few are kept so that a damaged newest
// one falls back to the one before.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "common/nn/byte_io.hpp"

namespace auvrl::learner {

/// A checkpoint file found in a directory.
struct CheckpointFile {
  std::string path;
  std::int64_t updates = 0;  ///< from the file name checkpoint-<updates>.ckpt
};

/// Checkpoints in dir, newest (most updates) first. A missing directory gives none.
std::vector<CheckpointFile> list_checkpoints(const std::string& dir);

/// A snapshot of the actor network the learner writes in the reproducible mode (the launcher
/// gives each the quick evaluation for the best policy): <dir>/policy-<updates>.nn.
struct PolicySnapshot {
  std::int64_t updates = 0;  ///< the learner's update count when it wrote it
  std::string path;          ///< <dir>/policy-<updates, 12 digits>.nn
};

/// Where the snapshot at `updates` goes in dir.
std::string snapshot_path(const std::string& dir, std::int64_t updates);

/// The snapshots in dir, oldest (fewest updates) first: the regular files named
/// policy-<digits>.nn (the learner's temporary files and anything else are left out). A
/// missing directory gives none.
std::vector<PolicySnapshot> list_snapshots(const std::string& dir);

/// Writes dir/checkpoint-<updates>.ckpt atomically with `fill`, then deletes all but the
/// newest `keep` checkpoints. Returns the path. Throws std::runtime_error naming the path if
/// the file cannot be written (disk full, no permission): the older checkpoints are intact.
std::string write_checkpoint(const std::string& dir, std::int64_t updates, int keep,
                             const std::function<void(nn::Writer&)>& fill);

/// Tries the checkpoints in dir from the newest: calls `restore` on each until one succeeds.
/// restore must read the whole record into temporaries, call Reader::verify_checksum(), and
/// only then commit, so that a damaged file (it throws std::runtime_error) changes nothing. Reports
/// every damaged file on `log`. Returns the one restored; throws std::runtime_error if none could
/// be (or there is none).
CheckpointFile restore_latest_checkpoint(const std::string& dir,
                                         const std::function<void(nn::Reader&)>& restore,
                                         std::ostream& log);

}  // namespace auvrl::learner
