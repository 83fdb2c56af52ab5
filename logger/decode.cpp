#include "logger/decode.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace auvrl::logger {

namespace {

/// Arrays whose elements can encode to zero bytes (structs of only variable arrays) are not
/// bounded by the message size; this caps their length so a corrupt count cannot spin.
constexpr std::uint64_t kMaxZeroSizeElements = 1u << 20;

std::uint64_t element_min_size(const Member& member) {
  return member.is_primitive ? primitive_min_size(member.primitive)
                             : member.nested->min_encoded_size;
}

/// Walks the bytes of one message body with a cursor, appending columns.
class BodyDecoder {
 public:
  BodyDecoder(const std::uint8_t* data, std::size_t size, std::size_t start,
              const DecodeOptions& options, std::vector<FieldValue>& out)
      : data_(data), size_(size), pos_(start), options_(options), out_(out) {}

  bool decode_struct(const StructType& type, const std::string& prefix) {
    // Integer scalars decoded so far in this instance: the sizes of its variable arrays.
    std::vector<std::int64_t> scalars(type.members.size(), 0);
    for (std::size_t m = 0; m < type.members.size(); ++m) {
      const Member& member = type.members[m];
      const std::string name = prefix + member.name;
      if (member.dimensions.empty()) {
        if (!decode_element(member, name, &scalars[m])) return false;
        continue;
      }
      if (!decode_array(type, member, scalars, name)) return false;
    }
    return true;
  }

  std::size_t position() const { return pos_; }
  const std::string& error() const { return error_; }

 private:
  bool fail(const std::string& field, const std::string& what) {
    error_ = field + " at byte " + std::to_string(pos_) + ": " + what;
    return false;
  }

  bool need(const std::string& field, std::size_t bytes) {
    if (size_ - pos_ >= bytes) return true;
    return fail(field, "needs " + std::to_string(bytes) + " bytes, only " +
                           std::to_string(size_ - pos_) + " left in the message");
  }

  std::uint64_t read_be(int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | data_[pos_ + static_cast<std::size_t>(i)];
    pos_ += static_cast<std::size_t>(bytes);
    return v;
  }

  bool decode_array(const StructType& type, const Member& member,
                    const std::vector<std::int64_t>& scalars, const std::string& name) {
    std::vector<std::int64_t> sizes;
    std::uint64_t total = 1;
    for (const Dimension& dim : member.dimensions) {
      std::int64_t n = dim.fixed_size;
      if (dim.variable) {
        n = scalars[static_cast<std::size_t>(dim.size_member)];
        if (n < 0) {
          return fail(name, "array length " + type.members[dim.size_member].name + " = " +
                                std::to_string(n) + " is negative");
        }
      }
      sizes.push_back(n);
      const auto un = static_cast<std::uint64_t>(n);
      total = (un == 0 || total == 0) ? 0 : (total > UINT64_MAX / un ? UINT64_MAX : total * un);
    }
    // Refuse lengths that cannot fit in what is left before allocating or looping over them.
    const std::uint64_t min_size = element_min_size(member);
    const std::uint64_t left = size_ - pos_;
    if (min_size == 0 ? total > kMaxZeroSizeElements : total > left / min_size) {
      return fail(name, "array of " + std::to_string(total) + " elements of at least " +
                            std::to_string(min_size) + " bytes cannot fit in the " +
                            std::to_string(left) + " bytes left");
    }
    const bool blob = options_.byte_arrays_as_blobs && member.is_primitive &&
                      member.primitive == Primitive::kByte;
    const std::size_t outer_dims = blob ? sizes.size() - 1 : sizes.size();
    std::vector<std::int64_t> index(outer_dims, 0);
    for (std::size_t d = 0; d < outer_dims; ++d) {
      if (sizes[d] == 0) return true;
    }
    std::string element_name;
    while (true) {
      element_name = name;
      for (const std::int64_t i : index) element_name += "[" + std::to_string(i) + "]";
      if (blob) {
        const auto length = static_cast<std::size_t>(sizes.back());
        if (!need(element_name, length)) return false;
        FieldValue field;
        field.name = element_name;
        field.type = Primitive::kByte;
        field.blob = true;
        field.text.assign(reinterpret_cast<const char*>(data_ + pos_), length);
        pos_ += length;
        out_.push_back(std::move(field));
      } else if (!decode_element(member, element_name, nullptr)) {
        return false;
      }
      // Next index, last dimension fastest (the order lcm-gen encodes in).
      std::size_t d = outer_dims;
      while (d > 0) {
        --d;
        if (++index[d] < sizes[d]) break;
        index[d] = 0;
        if (d == 0) return true;
      }
      if (outer_dims == 0) return true;
    }
  }

