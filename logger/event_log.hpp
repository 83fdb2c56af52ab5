// LCM event logs, the format lcm-logger writes and lcm-logplayer and lcm-spy read: no file
// header, a sequence of big-endian events
//   u32 sync 0xEDA1DA01, i64 event number, i64 timestamp (us), u32 channel length,
//   u32 data length, channel bytes (no NUL), data bytes (the encoded message).
// The reader survives damaged files: it reads what is readable and reports each damaged
// region with its byte offset. The writer uses LCM's own C eventlog API and rotates by size.
#pragma once

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

extern "C" {
struct _lcm_eventlog_t;
}

namespace auvrl::logger {

/// The sync word in front of every event.
inline constexpr std::uint32_t kEventSync = 0xEDA1DA01u;
/// Bytes of an event before its channel: sync, event number, timestamp, two lengths.
inline constexpr std::size_t kEventHeaderSize = 4 + 8 + 8 + 4 + 4;
/// Longest channel name the reader accepts (LCM's own reader refuses 1000 or more; LCM itself
/// allows 63).
inline constexpr std::uint32_t kMaxChannelLength = 999;
/// Largest message the reader accepts: LCM's maximum message size (256 MB).
inline constexpr std::uint32_t kMaxDataLength = 256u * 1024 * 1024;

/// A log file that cannot be opened or written.
class LogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One event of a log.
struct LogEvent {
  std::int64_t event_number = 0;
  std::int64_t timestamp_us = 0;  ///< when the logger received it, us since the Unix epoch
  std::string channel;
  std::vector<std::uint8_t> data;
  std::uint64_t offset = 0;  ///< byte offset of its sync word in the file
};

/// A damaged region of a log file.
struct LogDamage {
  std::string file;
  std::uint64_t offset = 0;         ///< where the damage starts (bytes from the file start)
  std::uint64_t bytes_skipped = 0;  ///< bytes not read as events from there
  std::string what;                 ///< e.g. "bad sync word 0x12345678"
};

/// Reads the events of one log file in order. Damage (a bad sync word, an impossible length,
/// a truncated event) is recorded and reading resumes at the next plausible event.
class LogReader {
 public:
  /// Opens path; throws LogError if it cannot be opened.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  /// Reads the next event; false at the end of the file.
  bool next(LogEvent& event);

  const std::string& path() const { return path_; }
  std::uint64_t file_size() const { return file_size_; }
  /// Damage found so far (all of it once next() has returned false).
  const std::vector<LogDamage>& damage() const { return damage_; }

 private:
  /// Reads and checks an event header at offset; on success the event's channel and data.
  bool try_event_at(std::uint64_t offset, LogEvent& event, std::string& problem);
  /// Records damage from offset and finds the next offset holding a valid event (or the end).
  void resync(std::uint64_t offset, const std::string& what);
  bool read_at(std::uint64_t offset, void* buffer, std::size_t size);

  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t file_size_ = 0;
  std::uint64_t position_ = 0;
  std::vector<LogDamage> damage_;
};

/// Writes events to numbered files DIR/PREFIX-NNNN.lcmlog, starting a new file before one
/// would exceed max_file_bytes (an event larger than that gets a file of its own). It never
/// appends to or overwrites an existing file: numbering continues after the highest file of
/// that prefix already in the directory (LCM's logger could grow a file past its limit after
/// a restart). Event numbers continue across files.
class RotatingLogWriter {
 public:
  /// Creates the directory if needed; the first file is opened on the first write. Throws
  /// LogError if the directory cannot be made.
  RotatingLogWriter(std::string dir, std::string prefix, std::uint64_t max_file_bytes);
  ~RotatingLogWriter();
  RotatingLogWriter(const RotatingLogWriter&) = delete;
  RotatingLogWriter& operator=(const RotatingLogWriter&) = delete;

  /// Appends one event; throws LogError on an I/O error (the event is then not written).
  void write(const std::string& channel, const void* data, std::size_t size,
             std::int64_t timestamp_us);
  /// Pushes buffered events to the operating system (survives a crash of this process).
  void flush();
  /// Flushes and closes the current file.
  void close();

  /// Bytes of the event as stored (header, channel, data).
  static std::uint64_t event_bytes(std::size_t channel_size, std::size_t data_size) {
    return kEventHeaderSize + channel_size + data_size;
  }

  const std::string& current_path() const { return current_path_; }
  const std::vector<std::string>& files() const { return files_; }
  std::uint64_t bytes_written() const { return bytes_written_; }
  std::int64_t events_written() const { return events_written_; }
  int first_file_number() const { return first_number_; }

 private:
  void open_next();

  std::string dir_;
  std::string prefix_;
  std::uint64_t max_file_bytes_;
  _lcm_eventlog_t* log_ = nullptr;
  std::string current_path_;
  std::uint64_t current_bytes_ = 0;
  int next_number_ = 0;
  int first_number_ = 0;
  std::vector<std::string> files_;
  std::uint64_t bytes_written_ = 0;
  std::int64_t events_written_ = 0;
};

/// The log files to read for a command-line argument: the file itself, or for a directory its
/// *.lcmlog files in name order (the order the writer numbered them).
std::vector<std::string> expand_log_paths(const std::vector<std::string>& arguments);

/// An LCM timestamp (microseconds since the Unix epoch) as ISO 8601 UTC text.
std::string utc_text(std::int64_t utime);

}  // namespace auvrl::logger
