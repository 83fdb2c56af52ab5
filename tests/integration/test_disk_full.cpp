// A full disk and an unwritable run directory, on real file systems: this test moves itself
// into a mount namespace of its own (root, or the user namespace scripts/netns.sh makes) and
// mounts small tmpfs there, invisible to the rest of the machine. The learner's checkpoint
// writer names the path it could not write and leaves the last good checkpoint intact; auvrl
// train stops with that path named when the disk fills up mid-run, its newest checkpoint still
// restorable; and it refuses a read-only run directory with the path named.
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "child_process.hpp"
#include "common/nn/byte_io.hpp"
#include "common/transport.hpp"
#include "learner/checkpoint.hpp"
#include "learner/learner_config.hpp"
#include "learner/learner_node.hpp"
#include "run_files.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using test_support::ChildProcess;

const std::string kPreset = std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml";

/// Enters a private mount namespace once; false (with the reason) if that is not allowed.
bool private_mounts(std::string& why) {
  static int state = 0;  // 0 not tried, 1 done, -1 failed
  static std::string reason;
  if (state == 0) {
    state = -1;
    if (unshare(CLONE_NEWNS) != 0) {
      reason = std::string("unshare(CLONE_NEWNS): ") + std::strerror(errno);
    } else if (mount("none", "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) {
      reason = std::string("making / private: ") + std::strerror(errno);
    } else {
      state = 1;
    }
  }
  why = reason;
  return state == 1;
}

/// A fresh directory with a tmpfs of `size` ("4m") mounted on it (read-only if asked), or ""
/// with the reason in why.
std::string small_tmpfs(const std::string& size, bool read_only, std::string& why) {
  if (!private_mounts(why)) return "";
  const std::string dir = test_support::make_temp_dir("auvrl_tmpfs_");
  const std::string options = "size=" + size + ",mode=0755";
  if (mount("tmpfs", dir.c_str(), "tmpfs", read_only ? MS_RDONLY : 0, options.c_str()) != 0) {
    why = "mount tmpfs: " + std::string(std::strerror(errno));
    return "";
  }
  return dir;
}

/// Fills the file system holding dir until a write fails; returns the bytes written.
std::size_t fill_up(const std::string& dir) {
  std::ofstream filler(dir + "/filler", std::ios::binary);
  const std::vector<char> block(64 * 1024, 'x');
  std::size_t written = 0;
  while (filler.write(block.data(), static_cast<std::streamsize>(block.size())) && filler.flush()) {
    written += block.size();
  }
  // Whatever fits in the last partial block too.
  filler.clear();
  for (int i = 0; i < 64 * 1024 && filler.put('x') && filler.flush(); ++i) ++written;
  return written;
}

bool wait_for(const std::function<bool()>& condition, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return condition();
}

/// `bytes` payload bytes, as the learner's checkpoint record would carry them.
std::function<void(nn::Writer&)> payload(std::size_t bytes, std::uint8_t value) {
  return [bytes, value](nn::Writer& w) {
    w.u64(bytes);
    for (std::size_t i = 0; i < bytes; ++i) w.u8(value);
  };
}

TEST(CheckpointWriter, DiskFullNamesThePathAndKeepsTheLastGoodCheckpoint) {
  std::string why;
  const std::string disk = small_tmpfs("4m", false, why);
  if (disk.empty()) GTEST_SKIP() << "no private tmpfs: " << why;
  const std::string dir = disk + "/checkpoints";
  learner::write_checkpoint(dir, 100, 2, payload(1 << 20, 7));
  try {
    learner::write_checkpoint(dir, 200, 2, payload(8 << 20, 9));
    FAIL() << "an 8 MB checkpoint was written to a 4 MB disk";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/checkpoint-000000000200.ckpt"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
  // Nothing half-written is left, and the good checkpoint reads back whole.
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"checkpoint-000000000100.ckpt"});
  std::ostringstream log;
  const learner::CheckpointFile restored = learner::restore_latest_checkpoint(
      dir,
      [](nn::Reader& r) {
        const std::uint64_t n = r.u64();
        ASSERT_EQ(n, 1u << 20);
        for (std::uint64_t i = 0; i < n; ++i) ASSERT_EQ(r.u8(), 7);
        r.verify_checksum();
      },
      log);
  EXPECT_EQ(restored.updates, 100);
  EXPECT_EQ(log.str(), "");
  // Space again: writing works again.
  EXPECT_NO_THROW(learner::write_checkpoint(dir, 300, 2, payload(1 << 20, 3)));
  umount2(disk.c_str(), MNT_DETACH);
}

