// Seeded scalar draws that give the same numbers with any standard library
// (std::uniform_real_distribution and std::normal_distribution are implementation-defined).
// Header-only and free of our other code, so that the physics (sim/), the agents and the
// learning core (common/nn/) draw the same way.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace auvrl::draw {

/// The generator of every seeded random process.
using Engine = std::mt19937_64;

/// Uniform double in [0, 1) from the top 53 bits of one draw.
inline double unit(Engine& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// N(0, 1) by Box-Muller from two draws (cosine branch only): no second value is cached, so the
/// stream depends only on the engine (copying the engine copies its whole random future).
inline double standard_normal(Engine& rng) {
  const double u1 = static_cast<double>((rng() >> 11) + 1) * 0x1.0p-53;  // (0, 1]: finite log
  const double u2 = static_cast<double>(rng() >> 11) * 0x1.0p-53;        // [0, 1)
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.28318530717958647692 * u2);
}

}  // namespace auvrl::draw
