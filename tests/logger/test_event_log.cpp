// LCM event logs: what the writer writes, LCM's own reader reads (and the other way round);
// rotation keeps every file under its limit and never overwrites; damaged files (bad sync
// word, absurd lengths, truncated events, garbage) are read as far as they are readable, with
// the damage reported at the right byte offset.
#include <gtest/gtest.h>
#include <lcm/eventlog.h>

#include <filesystem>
#include <fstream>

#include "child_process.hpp"
#include "logger/event_log.hpp"

namespace {

using namespace auvrl::logger;
namespace fs = std::filesystem;

struct Sent {
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime;
};

std::vector<Sent> some_events(int count, std::size_t size_step = 37) {
  std::vector<Sent> events;
  for (int i = 0; i < count; ++i) {
    Sent e;
    e.channel = "CHAN_" + std::to_string(i % 5);
    e.data.resize(static_cast<std::size_t>(i) * size_step % 2000);
    for (std::size_t k = 0; k < e.data.size(); ++k) {
      e.data[k] = static_cast<std::uint8_t>(k * 7 + static_cast<std::size_t>(i));
    }
    e.utime = 1700000000000000 + i * 1000;
    events.push_back(std::move(e));
  }
  return events;
}

std::vector<LogEvent> read_all(const std::vector<std::string>& files,
                               std::vector<LogDamage>* damage = nullptr) {
  std::vector<LogEvent> events;
  for (const std::string& file : files) {
    LogReader reader(file);
    LogEvent event;
    while (reader.next(event)) events.push_back(event);
    if (damage != nullptr)
      damage->insert(damage->end(), reader.damage().begin(), reader.damage().end());
  }
  return events;
}

std::vector<std::uint8_t> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

class EventLog : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = auvrl::test_support::make_temp_dir("auvrl_event_log_"); }
  void TearDown() override { fs::remove_all(dir_); }

  /// One file of the given events (no rotation); returns its path.
  std::string write_log(const std::vector<Sent>& events) {
    RotatingLogWriter writer(dir_, "one", 1u << 30);
    for (const Sent& e : events) writer.write(e.channel, e.data.data(), e.data.size(), e.utime);
    writer.close();
    return writer.files().at(0);
  }

  std::string dir_;
};

TEST_F(EventLog, WhatIsWrittenIsReadBackExactly) {
  const auto sent = some_events(300);
  const std::string path = write_log(sent);
  std::vector<LogDamage> damage;
  const auto events = read_all({path}, &damage);
  EXPECT_TRUE(damage.empty());
  ASSERT_EQ(events.size(), sent.size());
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(events[i].channel, sent[i].channel);
    EXPECT_EQ(events[i].data, sent[i].data);
    EXPECT_EQ(events[i].timestamp_us, sent[i].utime);
    EXPECT_EQ(events[i].event_number, static_cast<std::int64_t>(i));
    EXPECT_EQ(events[i].offset, offset);
    offset += RotatingLogWriter::event_bytes(sent[i].channel.size(), sent[i].data.size());
  }
  EXPECT_EQ(fs::file_size(path), offset);
}

TEST_F(EventLog, LcmsOwnReaderReadsOurFilesAndWeReadItsFiles) {
  const auto sent = some_events(50);
  const std::string path = write_log(sent);
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "r");
  ASSERT_NE(log, nullptr);
  std::size_t count = 0;
  while (lcm_eventlog_event_t* event = lcm_eventlog_read_next_event(log)) {
    ASSERT_LT(count, sent.size());
    EXPECT_EQ(std::string(event->channel, static_cast<std::size_t>(event->channellen)),
              sent[count].channel);
    EXPECT_EQ(event->timestamp, sent[count].utime);
    EXPECT_EQ(std::vector<std::uint8_t>(static_cast<std::uint8_t*>(event->data),
                                        static_cast<std::uint8_t*>(event->data) + event->datalen),
              sent[count].data);
    lcm_eventlog_free_event(event);
    ++count;
  }
  lcm_eventlog_destroy(log);
  EXPECT_EQ(count, sent.size());

  // A file written by LCM's own writer directly.
  const std::string theirs = dir_ + "/theirs.lcmlog";
  log = lcm_eventlog_create(theirs.c_str(), "w");
  for (const Sent& e : sent) {
    lcm_eventlog_event_t event{};
    event.timestamp = e.utime;
    event.channellen = static_cast<std::int32_t>(e.channel.size());
    event.datalen = static_cast<std::int32_t>(e.data.size());
    event.channel = const_cast<char*>(e.channel.c_str());
    event.data = const_cast<std::uint8_t*>(e.data.data());
    ASSERT_EQ(lcm_eventlog_write_event(log, &event), 0);
  }
  lcm_eventlog_destroy(log);
  EXPECT_EQ(file_bytes(theirs), file_bytes(path));  // byte for byte the same format
}

