#include "learner/checkpoint.hpp"

#include <algorithm>
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
}  // namespace

std::vector<CheckpointFile> list_checkpoints(const std::string& dir) {
  std::vector<CheckpointFile> found;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return found;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const std::string prefix = kPrefix, suffix = kSuffix;
    if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    const std::string digits =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), ::isdigit) ||
        digits.size() > 18) {
      continue;
    }
    found.push_back({entry.path().string(), std::stoll(digits)});
  }
  std::sort(found.begin(), found.end(),
            [](const CheckpointFile& a, const CheckpointFile& b) { return a.updates > b.updates; });
  return found;
}

std::string write_checkpoint(const std::string& dir, std::int64_t updates, int keep,
                             const std::function<void(nn::Writer&)>& fill) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw std::runtime_error("cannot create checkpoint directory " + dir + ": " + ec.message());
  char name[64];
  std::snprintf(name, sizeof name, "%s%012lld%s", kPrefix, static_cast<long long>(updates),
                kSuffix);
  const std::string path = (fs::path(dir) / name).string();
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
