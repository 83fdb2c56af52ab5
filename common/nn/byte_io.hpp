// Little-endian binary writing and reading with a running CRC-32, shared by every serialised
// format of the learning core (networks, optimiser state, replay buffer, learner state).
#pragma once

#include <cstddef>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "common/nn/checksum.hpp"

namespace auvrl::nn {

/// Destination of serialised bytes.
class ByteSink {
 public:
  virtual ~ByteSink() = default;
  /// Writes all n bytes or throws std::runtime_error.
  virtual void write(const void* data, std::size_t n) = 0;
};

/// Appends to a byte vector (for messages).
class VectorSink final : public ByteSink {
 public:
  explicit VectorSink(std::vector<std::uint8_t>& out) : out_(out) {}
  void write(const void* data, std::size_t n) override;

 private:
  std::vector<std::uint8_t>& out_;
};

/// Writes to a std::ostream (for checkpoints); throws std::runtime_error when the stream fails.
class OStreamSink final : public ByteSink {
 public:
  explicit OStreamSink(std::ostream& os) : os_(os) {}
  void write(const void* data, std::size_t n) override;

 private:
  std::ostream& os_;
};

/// Origin of serialised bytes.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Reads up to n bytes and returns how many were read: fewer than n only at the end.
  virtual std::size_t read(void* data, std::size_t n) = 0;
};

/// Reads from a byte buffer the caller keeps alive.
class SpanSource final : public ByteSource {
 public:
  SpanSource(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  explicit SpanSource(const std::vector<std::uint8_t>& v) : SpanSource(v.data(), v.size()) {}
  std::size_t read(void* data, std::size_t n) override;
  /// Bytes not read yet.
  std::size_t remaining() const { return size_ - pos_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// Reads from a std::istream.
class IStreamSource final : public ByteSource {
 public:
  explicit IStreamSource(std::istream& is) : is_(is) {}
  std::size_t read(void* data, std::size_t n) override;

 private:
  std::istream& is_;
};

/// Writes little-endian scalars and arrays whatever the host byte order, and keeps the CRC-32 of
/// every byte written so that checksum() can seal the record.
class Writer {
 public:
  explicit Writer(ByteSink& sink) : sink_(sink) {}

  void bytes(const void* data, std::size_t n);
  void u8(std::uint8_t v) { bytes(&v, 1); }
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void f32(float v);
  void f64(double v);
  void f32_array(const float* data, std::size_t n);
  void u32_array(const std::uint32_t* data, std::size_t n);
  void u64_array(const std::uint64_t* data, std::size_t n);
  /// Length (u32) then the characters.
  void string(const std::string& s);
  /// Appends the CRC-32 of every byte written so far (the CRC itself is not covered).
  void checksum();
  /// Bytes written so far.
  std::uint64_t size() const { return count_; }

 private:
  ByteSink& sink_;
  Crc32 crc_;
  std::uint64_t count_ = 0;
};

/// Reads what Writer wrote. Every failure throws std::runtime_error whose message starts with the
/// context given at construction (e.g. "actor network") and says what was expected and where.
class Reader {
 public:
  Reader(ByteSource& source, std::string context) : source_(source), context_(std::move(context)) {}

  void bytes(void* data, std::size_t n);
  std::uint8_t u8();
  std::uint32_t u32();
  std::uint64_t u64();
  float f32();
  double f64();
  void f32_array(float* data, std::size_t n);
  void u32_array(std::uint32_t* data, std::size_t n);
  void u64_array(std::uint64_t* data, std::size_t n);
  /// A string written by Writer::string; longer than max_size is an error.
  std::string string(std::size_t max_size);
  /// Reads an 8-byte magic and fails unless it equals `magic` (8 characters).
  void expect_magic(const char* magic);
  /// Reads the stored CRC-32 and fails unless it equals the CRC of everything read before it.
  void verify_checksum();
  /// Throws std::runtime_error("<context>: <what> (at byte <offset>)").
  [[noreturn]] void fail(const std::string& what) const;
  /// Bytes read so far.
  std::uint64_t offset() const { return count_; }
  const std::string& context() const { return context_; }

 private:
  ByteSource& source_;
  std::string context_;
  Crc32 crc_;
  std::uint64_t count_ = 0;
};

}  // namespace auvrl::nn
