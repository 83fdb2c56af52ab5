#include "common/nn/checksum.hpp"

#include <zlib.h>

#include <algorithm>
#include <limits>

namespace auvrl::nn {

void Crc32::update(const void* data, std::size_t n) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong crc = value_;
  // crc32_z takes a z_size_t; chunks keep any size within it on every platform.
  constexpr std::size_t kChunk = std::numeric_limits<unsigned int>::max();
  while (n > 0) {
    const std::size_t len = std::min(n, kChunk);
    crc = crc32_z(crc, p, static_cast<z_size_t>(len));
    p += len;
    n -= len;
  }
  value_ = static_cast<std::uint32_t>(crc);
}

std::uint32_t crc32(const void* data, std::size_t n) {
  Crc32 c;
  c.update(data, n);
  return c.value();
}

}  // namespace auvrl::nn
