#include "child_process.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace auvrl::test_support {

namespace {

/// The folders make_temp_dir made, removed when the test program ends: a test run otherwise
/// leaves its runs (up to a few hundred MB each) in /tmp, and repeated runs fill the disk.
/// Kept when a test failed, or with AUVRL_KEEP_TEST_DIRS set, to look at.
class TempDirs {
 public:
  ~TempDirs() {
    if (getpid() != owner_) return;  // a forked child that exits leaves them to its parent
    if (std::getenv("AUVRL_KEEP_TEST_DIRS") != nullptr) return;
    if (::testing::UnitTest::GetInstance()->Failed()) return;
    for (const std::string& dir : dirs_) {
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    }
  }
  void add(std::string dir) {
    const std::lock_guard<std::mutex> lock(mutex_);
    dirs_.push_back(std::move(dir));
  }

 private:
  const pid_t owner_ = getpid();
  std::mutex mutex_;
  std::vector<std::string> dirs_;
};

TempDirs& temp_dirs() {
  static TempDirs dirs;
  return dirs;
}

}  // namespace

std::string bin_path(const std::string& name) { return std::string(AUVRL_BIN_DIR) + "/" + name; }

std::string make_temp_dir(const std::string& prefix) {
  std::string pattern = "/tmp/" + prefix + "XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  temp_dirs().add(pattern);
  return pattern;
}

}  // namespace auvrl::test_support
