// Every lcm-gen C++ type of the build (wire types and the logger's test types), as a table the
// tests iterate: a new .lcm file is covered without editing a test.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/transport.hpp"
#include "generated_type_list.hpp"
#include "logger/schema.hpp"

namespace auvrl::logger::test_types {

/// One generated type: its name, its generated fingerprint, and a decode/encode round trip
/// through the generated code.
struct GeneratedType {
  std::string full_name;
  std::uint64_t hash;
  /// Decodes bytes with the generated decode() (exactly one message, nothing left over) and
  /// encodes the result again with the generated encode(); false if the decode fails.
  bool (*reencode)(const std::vector<std::uint8_t>& in, std::vector<std::uint8_t>& out);
};

template <class Msg>
bool reencode(const std::vector<std::uint8_t>& in, std::vector<std::uint8_t>& out) {
  Msg msg;
  if (!transport::decode_exact(in.data(), in.size(), msg)) return false;
  out.assign(static_cast<std::size_t>(msg.getEncodedSize()), 0);
  return msg.encode(out.data(), 0, static_cast<int>(out.size())) == static_cast<int>(out.size());
}

inline std::vector<GeneratedType> generated_types() {
  std::vector<GeneratedType> types;
#define AUVRL_ADD_TYPE(package, type)                                                        \
  types.push_back({#package "." #type, static_cast<std::uint64_t>(package::type::getHash()), \
                   &reencode<package::type>});
  AUVRL_FOR_EACH_GENERATED_TYPE(AUVRL_ADD_TYPE)
#undef AUVRL_ADD_TYPE
  return types;
}

/// The schema of the wire types and the test types, read from their .lcm files.
inline Schema all_types_schema() {
  return Schema::from_directories({AUVRL_WIRE_TYPES_DIR, AUVRL_TEST_TYPES_DIR});
}

}  // namespace auvrl::logger::test_types
