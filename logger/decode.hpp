// Decodes any encoded LCM message of a Schema's types field by field into a flat list of
// (column name, value): nested structs become "outer.inner", arrays one column per element with
// indexed names ("thrust_n[3]", "states[3][12]", "points[1].xyz[2]"). Every read is bounds
// checked: malformed bytes give an error naming the field and byte offset, never a crash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "logger/schema.hpp"

namespace auvrl::logger {

/// One column of a decoded message.
struct FieldValue {
  std::string name;
  Primitive type = Primitive::kInt8;
  /// A byte array's innermost dimension kept whole (see DecodeOptions): text holds the bytes.
  bool blob = false;
  std::int64_t integer = 0;  ///< int8_t..int64_t, byte (0..255), boolean (0 or 1)
  double real = 0.0;         ///< float (widened exactly), double
  std::string text;          ///< string (its bytes, without the NUL), or the blob's bytes
};

/// How to flatten.
struct DecodeOptions {
  /// true: the innermost dimension of a `byte` array is one column holding all its bytes
  /// (written as hex), because byte arrays are binary blobs (a 0.5 MB policy network would
  /// otherwise be half a million columns). false: one column per byte, like other arrays.
  bool byte_arrays_as_blobs = true;
};

/// Why a message did not decode.
enum class DecodeStatus {
  kOk,
  kUnknownType,  ///< fingerprint of no type in the schema (not an error in the bytes)
  kMalformed,    ///< known fingerprint, but the bytes do not hold one message of that type
};

/// A decoded message: its type and its columns in encoding order.
struct DecodedMessage {
  const StructType* type = nullptr;
  std::uint64_t fingerprint = 0;
  std::vector<FieldValue> fields;
};

/// Decodes a whole encoded message (the 8-byte fingerprint, then the body, nothing after).
/// On failure, error says what is wrong: field, byte offset, what was expected.
DecodeStatus decode_message(const Schema& schema, const std::uint8_t* data, std::size_t size,
                            DecodedMessage& out, std::string& error,
                            const DecodeOptions& options = {});

/// Reads the big-endian fingerprint at the start of an encoded message; false if shorter.
bool read_fingerprint(const std::uint8_t* data, std::size_t size, std::uint64_t& fingerprint);

/// A value as text for CSV and comparisons: integers in decimal, booleans 0/1, float with 9
/// and double with 17 significant digits (both read back exactly), strings as they are, blobs
/// as lower-case hex.
std::string format_value(const FieldValue& field);

/// Where a column of type's messages sits in encoding order, as a sortable key: for each step
/// of the name the member's index in its struct, then the array indices ("points[1].xyz[2]" of
/// nested_arrays_t gives {8, 1, 0, 2}). Sorting by it puts "thrust_n[6]" right after
/// "thrust_n[5]" and "actions[0][3]" before "actions[1][0]", whatever lengths the messages had.
/// A name that is not a column of type sorts after all that are.
std::vector<std::int64_t> column_order_key(const StructType& type, const std::string& column);

/// Lower-case hex of bytes.
std::string to_hex(const std::string& bytes);

}  // namespace auvrl::logger
