// Seeded, portable random draws: the same seed gives the same numbers with any standard library
// (std::uniform_*_distribution and std::normal_distribution are implementation-defined).
#pragma once

#include <cstdint>
#include <random>

#include "common/nn/byte_io.hpp"
#include "common/nn/types.hpp"
#include "common/random.hpp"

namespace auvrl::nn {

/// The generator used everywhere in the learning core (the system's one, common/random.hpp).
using Rng = draw::Engine;

/// Scalar N(0, 1) in double, the same draw as the physics and the agents use.
using draw::standard_normal;

/// Uniform float in [0, 1) from the top 24 bits of one draw.
inline float uniform01(Rng& rng) { return static_cast<float>(rng() >> 40) * 0x1.0p-24f; }

/// Uniform float in [lo, hi).
inline float uniform(Rng& rng, float lo, float hi) { return lo + (hi - lo) * uniform01(rng); }

/// Uniform integer in [0, n), n > 0 (Lemire's multiply-shift; bias below n / 2^64).
inline std::uint64_t uniform_index(Rng& rng, std::uint64_t n) {
  __extension__ using U128 = unsigned __int128;
  return static_cast<std::uint64_t>((static_cast<U128>(rng()) * n) >> 64);
}

/// Fills `out` (column by column) with independent N(0, 1) draws: Box-Muller on blocks of
/// uniforms with Eigen's vectorised log/sin/cos, so that a TD3 update's target noise stays
/// cheap. Allocates nothing.
void fill_standard_normal(Rng& rng, MatrixRef out);

/// Writes the generator's full state (the standard's textual form, portable).
void write_rng(Writer& w, const Rng& rng);
/// Reads a state written by write_rng into `rng` (unchanged if reading fails).
void read_rng(Reader& r, Rng& rng);

}  // namespace auvrl::nn
