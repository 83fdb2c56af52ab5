#include "learner/checkpoint.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "common/nn/file_io.hpp"
#include "common/unrecoverable.hpp"

namespace auvrl::learner {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPrefix = "checkpoint-";
constexpr const char* kSuffix = ".ckpt";
constexpr const char* kSnapshotPrefix = "policy-";
constexpr const char* kSnapshotSuffix = ".nn";

/// The learner's files numbered by update count: <prefix><updates, 12 digits><suffix>.
std::string numbered_name(const char* prefix, std::int64_t updates, const char* suffix) {
  char name[64];
  std::snprintf(name, sizeof name, "%s%012lld%s", prefix, static_cast<long long>(updates), suffix);
  return name;
}

/// The regular files of dir named <prefix><digits><suffix>, with their numbers, in increasing
/// order (a missing dir holds none).
std::vector<std::pair<std::int64_t, std::string>> numbered_files(const std::string& dir,
                                                                 const std::string& prefix,
                                                                 const std::string& suffix) {
  std::vector<std::pair<std::int64_t, std::string>> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0 ||
        !entry.is_regular_file(ec)) {
      continue;
    }
    const std::string digits =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(),
                                           [](unsigned char c) { return std::isdigit(c); })) {
      continue;
    }
    found.emplace_back(std::stoll(digits), entry.path().string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

std::vector<CheckpointFile> list_checkpoints(const std::string& dir) {
  std::vector<CheckpointFile> newest_first;
  const auto found = numbered_files(dir, kPrefix, kSuffix);
  for (auto it = found.rbegin(); it != found.rend(); ++it) {
    newest_first.push_back({it->second, it->first});
  }
  return newest_first;
}

std::string snapshot_path(const std::string& dir, std::int64_t updates) {
  return (fs::path(dir) / numbered_name(kSnapshotPrefix, updates, kSnapshotSuffix)).string();
}

std::vector<PolicySnapshot> list_snapshots(const std::string& dir) {
  std::vector<PolicySnapshot> oldest_first;
  for (auto& [updates, path] : numbered_files(dir, kSnapshotPrefix, kSnapshotSuffix)) {
    oldest_first.push_back({updates, std::move(path)});
  }
  return oldest_first;
}

std::string write_checkpoint(const std::string& dir, std::int64_t updates, int keep,
                             const std::function<void(nn::Writer&)>& fill) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw std::runtime_error("cannot create checkpoint directory " + dir + ": " + ec.message());
  const std::string path = (fs::path(dir) / numbered_name(kPrefix, updates, kSuffix)).string();
  nn::write_file_atomically(path, [&](nn::ByteSink& sink) {
    nn::Writer writer(sink);
    fill(writer);
    writer.checksum();
  });
  const auto all = list_checkpoints(dir);
  for (std::size_t i = static_cast<std::size_t>(std::max(keep, 1)); i < all.size(); ++i) {
    fs::remove(all[i].path, ec);
  }
  return path;
}

CheckpointFile restore_latest_checkpoint(const std::string& dir,
                                         const std::function<void(nn::Reader&)>& restore,
                                         std::ostream& log) {
  const auto all = list_checkpoints(dir);
  if (all.empty()) throw std::runtime_error("no checkpoint-*.ckpt in " + dir);
  std::optional<UnrecoverableFault> other_learner;
  for (const CheckpointFile& file : all) {
    try {
      std::ifstream in(file.path, std::ios::binary);
      if (!in) throw std::runtime_error("cannot open " + file.path);
      nn::IStreamSource source(in);
      nn::Reader reader(source, file.path);
      restore(reader);
      return file;
    } catch (const UnrecoverableFault& e) {
      log << "checkpoint " << file.path << " is another learner's: " << e.what() << "\n";
      if (!other_learner) other_learner = e;
    } catch (const std::exception& e) {
      log << "checkpoint " << file.path << " is unusable: " << e.what() << "\n";
    }
  }
  // Nothing usable, and the newest sound one belongs to a learner of other sizes: say so.
  if (other_learner) throw *other_learner;
  throw std::runtime_error("no usable checkpoint in " + dir + " (" + std::to_string(all.size()) +
                           " damaged)");
}

}  // namespace auvrl::learner
