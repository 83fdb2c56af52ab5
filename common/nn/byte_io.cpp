#include "common/nn/byte_io.hpp"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace auvrl::nn {
namespace {

constexpr bool kLittleEndianHost = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

template <typename T>
T byte_swap(T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  std::memcpy(&v, b, sizeof(T));
  return v;
}

template <typename T>
T to_little(T v) {
  if constexpr (kLittleEndianHost) {
    return v;
  } else {
    return byte_swap(v);
  }
}

}  // namespace

void VectorSink::write(const void* data, std::size_t n) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  out_.insert(out_.end(), p, p + n);
}

void OStreamSink::write(const void* data, std::size_t n) {
  os_.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  if (!os_) throw std::runtime_error("write failed (output stream error)");
}

std::size_t SpanSource::read(void* data, std::size_t n) {
  const std::size_t k = std::min(n, size_ - pos_);
  if (k > 0) std::memcpy(data, data_ + pos_, k);
  pos_ += k;
  return k;
}

std::size_t IStreamSource::read(void* data, std::size_t n) {
  is_.read(static_cast<char*>(data), static_cast<std::streamsize>(n));
  return static_cast<std::size_t>(is_.gcount());
}

void Writer::bytes(const void* data, std::size_t n) {
  sink_.write(data, n);
  crc_.update(data, n);
  count_ += n;
}

void Writer::u32(std::uint32_t v) {
  v = to_little(v);
  bytes(&v, sizeof v);
}

void Writer::u64(std::uint64_t v) {
  v = to_little(v);
  bytes(&v, sizeof v);
}

void Writer::f32(float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  u32(u);
}

void Writer::f64(double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, sizeof u);
  u64(u);
}

void Writer::f32_array(const float* data, std::size_t n) {
  if constexpr (kLittleEndianHost) {
    bytes(data, n * sizeof(float));
  } else {
    for (std::size_t i = 0; i < n; ++i) f32(data[i]);
  }
}

void Writer::u32_array(const std::uint32_t* data, std::size_t n) {
  if constexpr (kLittleEndianHost) {
    bytes(data, n * sizeof(std::uint32_t));
  } else {
    for (std::size_t i = 0; i < n; ++i) u32(data[i]);
  }
}

void Writer::u64_array(const std::uint64_t* data, std::size_t n) {
  if constexpr (kLittleEndianHost) {
    bytes(data, n * sizeof(std::uint64_t));
  } else {
    for (std::size_t i = 0; i < n; ++i) u64(data[i]);
  }
}

void Writer::string(const std::string& s) {
  u32(static_cast<std::uint32_t>(s.size()));
  bytes(s.data(), s.size());
}

void Writer::checksum() {
  const std::uint32_t c = to_little(crc_.value());
  // Not through bytes(): the CRC does not cover itself.
  sink_.write(&c, sizeof c);
  count_ += sizeof c;
}

void Reader::fail(const std::string& what) const {
  std::ostringstream os;
  os << context_ << ": " << what << " (at byte " << count_ << ")";
  throw std::runtime_error(os.str());
}

void Reader::bytes(void* data, std::size_t n) {
  const std::size_t got = source_.read(data, n);
  if (got != n) {
    std::ostringstream os;
    os << "truncated: needed " << n << " more bytes, only " << got << " left";
    fail(os.str());
  }
  crc_.update(data, n);
  count_ += n;
}

std::uint8_t Reader::u8() {
  std::uint8_t v;
  bytes(&v, 1);
  return v;
}

std::uint32_t Reader::u32() {
  std::uint32_t v;
  bytes(&v, sizeof v);
  return to_little(v);
}

std::uint64_t Reader::u64() {
  std::uint64_t v;
  bytes(&v, sizeof v);
  return to_little(v);
}

float Reader::f32() {
  const std::uint32_t u = u32();
  float v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

double Reader::f64() {
  const std::uint64_t u = u64();
  double v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

void Reader::f32_array(float* data, std::size_t n) {
  if constexpr (kLittleEndianHost) {
    bytes(data, n * sizeof(float));
  } else {
    for (std::size_t i = 0; i < n; ++i) data[i] = f32();
  }
}

void Reader::u32_array(std::uint32_t* data, std::size_t n) {
  if constexpr (kLittleEndianHost) {
    bytes(data, n * sizeof(std::uint32_t));
  } else {
    for (std::size_t i = 0; i < n; ++i) data[i] = u32();
  }
}

void Reader::u64_array(std::uint64_t* data, std::size_t n) {
  if constexpr (kLittleEndianHost) {
    bytes(data, n * sizeof(std::uint64_t));
  } else {
    for (std::size_t i = 0; i < n; ++i) data[i] = u64();
  }
}

std::string Reader::string(std::size_t max_size) {
  const std::uint32_t n = u32();
  if (n > max_size) {
    fail("string of " + std::to_string(n) + " bytes, more than the " + std::to_string(max_size) +
         " allowed");
  }
  std::string s(n, '\0');
  bytes(s.data(), n);
  return s;
}

void Reader::expect_magic(const char* magic) {
  char got[8];
  bytes(got, 8);
  if (std::memcmp(got, magic, 8) != 0) {
    std::string printable;
    for (char c : got) printable += (c >= 32 && c < 127) ? c : '?';
    // The magic ends in a NUL: print it as text up to there, so the message is not cut.
    fail("bad magic: expected '" + std::string(magic, strnlen(magic, 8)) + "', got '" + printable +
         "' (not this kind of file, or damaged)");
  }
}

void Reader::verify_checksum() {
  const std::uint32_t computed = crc_.value();
  std::uint32_t stored;
  const std::size_t got = source_.read(&stored, sizeof stored);
  if (got != sizeof stored) fail("truncated: the CRC-32 at the end is missing");
  count_ += sizeof stored;
  stored = to_little(stored);
  if (stored != computed) {
    std::ostringstream os;
    os << std::hex << "checksum mismatch: stored CRC-32 0x" << stored << ", computed 0x" << computed
       << " (corrupted data)";
    fail(os.str());
  }
}

}  // namespace auvrl::nn
