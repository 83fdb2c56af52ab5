// Makes valid encoded messages of any Schema type filled with non-trivial pseudo-random values:
// for tests (every type, current and future, checked against the generated C++ and the Java
// jar without hand-written fillers) and for demo traffic (lcm-spy on every type).
#pragma once

#include <cstdint>
#include <vector>

#include "logger/schema.hpp"

namespace auvrl::logger {

/// What the sample messages look like.
struct SampleOptions {
  /// Variable array lengths are drawn from [min_variable_length, max_variable_length].
  std::int64_t min_variable_length = 1;
  std::int64_t max_variable_length = 4;
};

/// One encoded message of type (fingerprint first), values drawn from a generator seeded with
/// seed: the same seed gives the same bytes. Integers span their type's range (except array
/// sizes), floats and doubles mix signs and magnitudes, strings mix ASCII and UTF-8.
std::vector<std::uint8_t> make_sample_message(const StructType& type, std::uint64_t seed,
                                              const SampleOptions& options = {});

}  // namespace auvrl::logger
