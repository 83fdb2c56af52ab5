#include "logger/event_log.hpp"

#include <lcm/eventlog.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

namespace auvrl::logger {

namespace fs = std::filesystem;

namespace {

std::uint64_t be_read(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

std::string hex32(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", value);
  return text;
}

/// The number NNNN of a file named PREFIX-NNNN.lcmlog, or -1.
int file_number(const std::string& name, const std::string& prefix) {
  const std::string head = prefix + "-";
  const std::string tail = ".lcmlog";
  if (name.size() <= head.size() + tail.size() || name.compare(0, head.size(), head) != 0 ||
      name.compare(name.size() - tail.size(), tail.size(), tail) != 0) {
    return -1;
  }
  const std::string digits = name.substr(head.size(), name.size() - head.size() - tail.size());
  if (digits.empty() || digits.size() > 8 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return -1;
  }
  return std::stoi(digits);
}

}  // namespace

// ---- LogReader ------------------------------------------------------------------------------

LogReader::LogReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) {
    throw LogError("cannot open log " + path + ": " + std::strerror(errno));
  }
  struct stat info {};
  if (fstat(fileno(file_), &info) != 0 || !S_ISREG(info.st_mode)) {
    std::fclose(file_);
    file_ = nullptr;
    throw LogError("log " + path + " is not a regular file");
  }
  file_size_ = static_cast<std::uint64_t>(info.st_size);
}

LogReader::~LogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

bool LogReader::read_at(std::uint64_t offset, void* buffer, std::size_t size) {
  if (offset + size > file_size_) return false;
  if (fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0) return false;
  return std::fread(buffer, 1, size, file_) == size;
}

bool LogReader::try_event_at(std::uint64_t offset, LogEvent& event, std::string& problem) {
  std::uint8_t header[kEventHeaderSize];
  if (!read_at(offset, header, sizeof header)) {
    problem = "truncated event header: " + std::to_string(file_size_ - offset) +
              " bytes at the end of the file, an event header is " +
              std::to_string(kEventHeaderSize);
    return false;
  }
  const auto sync = static_cast<std::uint32_t>(be_read(header, 4));
  if (sync != kEventSync) {
    problem = "bad sync word " + hex32(sync) + " (expected " + hex32(kEventSync) + ")";
    return false;
  }
  const auto channel_length = static_cast<std::uint32_t>(be_read(header + 20, 4));
  const auto data_length = static_cast<std::uint32_t>(be_read(header + 24, 4));
  if (channel_length == 0 || channel_length > kMaxChannelLength) {
    problem = "impossible channel length " + std::to_string(channel_length) + " (1 to " +
              std::to_string(kMaxChannelLength) + ")";
    return false;
  }
  if (data_length > kMaxDataLength) {
    problem = "impossible data length " + std::to_string(data_length) + " (LCM's limit is " +
              std::to_string(kMaxDataLength) + ")";
    return false;
  }
  const std::uint64_t end = offset + kEventHeaderSize + channel_length + data_length;
  if (end > file_size_) {
    problem = "truncated event: its header promises " +
              std::to_string(channel_length + data_length) + " bytes of channel and data, " +
              "the file holds " + std::to_string(file_size_ - offset - kEventHeaderSize);
    return false;
  }
  event.channel.resize(channel_length);
  if (!read_at(offset + kEventHeaderSize, event.channel.data(), channel_length)) {
    problem = "read error";
    return false;
  }
  for (const char c : event.channel) {
    if (c < 0x20 || c > 0x7e) {
      problem = "channel name is not printable text";
      return false;
    }
  }
  event.data.resize(data_length);
  if (data_length > 0 && std::fread(event.data.data(), 1, data_length, file_) != data_length) {
    problem = "read error";
    return false;
  }
  event.event_number = static_cast<std::int64_t>(be_read(header + 4, 8));
  event.timestamp_us = static_cast<std::int64_t>(be_read(header + 12, 8));
  event.offset = offset;
  return true;
}

void LogReader::resync(std::uint64_t offset, const std::string& what) {
  // Look for the next sync word that starts a valid event whose end is the end of the file or
  // another sync word: a sync pattern inside message data is then unlikely to be taken.
  std::uint64_t found = file_size_;
  std::vector<std::uint8_t> chunk(1 << 16);
  std::uint64_t base = offset + 1;
  LogEvent candidate;
  std::string ignored;
  while (base + 4 <= file_size_ && found == file_size_) {
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(chunk.size(), file_size_ - base));
    if (!read_at(base, chunk.data(), n)) break;
    for (std::size_t i = 0; i + 4 <= n; ++i) {
      if (be_read(&chunk[i], 4) != kEventSync) continue;
      const std::uint64_t at = base + i;
      if (!try_event_at(at, candidate, ignored)) continue;
      const std::uint64_t end =
          at + kEventHeaderSize + candidate.channel.size() + candidate.data.size();
      std::uint8_t next_sync[4];
      if (end + 4 > file_size_ ||
          (read_at(end, next_sync, 4) && be_read(next_sync, 4) == kEventSync)) {
        found = at;
        break;
      }
    }
    if (n < 4) break;
    base += n - 3;  // overlap so a sync word across chunks is seen
  }
  damage_.push_back({path_, offset, found - offset, what});
  position_ = found;
}

