// CRC-32 for the serialised formats (networks, optimiser state, replay buffer, learner state).
#pragma once

#include <cstddef>
#include <cstdint>

namespace auvrl::nn {

/// Running CRC-32, computed by zlib's crc32 (IEEE 802.3 / zlib / PNG: reflected polynomial
/// 0xEDB88320, initial value and final XOR 0xFFFFFFFF), so a stored value can be checked with
/// `zlib.crc32` or `crc32(1)`. Check value: crc32("123456789") = 0xCBF43926.
class Crc32 {
 public:
  /// Feeds n bytes; calls may be split anywhere (the result does not depend on the split).
  void update(const void* data, std::size_t n);
  /// The CRC of every byte fed so far.
  std::uint32_t value() const { return value_; }

 private:
  std::uint32_t value_ = 0;  // zlib's CRC of no bytes
};

/// CRC-32 of one buffer (same algorithm as Crc32).
std::uint32_t crc32(const void* data, std::size_t n);

}  // namespace auvrl::nn