TEST_F(EventLog, RotationKeepsFilesUnderTheLimitAndLosesNothing) {
  const std::uint64_t limit = 20000;
  RotatingLogWriter writer(dir_, "rot", limit);
  const auto sent = some_events(500);
  for (const Sent& e : sent) writer.write(e.channel, e.data.data(), e.data.size(), e.utime);
  // An event larger than the limit gets a file of its own.
  const std::vector<std::uint8_t> big(30000, 0xab);
  writer.write("BIG", big.data(), big.size(), 1);
  writer.write("AFTER", big.data(), 10, 2);
  writer.close();
  const auto& files = writer.files();
  ASSERT_GT(files.size(), 10u);
  for (std::size_t i = 0; i < files.size(); ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "/rot-%04zu.lcmlog", i);
    EXPECT_EQ(files[i], dir_ + name);
    const auto size = fs::file_size(files[i]);
    if (files[i] != files[files.size() - 2]) {
      EXPECT_LE(size, limit) << files[i];
    }
  }
  EXPECT_GT(fs::file_size(files[files.size() - 2]), limit);  // the big one, alone
  const auto events = read_all(expand_log_paths({dir_}));
  ASSERT_EQ(events.size(), sent.size() + 2);
  for (std::size_t i = 0; i < sent.size(); ++i) {
    ASSERT_EQ(events[i].data, sent[i].data) << i;
    ASSERT_EQ(events[i].event_number, static_cast<std::int64_t>(i));  // continues across files
  }
  EXPECT_EQ(events[sent.size()].channel, "BIG");
  std::uint64_t total = 0;
  for (const auto& f : files) total += fs::file_size(f);
  EXPECT_EQ(writer.bytes_written(), total);
}

TEST_F(EventLog, ARestartContinuesNumberingAndNeverOverwrites) {
  const auto sent = some_events(10);
  {
    RotatingLogWriter writer(dir_, "run", 1000);
    for (const Sent& e : sent) writer.write(e.channel, e.data.data(), e.data.size(), e.utime);
  }
  const auto before = expand_log_paths({dir_});
  const auto first_bytes = file_bytes(before.front());
  RotatingLogWriter again(dir_, "run", 1000);
  EXPECT_EQ(again.first_file_number(), static_cast<int>(before.size()));
  again.write("X", "abc", 3, 5);
  again.close();
  EXPECT_EQ(file_bytes(before.front()), first_bytes);
  EXPECT_EQ(expand_log_paths({dir_}).size(), before.size() + 1);
  // Another prefix in the same directory starts at 0.
  RotatingLogWriter other(dir_, "other", 1000);
  EXPECT_EQ(other.first_file_number(), 0);
}

TEST_F(EventLog, BadSyncWordIsSkippedAndReportedAtItsOffset) {
  const auto sent = some_events(20);
  const std::string path = write_log(sent);
  auto bytes = file_bytes(path);
  // Damage the sync word of event 7.
  const auto events = read_all({path});
  const std::uint64_t at = events[7].offset;
  bytes[at] = 0x00;
  write_bytes(path, bytes);
  std::vector<LogDamage> damage;
  const auto read = read_all({path}, &damage);
  ASSERT_EQ(read.size(), sent.size() - 1);
  EXPECT_EQ(read[6].channel, sent[6].channel);
  EXPECT_EQ(read[7].data, sent[8].data);  // reading resumed at the next event
  ASSERT_EQ(damage.size(), 1u);
  EXPECT_EQ(damage[0].offset, at);
  EXPECT_EQ(damage[0].bytes_skipped, events[8].offset - at);
  EXPECT_NE(damage[0].what.find("bad sync word 0x00a1da01"), std::string::npos) << damage[0].what;
}

TEST_F(EventLog, AbsurdLengthsAreReportedAndReadingResumes) {
  const auto sent = some_events(20);
  const std::string path = write_log(sent);
  auto bytes = file_bytes(path);
  const auto events = read_all({path});
  // Event 3: data length 0xFFFFFFF0; event 12: channel length 0.
  for (int i = 0; i < 4; ++i) bytes[events[3].offset + 24 + static_cast<std::size_t>(i)] = 0xff;
  for (int i = 0; i < 4; ++i) bytes[events[12].offset + 20 + static_cast<std::size_t>(i)] = 0;
  write_bytes(path, bytes);
  std::vector<LogDamage> damage;
  const auto read = read_all({path}, &damage);
  EXPECT_EQ(read.size(), sent.size() - 2);
  ASSERT_EQ(damage.size(), 2u);
  EXPECT_EQ(damage[0].offset, events[3].offset);
  EXPECT_NE(damage[0].what.find("impossible data length 4294967295"), std::string::npos)
      << damage[0].what;
  EXPECT_EQ(damage[1].offset, events[12].offset);
  EXPECT_NE(damage[1].what.find("impossible channel length 0"), std::string::npos);
}

