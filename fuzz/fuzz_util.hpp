// Helpers shared by the fuzz targets: reading a fuzz input as a sequence of records, scratch
// files for the parsers that read paths, and publishing raw bytes on the in-process transport.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <ostream>
#include <streambuf>
#include <string>
#include <vector>

#include "common/transport.hpp"

namespace auvrl::fuzz {

/// Reads a fuzz input front to back; reads past the end give zeros / empty spans.
class InputReader {
 public:
  InputReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return pos_ >= size_; }
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t u16() {
    const std::uint16_t lo = u8();
    return static_cast<std::uint16_t>(lo | (u8() << 8));
  }
  /// Up to n bytes (fewer at the end of the input).
  std::vector<std::uint8_t> bytes(std::size_t n) {
    n = std::min(n, size_ - std::min(pos_, size_));
    std::vector<std::uint8_t> out(data_ + pos_, data_ + pos_ + n);
    pos_ += n;
    return out;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// One message of a multi-message input: a selector byte (which channel; bit 7: put the
/// channel type's fingerprint in front of the body, so that mutations of the body alone
/// reach the decoder's checks) and a little-endian u16 length, then the bytes.
struct Record {
  std::uint8_t selector = 0;
  std::vector<std::uint8_t> bytes;
};

/// Splits an input into records.
inline std::vector<Record> read_records(const std::uint8_t* data, std::size_t size) {
  InputReader in(data, size);
  std::vector<Record> out;
  while (!in.empty() && out.size() < 64) {
    Record r;
    r.selector = in.u8();
    r.bytes = in.bytes(in.u16());
    out.push_back(std::move(r));
  }
  return out;
}

/// The bytes of a record as published: with the fingerprint of Msg in front when asked.
template <class Msg>
std::vector<std::uint8_t> message_bytes(const Record& r) {
  if ((r.selector & 0x80) == 0) return r.bytes;
  const auto hash = static_cast<std::uint64_t>(Msg::getHash());
  std::vector<std::uint8_t> out(8);
  for (int i = 0; i < 8; ++i) out[static_cast<std::size_t>(i)] = std::uint8_t(hash >> (56 - 8 * i));
  out.insert(out.end(), r.bytes.begin(), r.bytes.end());
  return out;
}

/// Decodes the record as Msg (with its fingerprint put in front when the selector asks), as a
/// subscription decodes what it receives; false when it does not decode.
template <class Msg>
bool decode_record(const Record& r, Msg& msg) {
  const std::vector<std::uint8_t> bytes = message_bytes<Msg>(r);
  return transport::decode_exact(bytes.data(), bytes.size(), msg);
}

/// Appends one record to a seed input (the generator uses it).
inline void append_record(std::vector<std::uint8_t>& out, std::uint8_t selector,
                          const std::vector<std::uint8_t>& bytes) {
  out.push_back(selector);
  out.push_back(static_cast<std::uint8_t>(bytes.size() & 0xFF));
  out.push_back(static_cast<std::uint8_t>((bytes.size() >> 8) & 0xFF));
  out.insert(out.end(), bytes.begin(), bytes.end());
}

/// An LCM-generated message's encoding (with its fingerprint).
template <class Msg>
std::vector<std::uint8_t> encode(const Msg& msg) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

/// The in-process transport (LCM memq://), made once per fuzzer process and never destroyed.
inline transport::Transport& in_process_transport() {
  static transport::Transport* t = transport::make_in_process_transport().release();
  return *t;
}

/// A scratch directory of this process (in /dev/shm when there is one), removed at exit.
inline const std::string& scratch_dir() {
  // Never destroyed: the exit handler that removes the directory runs after static destructors.
  static const std::string* dir = [] {
    const std::string base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp";
    std::string templ = base + "/auvrl-fuzz-XXXXXX";
    if (mkdtemp(templ.data()) == nullptr) std::abort();
    auto* kept = new std::string(templ);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratch_dir(), ec);
    });
    return kept;
  }();
  return *dir;
}

/// Writes data to path (replacing it); aborts if it cannot.
inline void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

/// An ostream that discards everything (the processes' logs).
class NullStream : public std::ostream {
 public:
  NullStream() : std::ostream(&buffer_) {}

 private:
  /// A stream buffer that accepts and drops every character.
  class NullBuffer : public std::streambuf {
   protected:
    int overflow(int c) override { return c; }
    std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
  };
  NullBuffer buffer_;
};

}  // namespace auvrl::fuzz
