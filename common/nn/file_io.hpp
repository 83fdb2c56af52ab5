// Whole-file writes that never leave a half-written file under the final name.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/nn/byte_io.hpp"

namespace auvrl::nn {

/// Writes a file atomically: `fill` writes into "<path>.tmp", which is flushed to disk (fsync)
/// and renamed over `path` only if everything succeeded, so a crash or a full disk leaves the
/// previous file intact. Throws std::runtime_error (naming the path) on any failure, after
/// removing the temporary file.
void write_file_atomically(const std::string& path, const std::function<void(ByteSink&)>& fill);

/// Same, for bytes already in memory.
void write_file_atomically(const std::string& path, const std::vector<std::uint8_t>& bytes);

/// Reads a whole file; throws std::runtime_error naming the path if it cannot.
std::vector<std::uint8_t> read_file(const std::string& path);

}  // namespace auvrl::nn