  /// Decodes one scalar element (primitive or nested struct); stores integer values in
  /// *scalar when given (possible array sizes).
  bool decode_element(const Member& member, const std::string& name, std::int64_t* scalar) {
    if (!member.is_primitive) return decode_struct(*member.nested, name + ".");
    FieldValue field;
    field.name = name;
    field.type = member.primitive;
    switch (member.primitive) {
      case Primitive::kInt8:
        if (!need(name, 1)) return false;
        field.integer = static_cast<std::int8_t>(read_be(1));
        break;
      case Primitive::kByte:
        if (!need(name, 1)) return false;
        field.integer = static_cast<std::uint8_t>(read_be(1));
        break;
      case Primitive::kBoolean:
        if (!need(name, 1)) return false;
        field.integer = read_be(1) != 0 ? 1 : 0;
        break;
      case Primitive::kInt16:
        if (!need(name, 2)) return false;
        field.integer = static_cast<std::int16_t>(read_be(2));
        break;
      case Primitive::kInt32:
        if (!need(name, 4)) return false;
        field.integer = static_cast<std::int32_t>(read_be(4));
        break;
      case Primitive::kInt64:
        if (!need(name, 8)) return false;
        field.integer = static_cast<std::int64_t>(read_be(8));
        break;
      case Primitive::kFloat: {
        if (!need(name, 4)) return false;
        const auto bits = static_cast<std::uint32_t>(read_be(4));
        float value;
        std::memcpy(&value, &bits, sizeof value);
        field.real = value;
        break;
      }
      case Primitive::kDouble: {
        if (!need(name, 8)) return false;
        const std::uint64_t bits = read_be(8);
        double value;
        std::memcpy(&value, &bits, sizeof value);
        field.real = value;
        break;
      }
      case Primitive::kString: {
        if (!need(name, 4)) return false;
        const auto length = static_cast<std::int32_t>(read_be(4));
        // The encoded length counts the terminating NUL.
        if (length < 1) {
          pos_ -= 4;
          return fail(name, "string length " + std::to_string(length) +
                                " (it counts the NUL, so it is at least 1)");
        }
        if (!need(name, static_cast<std::size_t>(length))) return false;
        // LCM strings are C strings: the generated code cannot carry a NUL before the end
        // (it re-encodes up to the first one), so neither may the decoder.
        if (std::memchr(data_ + pos_, 0, static_cast<std::size_t>(length) - 1) != nullptr) {
          return fail(name, "a NUL byte inside the string (LCM strings end at their first NUL)");
        }
        field.text.assign(reinterpret_cast<const char*>(data_ + pos_),
                          static_cast<std::size_t>(length) - 1);
        pos_ += static_cast<std::size_t>(length);
        break;
      }
    }
    if (scalar != nullptr) *scalar = field.integer;
    out_.push_back(std::move(field));
    return true;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_;
  const DecodeOptions& options_;
  std::vector<FieldValue>& out_;
  std::string error_;
};

}  // namespace

bool read_fingerprint(const std::uint8_t* data, std::size_t size, std::uint64_t& fingerprint) {
  if (size < 8) return false;
  fingerprint = 0;
  for (int i = 0; i < 8; ++i) fingerprint = (fingerprint << 8) | data[i];
  return true;
}

DecodeStatus decode_message(const Schema& schema, const std::uint8_t* data, std::size_t size,
                            DecodedMessage& out, std::string& error, const DecodeOptions& options) {
  out.type = nullptr;
  out.fields.clear();
  error.clear();
  if (!read_fingerprint(data, size, out.fingerprint)) {
    error = "message of " + std::to_string(size) + " bytes is shorter than its 8-byte fingerprint";
    return DecodeStatus::kMalformed;
  }
  out.type = schema.find_by_fingerprint(out.fingerprint);
  if (out.type == nullptr) {
    error = "unknown type " + fingerprint_hex(out.fingerprint) +
            " (no .lcm file in the types directory has this fingerprint)";
    return DecodeStatus::kUnknownType;
  }
  BodyDecoder decoder(data, size, 8, options, out.fields);
  if (!decoder.decode_struct(*out.type, "")) {
    error = out.type->full_name + "." + decoder.error();
    return DecodeStatus::kMalformed;
  }
  if (decoder.position() != size) {
    error = out.type->full_name + ": " + std::to_string(size - decoder.position()) +
            " bytes left over after the message (it ends at byte " +
            std::to_string(decoder.position()) + ")";
    return DecodeStatus::kMalformed;
  }
  return DecodeStatus::kOk;
}

std::vector<std::int64_t> column_order_key(const StructType& type, const std::string& column) {
  std::vector<std::int64_t> key;
  const StructType* current = &type;
  std::size_t pos = 0;
  while (pos < column.size() && current != nullptr) {
    const std::size_t end = std::min(column.find_first_of("[.", pos), column.size());
    const std::string member = column.substr(pos, end - pos);
    std::int64_t index = -1;
    for (std::size_t m = 0; m < current->members.size(); ++m) {
      if (current->members[m].name == member) index = static_cast<std::int64_t>(m);
    }
    if (index < 0) {
      key.push_back(INT64_MAX);
      return key;
    }
    key.push_back(index);
    pos = end;
    while (pos < column.size() && column[pos] == '[') {
      const std::size_t close = column.find(']', pos);
      if (close == std::string::npos) {
        key.push_back(INT64_MAX);
        return key;
      }
      key.push_back(std::strtoll(column.c_str() + pos + 1, nullptr, 10));
      pos = close + 1;
    }
    if (pos < column.size() && column[pos] == '.') {
      current = current->members[static_cast<std::size_t>(index)].nested;
      ++pos;
    }
  }
  return key;
}

std::string to_hex(const std::string& bytes) {
  static const char kDigits[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(bytes.size() * 2);
  for (const char c : bytes) {
    const auto b = static_cast<unsigned char>(c);
    hex += kDigits[b >> 4];
    hex += kDigits[b & 15];
  }
  return hex;
}

std::string format_value(const FieldValue& field) {
  if (field.blob) return to_hex(field.text);
  char text[40];
  switch (field.type) {
    case Primitive::kString:
      return field.text;
    case Primitive::kFloat:
      std::snprintf(text, sizeof text, "%.9g", field.real);
      return text;
    case Primitive::kDouble:
      std::snprintf(text, sizeof text, "%.17g", field.real);
      return text;
    default:
      std::snprintf(text, sizeof text, "%" PRId64, field.integer);
      return text;
  }
}

}  // namespace auvrl::logger
