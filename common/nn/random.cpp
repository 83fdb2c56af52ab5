// GCC 12 with -march=native on AVX-512 reports false (maybe-)uninitialized reads inside Eigen's
// vectorised kernels (its own _mm512_undefined_ps idiom, GCC bug 105593); not in our code. Before
// the includes, because the warnings are located in the headers.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include "common/nn/random.hpp"

#include <Eigen/Core>
#include <sstream>

namespace auvrl::nn {

void fill_standard_normal(Rng& rng, MatrixRef out) {
  constexpr int kPairs = 32;
  using Chunk = Eigen::Array<float, kPairs, 1>;
  Chunk u1, u2;
  Eigen::Array<float, 2 * kPairs, 1> z;
  int avail = 0;
  for (Eigen::Index j = 0; j < out.cols(); ++j) {
    for (Eigen::Index i = 0; i < out.rows(); ++i) {
      if (avail == 0) {
        for (int k = 0; k < kPairs; ++k) {
          const std::uint64_t bits = rng();
          // u1 in (0, 1] so that log(u1) is finite; u2 in [0, 1).
          u1[k] = static_cast<float>((bits >> 40) + 1) * 0x1.0p-24f;
          u2[k] = static_cast<float>((bits >> 16) & 0xFFFFFFu) * 0x1.0p-24f;
        }
        const Chunk r = (-2.0f * u1.log()).sqrt();
        const Chunk theta = 6.28318530717958647692f * u2;
        z.head<kPairs>() = r * theta.cos();
        z.tail<kPairs>() = r * theta.sin();
        avail = 2 * kPairs;
      }
      out(i, j) = z[2 * kPairs - avail];
      --avail;
    }
  }
}

void write_rng(Writer& w, const Rng& rng) {
  std::ostringstream os;
  os << rng;
  w.string(os.str());
}

void read_rng(Reader& r, Rng& rng) {
  const std::string text = r.string(1 << 16);
  std::istringstream is(text);
  Rng parsed;
  is >> parsed;
  if (!is) r.fail("unreadable random generator state");
  rng = parsed;
}

}  // namespace auvrl::nn
