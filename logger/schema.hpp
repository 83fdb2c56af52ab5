// A runtime model of LCM message types, read from the .lcm files themselves, so that the logger
// and the log tools decode every type of the system, current and future, without being rebuilt
// ("the logger knows only the wire types"). Fingerprints are computed exactly as lcm-gen
// computes them, so a message is matched to its type the way lcm-spy and the generated code
// match it: by the 8-byte fingerprint in front of every encoded message.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace auvrl::logger {

/// A .lcm file (or directory) that could not be read or parsed, or a type that cannot be
/// resolved; the message names the file, line and what was expected.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// LCM's primitive types (lcm-gen's list: there are no unsigned types).
enum class Primitive { kInt8, kInt16, kInt32, kInt64, kByte, kFloat, kDouble, kString, kBoolean };

/// The LCM spelling of a primitive ("int8_t", "byte", ...).
const char* primitive_name(Primitive primitive);

/// Fewest bytes one value of a primitive encodes to (a string: length and NUL, 5).
std::uint64_t primitive_min_size(Primitive primitive);

struct StructType;

/// One array dimension of a member: a constant size ("[3]") or the value of an earlier integer
/// member of the same struct ("[num_thrusters]").
struct Dimension {
  bool variable = false;
  std::string size_text;        ///< as written in the .lcm file (it enters the fingerprint)
  std::int64_t fixed_size = 0;  ///< constant size (variable == false)
  int size_member = -1;         ///< index of the size member (variable == true)
};

/// One member (field) of a struct.
struct Member {
  std::string name;
  std::string type_name;  ///< primitive name, or the nested type's full name "package.type"
  bool is_primitive = false;
  Primitive primitive = Primitive::kInt8;  ///< when is_primitive
  const StructType* nested = nullptr;      ///< when not primitive (set by resolution)
  std::vector<Dimension> dimensions;       ///< empty for a scalar
  int line = 0;                            ///< line in the .lcm file, for error messages
};

/// A named constant of a struct ("const int8_t STATUS_OK = 0"): not part of the encoding.
struct Constant {
  std::string type_name;
  std::string name;
  std::string value_text;
};

/// One LCM struct type as declared in a .lcm file.
struct StructType {
  std::string package;     ///< "" when the file has no package directive
  std::string short_name;  ///< "vehicle_state_t"
  std::string full_name;   ///< "auvrl_lcm.vehicle_state_t" (short_name when no package)
  std::string source;      ///< the .lcm file it came from
  int line = 0;
  std::vector<Member> members;
  std::vector<Constant> constants;
  /// lcm-gen's hash of this struct alone (member names, primitive type names, dimensions).
  std::uint64_t base_hash = 0;
  /// The fingerprint every encoded message starts with: base_hash combined with the nested
  /// types' hashes (lcm-gen's _computeHash), as the generated getHash() returns it.
  std::uint64_t fingerprint = 0;
  /// Fewest bytes one encoded instance can take (without the fingerprint): used to refuse
  /// array lengths that cannot fit in the bytes at hand before allocating anything.
  std::uint64_t min_encoded_size = 0;
};

/// A set of LCM types, parsed from .lcm text, with nested types resolved and fingerprints
/// computed. Immutable once built; safe to share between threads for reading.
class Schema {
 public:
  /// Parses every *.lcm file in the directories (not recursive). Throws SchemaError.
  static Schema from_directories(const std::vector<std::string>& directories);
  /// Parses the given .lcm files. Throws SchemaError.
  static Schema from_files(const std::vector<std::string>& paths);
  /// Parses .lcm sources given as (name for messages, text) pairs. Throws SchemaError.
  static Schema from_sources(const std::vector<std::pair<std::string, std::string>>& sources);

  Schema(Schema&&) = default;
  Schema& operator=(Schema&&) = default;

  /// All types, in the order they were parsed.
  const std::vector<std::unique_ptr<StructType>>& types() const { return types_; }
  /// The type whose fingerprint is given (the first one read if several types share it), or
  /// nullptr.
  const StructType* find_by_fingerprint(std::uint64_t fingerprint) const;
  /// Every type name with this fingerprint ("a.x_t or a.y_t"), or "unknown type 0x...".
  std::string names_for(std::uint64_t fingerprint) const;
  /// The type with this full name ("auvrl_lcm.vehicle_state_t") or, when unambiguous, this
  /// short name ("vehicle_state_t"); nullptr if none.
  const StructType* find_by_name(const std::string& name) const;

 private:
  Schema() = default;
  void resolve();

  std::vector<std::unique_ptr<StructType>> types_;
  std::map<std::uint64_t, std::vector<const StructType*>> by_fingerprint_;
  std::map<std::string, const StructType*> by_full_name_;
};

/// lcm-gen's hash of one struct's own declaration (lcmgen.c, lcm_struct_hash).
std::uint64_t lcm_base_hash(const StructType& type);

/// The compiled-in default directory of the project's .lcm files (overridable by --types-dir).
std::string default_types_dir();

/// Formats a fingerprint as lcm-gen prints it: 0x followed by 16 hex digits.
std::string fingerprint_hex(std::uint64_t fingerprint);

}  // namespace auvrl::logger
