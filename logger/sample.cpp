#include "logger/sample.hpp"

#include <cmath>
#include <cstring>
#include <string>

namespace auvrl::logger {

namespace {

/// splitmix64: small, fast, and the same sequence on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  /// Uniform in [lo, hi].
  std::int64_t range(std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  /// Mixed signs and magnitudes (1e-6 .. 1e6), never a trivial 0 or 1.
  double real() {
    const double mantissa = 1.0 + static_cast<double>(next() >> 11) / 9007199254740992.0;
    const double value = mantissa * std::pow(10.0, static_cast<double>(range(-6, 6)));
    return (next() & 1) != 0 ? -value : value;
  }

 private:
  std::uint64_t state_;
};

class SampleEncoder {
 public:
  SampleEncoder(std::uint64_t seed, const SampleOptions& options)
      : random_(seed), options_(options) {}

  void encode_struct(const StructType& type) {
    // Which integer members give array sizes: those get small values.
    std::vector<bool> is_size(type.members.size(), false);
    for (const Member& member : type.members) {
      for (const Dimension& dim : member.dimensions) {
        if (dim.variable) is_size[static_cast<std::size_t>(dim.size_member)] = true;
      }
    }
    std::vector<std::int64_t> scalars(type.members.size(), 0);
    for (std::size_t m = 0; m < type.members.size(); ++m) {
      const Member& member = type.members[m];
      if (member.dimensions.empty()) {
        if (is_size[m]) {
          scalars[m] = random_.range(options_.min_variable_length, options_.max_variable_length);
          write_integer(member.primitive, scalars[m]);
        } else {
          encode_element(member);
        }
        continue;
      }
      std::int64_t count = 1;
      for (const Dimension& dim : member.dimensions) {
        count *= dim.variable ? scalars[static_cast<std::size_t>(dim.size_member)] : dim.fixed_size;
      }
      for (std::int64_t i = 0; i < count; ++i) encode_element(member);
    }
  }

  std::vector<std::uint8_t>& bytes() { return bytes_; }

  void write_be(std::uint64_t value, int size) {
    for (int i = size - 1; i >= 0; --i)
      bytes_.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  }

 private:
  void write_integer(Primitive primitive, std::int64_t value) {
    switch (primitive) {
      case Primitive::kInt8:
        write_be(static_cast<std::uint64_t>(value), 1);
        break;
      case Primitive::kInt16:
        write_be(static_cast<std::uint64_t>(value), 2);
        break;
      case Primitive::kInt32:
        write_be(static_cast<std::uint64_t>(value), 4);
        break;
      default:
        write_be(static_cast<std::uint64_t>(value), 8);
        break;
    }
  }

  void encode_element(const Member& member) {
    if (!member.is_primitive) {
      encode_struct(*member.nested);
      return;
    }
    switch (member.primitive) {
      case Primitive::kInt8:
        write_be(static_cast<std::uint64_t>(random_.range(INT8_MIN, INT8_MAX)), 1);
        break;
      case Primitive::kByte:
        write_be(static_cast<std::uint64_t>(random_.range(0, 255)), 1);
        break;
      case Primitive::kBoolean:
        write_be(random_.next() & 1, 1);
        break;
      case Primitive::kInt16:
        write_be(static_cast<std::uint64_t>(random_.range(INT16_MIN, INT16_MAX)), 2);
        break;
      case Primitive::kInt32:
        write_be(static_cast<std::uint64_t>(random_.range(INT32_MIN, INT32_MAX)), 4);
        break;
      case Primitive::kInt64:
        write_be(random_.next(), 8);
        break;
      case Primitive::kFloat: {
        const float value = static_cast<float>(random_.real());
        std::uint32_t bits;
        std::memcpy(&bits, &value, sizeof bits);
        write_be(bits, 4);
        break;
      }
      case Primitive::kDouble: {
        const double value = random_.real();
        std::uint64_t bits;
        std::memcpy(&bits, &value, sizeof bits);
        write_be(bits, 8);
        break;
      }
      case Primitive::kString: {
        static const char* const kPieces[] = {"auv", " ",  "Nessie",   "\xc3\xa9",  "7",
                                              "_",   "-x", "\xce\xbb", "way point", ","};
        std::string text;
        const std::int64_t pieces = random_.range(0, 6);
        for (std::int64_t i = 0; i < pieces; ++i) text += kPieces[random_.range(0, 9)];
        write_be(text.size() + 1, 4);  // the length counts the NUL
        bytes_.insert(bytes_.end(), text.begin(), text.end());
        bytes_.push_back(0);
        break;
      }
    }
  }

  Random random_;
  SampleOptions options_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace

std::vector<std::uint8_t> make_sample_message(const StructType& type, std::uint64_t seed,
                                              const SampleOptions& options) {
  SampleEncoder encoder(seed, options);
  encoder.write_be(type.fingerprint, 8);
  encoder.encode_struct(type);
  return std::move(encoder.bytes());
}

}  // namespace auvrl::logger