bool LogReader::next(LogEvent& event) {
  while (position_ < file_size_) {
    std::string problem;
    if (try_event_at(position_, event, problem)) {
      position_ += kEventHeaderSize + event.channel.size() + event.data.size();
      return true;
    }
    resync(position_, problem);
  }
  return false;
}

// ---- RotatingLogWriter ----------------------------------------------------------------------

RotatingLogWriter::RotatingLogWriter(std::string dir, std::string prefix,
                                     std::uint64_t max_file_bytes)
    : dir_(std::move(dir)), prefix_(std::move(prefix)), max_file_bytes_(max_file_bytes) {
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error || !fs::is_directory(dir_)) {
    throw LogError("cannot create the log directory " + dir_ + ": " + error.message());
  }
  int highest = -1;
  for (const auto& entry : fs::directory_iterator(dir_, error)) {
    highest = std::max(highest, file_number(entry.path().filename().string(), prefix_));
  }
  next_number_ = highest + 1;
  first_number_ = next_number_;
}

RotatingLogWriter::~RotatingLogWriter() { close(); }

void RotatingLogWriter::open_next() {
  close();
  char name[64];
  std::snprintf(name, sizeof name, "-%04d.lcmlog", next_number_);
  const std::string path = dir_ + "/" + prefix_ + name;
  if (fs::exists(path)) throw LogError("log file " + path + " already exists; not overwriting it");
  log_ = lcm_eventlog_create(path.c_str(), "w");
  if (log_ == nullptr) {
    throw LogError("cannot create log file " + path + ": " + std::strerror(errno));
  }
  log_->eventcount = events_written_;  // numbering continues across files
  ++next_number_;
  current_path_ = path;
  current_bytes_ = 0;
  files_.push_back(path);
}

void RotatingLogWriter::write(const std::string& channel, const void* data, std::size_t size,
                              std::int64_t timestamp_us) {
  if (size > kMaxDataLength || channel.empty() || channel.size() > kMaxChannelLength) {
    throw LogError("event on channel '" + channel + "' of " + std::to_string(size) +
                   " bytes cannot be logged (channel 1 to " + std::to_string(kMaxChannelLength) +
                   " bytes, data at most " + std::to_string(kMaxDataLength) + ")");
  }
  const std::uint64_t bytes = event_bytes(channel.size(), size);
  if (log_ == nullptr || (current_bytes_ > 0 && current_bytes_ + bytes > max_file_bytes_)) {
    open_next();
  }
  lcm_eventlog_event_t event{};
  event.timestamp = timestamp_us;
  event.channellen = static_cast<std::int32_t>(channel.size());
  event.datalen = static_cast<std::int32_t>(size);
  event.channel = const_cast<char*>(channel.data());
  event.data = const_cast<void*>(data);
  if (lcm_eventlog_write_event(log_, &event) != 0) {
    // Part of the event may be in the file: close it so that later events go to a fresh file
    // instead of following a torn one (readers will report the torn end).
    const std::string path = current_path_;
    const int saved_errno = errno;
    close();
    throw LogError("cannot write to log file " + path + ": " + std::strerror(saved_errno));
  }
  current_bytes_ += bytes;
  bytes_written_ += bytes;
  ++events_written_;
}

void RotatingLogWriter::flush() {
  if (log_ != nullptr && std::fflush(log_->f) != 0) {
    throw LogError("cannot flush log file " + current_path_ + ": " + std::strerror(errno));
  }
}

void RotatingLogWriter::close() {
  if (log_ == nullptr) return;
  lcm_eventlog_destroy(log_);  // flushes and closes
  log_ = nullptr;
}

std::vector<std::string> expand_log_paths(const std::vector<std::string>& arguments) {
  std::vector<std::string> paths;
  for (const std::string& argument : arguments) {
    std::error_code error;
    if (!fs::is_directory(argument, error)) {
      paths.push_back(argument);
      continue;
    }
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(argument, error)) {
      if (entry.is_regular_file() && entry.path().extension() == ".lcmlog") {
        found.push_back(entry.path().string());
      }
    }
    if (found.empty()) throw LogError("no .lcmlog files in directory " + argument);
    std::sort(found.begin(), found.end());
    paths.insert(paths.end(), found.begin(), found.end());
  }
  return paths;
}

std::string utc_text(std::int64_t utime) {
  const std::time_t t = static_cast<std::time_t>(utime / 1000000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[40];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace auvrl::logger