TEST_F(EventLog, TruncatedLastEventIsReportedAndTheRestRead) {
  const auto sent = some_events(20);
  const std::string path = write_log(sent);
  const auto events = read_all({path});
  auto bytes = file_bytes(path);
  // Cut in the middle of the last event's data, then in the middle of a header.
  bytes.resize(bytes.size() - 5);
  write_bytes(path, bytes);
  std::vector<LogDamage> damage;
  auto read = read_all({path}, &damage);
  EXPECT_EQ(read.size(), sent.size() - 1);
  ASSERT_EQ(damage.size(), 1u);
  EXPECT_EQ(damage[0].offset, events.back().offset);
  EXPECT_EQ(damage[0].bytes_skipped, bytes.size() - events.back().offset);
  EXPECT_NE(damage[0].what.find("truncated event"), std::string::npos) << damage[0].what;

  bytes.resize(events.back().offset + 10);
  write_bytes(path, bytes);
  damage.clear();
  read = read_all({path}, &damage);
  EXPECT_EQ(read.size(), sent.size() - 1);
  ASSERT_EQ(damage.size(), 1u);
  EXPECT_NE(damage[0].what.find("truncated event header: 10 bytes"), std::string::npos);
}

TEST_F(EventLog, GarbageAndEmptyFilesAreHandled) {
  const std::string garbage = dir_ + "/garbage.lcmlog";
  std::vector<std::uint8_t> bytes(100000);
  std::uint64_t x = 1;
  for (auto& b : bytes) {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    b = static_cast<std::uint8_t>(x >> 56);
  }
  write_bytes(garbage, bytes);
  std::vector<LogDamage> damage;
  EXPECT_TRUE(read_all({garbage}, &damage).empty());
  ASSERT_EQ(damage.size(), 1u);
  EXPECT_EQ(damage[0].offset, 0u);
  EXPECT_EQ(damage[0].bytes_skipped, bytes.size());

  // Garbage between two good logs: both good parts are read.
  const auto sent = some_events(10);
  const std::string good = write_log(sent);
  auto joined = file_bytes(good);
  const std::size_t garbage_at = joined.size();
  joined.insert(joined.end(), bytes.begin(), bytes.begin() + 5000);
  const auto good_bytes = file_bytes(good);
  joined.insert(joined.end(), good_bytes.begin(), good_bytes.end());
  write_bytes(good, joined);
  damage.clear();
  EXPECT_EQ(read_all({good}, &damage).size(), 2 * sent.size());
  ASSERT_EQ(damage.size(), 1u);
  EXPECT_EQ(damage[0].offset, garbage_at);
  EXPECT_EQ(damage[0].bytes_skipped, 5000u);

  const std::string empty = dir_ + "/empty.lcmlog";
  write_bytes(empty, {});
  damage.clear();
  EXPECT_TRUE(read_all({empty}, &damage).empty());
  EXPECT_TRUE(damage.empty());
  EXPECT_THROW(LogReader(dir_ + "/missing.lcmlog"), LogError);
  EXPECT_THROW(LogReader{dir_}, LogError);  // a directory is not a log
}

TEST_F(EventLog, DirectoryArgumentsExpandToTheirLogsInOrder) {
  RotatingLogWriter writer(dir_, "a", 100);
  for (int i = 0; i < 3; ++i) writer.write("C", "0123456789012345678901234567890123456789", 40, i);
  writer.close();
  write_bytes(dir_ + "/notes.txt", {1, 2, 3});
  const auto paths = expand_log_paths({dir_, "/some/file"});
  ASSERT_EQ(paths.size(), 4u);
  EXPECT_EQ(paths[0], dir_ + "/a-0000.lcmlog");
  EXPECT_EQ(paths[2], dir_ + "/a-0002.lcmlog");
  EXPECT_EQ(paths[3], "/some/file");
  const std::string empty_dir = dir_ + "/empty";
  fs::create_directories(empty_dir);
  EXPECT_THROW(expand_log_paths({empty_dir}), LogError);
}

}  // namespace