TEST(LauncherDiskFull, RunStopsNamingThePathAndTheNewestCheckpointRestores) {
  std::string why;
  const std::string disk = small_tmpfs("128m", false, why);
  if (disk.empty()) GTEST_SKIP() << "no private tmpfs: " << why;
  const std::string tmp = test_support::make_temp_dir("auvrl_disk_full_");
  // The fast preset with checkpoints every 2 s.
  const std::string config = test_support::write_preset_copy(
      AUVRL_CONFIG_DIR, "fast", tmp + "/fast.yaml", [](std::string& line) {
        if (line.find("checkpoint_period_s:") != std::string::npos) {
          line = "  checkpoint_period_s: 2";
        }
      });
  const std::string run = disk + "/run";
  ChildProcess train(
      {test_support::bin_path("auvrl"), "train", "--config", config, "--run-dir", run, "--network",
       "host", "--actors", "1", "--max-seconds", "120", "--no-eval"},
      tmp + "/train.log");  // the launcher's own output: off the full disk
  ASSERT_TRUE(
      wait_for([&] { return !learner::list_checkpoints(run + "/checkpoints").empty(); }, 60))
      << train.log();
  const std::size_t filled = fill_up(disk);
  EXPECT_GT(filled, 0u);
  const int status = train.wait_for_exit(std::chrono::seconds(60));
  ASSERT_TRUE(WIFEXITED(status)) << train.log();
  EXPECT_EQ(WEXITSTATUS(status), 1) << train.log();
  EXPECT_NE(train.log().find("cannot write " + run + "/"), std::string::npos) << train.log();
  EXPECT_NE(train.log().find("No space left on device"), std::string::npos) << train.log();
  EXPECT_NE(train.log().find("continue it: auvrl train --resume " + run), std::string::npos);

  // The newest checkpoint on the full disk restores; nothing half-written is left beside it.
  for (const auto& e : fs::directory_iterator(run + "/checkpoints")) {
    EXPECT_EQ(e.path().extension(), ".ckpt") << e.path();
  }
  const learner::CheckpointFile newest = learner::list_checkpoints(run + "/checkpoints").front();
  learner::LearnerNodeConfig node_config;
  learner::read_learner_config_file(run + "/config.yaml", node_config);
  node_config.checkpoint_dir = run + "/checkpoints";
  node_config.max_actors = 1;
  auto transport = transport::make_in_process_transport();
  std::ostringstream log;
  learner::LearnerNode node(node_config, *transport, log);
  ASSERT_NO_THROW(node.resume()) << log.str();
  EXPECT_EQ(node.updates(), newest.updates);
  EXPECT_EQ(log.str().find("unusable"), std::string::npos) << log.str();
  umount2(disk.c_str(), MNT_DETACH);
}

TEST(LauncherDiskFull, ReadOnlyRunDirectoryIsRefusedWithThePath) {
  std::string why;
  const std::string disk = small_tmpfs("1m", true, why);
  if (disk.empty()) GTEST_SKIP() << "no private tmpfs: " << why;
  const std::string run = disk + "/run";
  ChildProcess train({test_support::bin_path("auvrl"), "train", "--config", kPreset, "--run-dir",
                      run, "--network", "host", "--no-eval"},
                     test_support::make_temp_dir("auvrl_ro_") + "/train.log");
  const int status = train.wait_for_exit(std::chrono::seconds(30));
  ASSERT_TRUE(WIFEXITED(status)) << train.log();
  EXPECT_NE(WEXITSTATUS(status), 0) << train.log();
  EXPECT_NE(train.log().find(run), std::string::npos) << train.log();
  EXPECT_NE(train.log().find("Read-only file system"), std::string::npos) << train.log();
  umount2(disk.c_str(), MNT_DETACH);
}

}  // namespace
