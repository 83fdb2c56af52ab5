// The run directory of `auvrl train`: config.yaml (a copy of the configuration), README.txt,
// logs/, checkpoints/, eval/, plots/, processes/ and the CSV files of the run.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace auvrl::launcher {

struct TrainOptions;

/// Creates the run directory of a new run (config copy, folders) or checks an existing one for
/// --resume; returns the path of the run's configuration. Throws std::runtime_error naming
/// what is wrong.
std::string prepare_run_directory(TrainOptions& options);

/// The seed `auvrl train`'s command line gave the run in run_dir (its command_line.yaml), if it
/// gave one: the run's seed where its configuration has another. Throws std::runtime_error
/// naming the file when it cannot be read.
std::optional<std::int64_t> command_line_seed(const std::string& run_dir);

/// The path made absolute and normal ("" stays "").
std::string absolute_path(const std::string& path);

/// Whether dir exists and holds anything: an output directory is never reused.
bool directory_in_use(const std::string& dir);

/// The local time as run directories name it: 20250131-142501.
std::string run_timestamp();

/// Whether dir holds a finished learner checkpoint (checkpoint-<updates>.ckpt). A learner
/// killed while writing leaves only its temporary file, which --resume cannot use.
bool has_checkpoint_file(const std::string& dir);

}  // namespace auvrl::launcher
