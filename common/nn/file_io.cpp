#include "common/nn/file_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace auvrl::nn {
namespace {

[[noreturn]] void throw_errno(const std::string& what, const std::string& path) {
  throw std::runtime_error(what + " '" + path + "': " + std::strerror(errno));
}

// Buffered sink on a file descriptor: checkpoints are written in large pieces.
class FdSink final : public ByteSink {
 public:
  FdSink(int fd, std::string path) : fd_(fd), path_(std::move(path)) { buf_.reserve(kBuf); }
  void write(const void* data, std::size_t n) override {
    const auto* p = static_cast<const std::uint8_t*>(data);
    if (buf_.size() + n > kBuf) flush();
    if (n >= kBuf) {
      write_all(p, n);
    } else {
      buf_.insert(buf_.end(), p, p + n);
    }
  }
  void flush() {
    write_all(buf_.data(), buf_.size());
    buf_.clear();
  }

 private:
  static constexpr std::size_t kBuf = std::size_t{1} << 20;
  void write_all(const std::uint8_t* p, std::size_t n) {
    while (n > 0) {
      const ssize_t k = ::write(fd_, p, n);
      if (k < 0) {
        if (errno == EINTR) continue;
        throw_errno("cannot write", path_);
      }
      p += k;
      n -= static_cast<std::size_t>(k);
    }
  }
  int fd_;
  std::string path_;
  std::vector<std::uint8_t> buf_;
};

}  // namespace

void write_file_atomically(const std::string& path, const std::function<void(ByteSink&)>& fill) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_errno("cannot create", tmp);
  bool fd_open = true;
  try {
    FdSink sink(fd, tmp);
    fill(sink);
    sink.flush();
    if (::fsync(fd) != 0) throw_errno("cannot flush", tmp);
    fd_open = false;
    if (::close(fd) != 0) throw_errno("cannot close", tmp);
  } catch (...) {
    if (fd_open) ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    throw_errno("cannot rename " + tmp + " to", path);
  }
}

void write_file_atomically(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  write_file_atomically(path, [&](ByteSink& sink) { sink.write(bytes.data(), bytes.size()); });
}

std::vector<std::uint8_t> read_file(const std::string& path) {
  // A directory opens as a stream, with a size that is not a file's.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw std::runtime_error("'" + path + "' is a directory, not a file");
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error("cannot open '" + path + "' for reading");
  const std::streamoff size = in.tellg();
  if (size < 0) throw std::runtime_error("cannot determine the size of '" + path + "'");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), size);
  if (in.gcount() != size) throw std::runtime_error("cannot read '" + path + "'");
  return bytes;
}

}  // namespace auvrl::nn
