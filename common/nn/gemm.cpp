// GCC 12 with -march=native on AVX-512 reports false (maybe-)uninitialized reads inside Eigen's
// vectorised kernels (its own _mm512_undefined_ps idiom, GCC bug 105593); not in our code. Before
// the includes, because the warnings are located in the headers.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include "common/nn/gemm.hpp"

#include <algorithm>

#include "common/nn/denormals.hpp"

#if defined(__AVX512F__) && !defined(AUVRL_NN_PORTABLE)
#define AUVRL_GEMM_AVX512 1
#include <immintrin.h>
#endif
#if defined(_OPENMP)
#include <omp.h>
#endif

namespace auvrl::nn::gemm {
namespace {

using MatrixMap = Eigen::Map<Eigen::MatrixXf, 0, Eigen::OuterStride<>>;
using ConstMatrixMap = Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>;

// The epilogue as a separate pass, for the Eigen path.
void apply_epilogue(Index m, Index n, float* c, Index ldc, Epilogue e, const float* aux,
                    Index aux_ld) {
  for (Index j = 0; j < n; ++j) {
    float* __restrict cj = c + j * ldc;
    switch (e) {
      case Epilogue::kStore:
        return;
      case Epilogue::kBias:
        for (Index i = 0; i < m; ++i) cj[i] += aux[i];
        break;
      case Epilogue::kBiasRelu:
        for (Index i = 0; i < m; ++i) cj[i] = std::max(cj[i] + aux[i], 0.0f);
        break;
      case Epilogue::kReluMask: {
        const float* __restrict mj = aux + j * aux_ld;
        for (Index i = 0; i < m; ++i) cj[i] = mj[i] > 0.0f ? cj[i] : 0.0f;
        break;
      }
    }
  }
}

void eigen_nn(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
              float* c, Index ldc, Epilogue e, const float* aux, Index aux_ld) {
  MatrixMap cm(c, m, n, Eigen::OuterStride<>(ldc));
  cm.noalias() = ConstMatrixMap(a, m, k, Eigen::OuterStride<>(lda)) *
                 ConstMatrixMap(b, k, n, Eigen::OuterStride<>(ldb));
  apply_epilogue(m, n, c, ldc, e, aux, aux_ld);
}

#if defined(AUVRL_GEMM_AVX512)

// One block of C: up to 16 * MV rows (masked) by NR columns, accumulated in registers over a
// depth k (added to what C holds if ADD), then the epilogue and a single store. Columns of A are
// loaded as vectors; entries of B are broadcast: B(p, j) is b[p + j * ldb], or b[j + p * ldb] when
// BT (B given transposed).
template <int MV, int NR, bool BT, Epilogue E, bool ADD>
void block(Index rows, Index k, const float* a, Index lda, const float* b, Index ldb, float* c,
           Index ldc, const float* aux, Index aux_ld) {
  __mmask16 mask[MV];
#pragma GCC unroll 16
  for (int v = 0; v < MV; ++v) {
    const Index r = rows - 16 * v;
    mask[v] = r >= 16 ? __mmask16(0xFFFF) : static_cast<__mmask16>((1u << r) - 1u);
  }
  __m512 acc[MV][NR];
#pragma GCC unroll 16
  for (int v = 0; v < MV; ++v) {
#pragma GCC unroll 16
    for (int j = 0; j < NR; ++j) {
      // ADD: carry on the sums that earlier slices of the depth left in C.
      acc[v][j] = ADD ? _mm512_maskz_loadu_ps(mask[v], c + j * ldc + 16 * v) : _mm512_setzero_ps();
    }
  }
  if constexpr (!BT) {
    const float* bcol[NR];
#pragma GCC unroll 16
    for (int j = 0; j < NR; ++j) bcol[j] = b + j * ldb;
    for (Index p = 0; p < k; ++p) {
      __m512 av[MV];
#pragma GCC unroll 16
      for (int v = 0; v < MV; ++v) av[v] = _mm512_maskz_loadu_ps(mask[v], a + p * lda + 16 * v);
#pragma GCC unroll 16
      for (int j = 0; j < NR; ++j) {
        const __m512 bj = _mm512_set1_ps(bcol[j][p]);
#pragma GCC unroll 16
        for (int v = 0; v < MV; ++v) acc[v][j] = _mm512_fmadd_ps(av[v], bj, acc[v][j]);
      }
    }
  } else {
    for (Index p = 0; p < k; ++p) {
      __m512 av[MV];
#pragma GCC unroll 16
      for (int v = 0; v < MV; ++v) av[v] = _mm512_maskz_loadu_ps(mask[v], a + p * lda + 16 * v);
      const float* bp = b + p * ldb;
#pragma GCC unroll 16
      for (int j = 0; j < NR; ++j) {
        const __m512 bj = _mm512_set1_ps(bp[j]);
#pragma GCC unroll 16
        for (int v = 0; v < MV; ++v) acc[v][j] = _mm512_fmadd_ps(av[v], bj, acc[v][j]);
      }
    }
  }
  const __m512 zero = _mm512_setzero_ps();
  __m512 bias[MV];
  if constexpr (E == Epilogue::kBias || E == Epilogue::kBiasRelu) {
#pragma GCC unroll 16
    for (int v = 0; v < MV; ++v) bias[v] = _mm512_maskz_loadu_ps(mask[v], aux + 16 * v);
  }
#pragma GCC unroll 16
  for (int j = 0; j < NR; ++j) {
#pragma GCC unroll 16
    for (int v = 0; v < MV; ++v) {
      __m512 x = acc[v][j];
      if constexpr (E == Epilogue::kBias) x = _mm512_add_ps(x, bias[v]);
      if constexpr (E == Epilogue::kBiasRelu) x = _mm512_max_ps(_mm512_add_ps(x, bias[v]), zero);
      if constexpr (E == Epilogue::kReluMask) {
        const __m512 y = _mm512_maskz_loadu_ps(mask[v], aux + j * aux_ld + 16 * v);
        x = _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(y, zero, _CMP_GT_OQ), x);
      }
      _mm512_mask_storeu_ps(c + j * ldc + 16 * v, mask[v], x);
    }
  }
}

// Register tile: up to kPanel rows (kPanel / 16 vectors) by kNr columns of C, i.e. 24
// accumulators of the 32 vector registers; of the tiles tried (32x8, 48x8, 64x4, 64x6) the
// fastest over these networks' sizes, and a 64-unit layer is then a single panel (B is read
// once).
constexpr int kPanel = 64;
constexpr int kNr = 6;

template <int NR, bool BT, Epilogue E, bool ADD>
void block_rows(Index rows, Index k, const float* a, Index lda, const float* b, Index ldb, float* c,
                Index ldc, const float* aux, Index aux_ld) {
  if constexpr (kPanel > 48) {
    if (rows > 48) return block<4, NR, BT, E, ADD>(rows, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
  }
  if constexpr (kPanel > 32) {
    if (rows > 32) return block<3, NR, BT, E, ADD>(rows, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
  }
  if (rows > 16) return block<2, NR, BT, E, ADD>(rows, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
  block<1, NR, BT, E, ADD>(rows, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
}

template <bool BT, Epilogue E, bool ADD>
void columns(Index rows, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
             float* c, Index ldc, const float* aux, Index aux_ld) {
  for (Index j0 = 0; j0 < n; j0 += kNr) {
    const float* bj = BT ? b + j0 : b + j0 * ldb;
    float* cj = c + j0 * ldc;
    const float* aux_j = E == Epilogue::kReluMask ? aux + j0 * aux_ld : aux;
    switch (std::min<Index>(kNr, n - j0)) {
      case 8:
        if constexpr (kNr >= 8)
          block_rows<8, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      case 7:
        if constexpr (kNr >= 7)
          block_rows<7, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      case 6:
        block_rows<6, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      case 5:
        block_rows<5, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      case 4:
        block_rows<4, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      case 3:
        block_rows<3, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      case 2:
        block_rows<2, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
      default:
        block_rows<1, BT, E, ADD>(rows, k, a, lda, bj, ldb, cj, ldc, aux_j, aux_ld);
        break;
    }
  }
}

// Rows in panels of kPanel; the depth in slices of at most kKc so that a panel's slice of A
// (64 x 128 floats, 32 KiB) stays in L1 while the columns of B sweep past; columns in blocks of
// kNr, the last one narrower. Only the last slice applies the epilogue.
template <bool BT, Epilogue E>
void run_serial(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                float* c, Index ldc, const float* aux, Index aux_ld) {
  constexpr Index kKc = 128;
  const Index slices = (k + kKc - 1) / kKc;
  const Index kc = (k + slices - 1) / slices;
  for (Index i0 = 0; i0 < m; i0 += kPanel) {
    const Index rows = std::min<Index>(kPanel, m - i0);
    const float* aux_i = aux == nullptr ? nullptr : aux + i0;
    for (Index p0 = 0; p0 < k; p0 += kc) {
      const Index depth = std::min(kc, k - p0);
      const float* ap = a + i0 + p0 * lda;
      const float* bp = BT ? b + p0 * ldb : b + p0;
      const bool first = p0 == 0;
      const bool last = p0 + depth == k;
      if (first && last) {
        columns<BT, E, false>(rows, n, depth, ap, lda, bp, ldb, c + i0, ldc, aux_i, aux_ld);
      } else if (first) {
        columns<BT, Epilogue::kStore, false>(rows, n, depth, ap, lda, bp, ldb, c + i0, ldc, nullptr,
                                             0);
      } else if (last) {
        columns<BT, E, true>(rows, n, depth, ap, lda, bp, ldb, c + i0, ldc, aux_i, aux_ld);
      } else {
        columns<BT, Epilogue::kStore, true>(rows, n, depth, ap, lda, bp, ldb, c + i0, ldc, nullptr,
                                            0);
      }
    }
  }
}

// With set_num_threads(t > 1) and OpenMP, a large product is split by columns: each thread
// computes a contiguous range of column blocks, so no two threads write the same entry.
template <bool BT, Epilogue E>
void run(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb, float* c,
         Index ldc, const float* aux, Index aux_ld) {
#if defined(_OPENMP)
  constexpr double kParallelMacs = 1 << 20;  // below this, waking the threads costs more
  const int threads = Eigen::nbThreads();
  if (threads > 1 && static_cast<double>(m) * n * k >= kParallelMacs && n >= 2 * kNr) {
    const Index blocks = (n + kNr - 1) / kNr;
#pragma omp parallel num_threads(threads)
    {
      // Worker threads do not inherit the caller's floating-point mode.
      const ScopedFlushDenormals flush;
      const Index t = omp_get_thread_num();
      const Index nt = omp_get_num_threads();
      const Index j0 = blocks * t / nt * kNr;
      const Index j1 = std::min(n, blocks * (t + 1) / nt * kNr);
      if (j1 > j0) {
        run_serial<BT, E>(m, j1 - j0, k, a, lda, BT ? b + j0 : b + j0 * ldb, ldb, c + j0 * ldc, ldc,
                          E == Epilogue::kReluMask ? aux + j0 * aux_ld : aux, aux_ld);
      }
    }
    return;
  }
#endif
  run_serial<BT, E>(m, n, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
}

// 16 x 16 tile transpose in registers: 16 loads, 64 shuffles, 16 stores.
inline void transpose_tile(const float* src, Index lds, float* dst, Index ldd) {
  __m512 r[16], t[16];
#pragma GCC unroll 16
  for (int i = 0; i < 16; ++i) r[i] = _mm512_loadu_ps(src + i * lds);
    // Interleave 32-bit, then 64-bit elements within 128-bit lanes...
#pragma GCC unroll 8
  for (int i = 0; i < 8; ++i) {
    t[2 * i] = _mm512_unpacklo_ps(r[2 * i], r[2 * i + 1]);
    t[2 * i + 1] = _mm512_unpackhi_ps(r[2 * i], r[2 * i + 1]);
  }
#pragma GCC unroll 4
  for (int i = 0; i < 4; ++i) {
    const __m512d t0 = _mm512_castps_pd(t[4 * i]), t1 = _mm512_castps_pd(t[4 * i + 1]);
    const __m512d t2 = _mm512_castps_pd(t[4 * i + 2]), t3 = _mm512_castps_pd(t[4 * i + 3]);
    r[4 * i] = _mm512_castpd_ps(_mm512_unpacklo_pd(t0, t2));
    r[4 * i + 1] = _mm512_castpd_ps(_mm512_unpackhi_pd(t0, t2));
    r[4 * i + 2] = _mm512_castpd_ps(_mm512_unpacklo_pd(t1, t3));
    r[4 * i + 3] = _mm512_castpd_ps(_mm512_unpackhi_pd(t1, t3));
  }
  // ... then transpose the 4 x 4 grid of 128-bit lanes.
#pragma GCC unroll 4
  for (int q = 0; q < 4; ++q) {
    const __m512 x = _mm512_shuffle_f32x4(r[q], r[4 + q], 0x44);
    const __m512 y = _mm512_shuffle_f32x4(r[q], r[4 + q], 0xEE);
    const __m512 z = _mm512_shuffle_f32x4(r[8 + q], r[12 + q], 0x44);
    const __m512 w = _mm512_shuffle_f32x4(r[8 + q], r[12 + q], 0xEE);
    _mm512_storeu_ps(dst + q * ldd, _mm512_shuffle_f32x4(x, z, 0x88));
    _mm512_storeu_ps(dst + (4 + q) * ldd, _mm512_shuffle_f32x4(x, z, 0xDD));
    _mm512_storeu_ps(dst + (8 + q) * ldd, _mm512_shuffle_f32x4(y, w, 0x88));
    _mm512_storeu_ps(dst + (12 + q) * ldd, _mm512_shuffle_f32x4(y, w, 0xDD));
  }
}

// dst (cols x rows, column-major, ldd) = src^T, src rows x cols column-major (lds).
void transpose(Index rows, Index cols, const float* src, Index lds, float* dst, Index ldd) {
  const Index rows16 = rows - rows % 16;
  const Index cols16 = cols - cols % 16;
  for (Index j0 = 0; j0 < cols16; j0 += 16) {
    for (Index i0 = 0; i0 < rows16; i0 += 16) {
      transpose_tile(src + i0 + j0 * lds, lds, dst + j0 + i0 * ldd, ldd);
    }
  }
  // Edges, one element at a time.
  for (Index j = 0; j < cols; ++j) {
    for (Index i = (j < cols16 ? rows16 : 0); i < rows; ++i) dst[j + i * ldd] = src[i + j * lds];
  }
}

// A single row of A (contiguous: lda == 1) times B: one dot product down each column of B,
// four columns at a time, depth in vectors of 16 (the last one masked).
void row_times_matrix(Index n, Index k, const float* a, const float* b, Index ldb, float* c,
                      Index ldc) {
  const __mmask16 tail = static_cast<__mmask16>((1u << (k % 16)) - 1u);
  const Index k16 = k - k % 16;
  Index j = 0;
  for (; j + 4 <= n; j += 4) {
    __m512 acc[4] = {_mm512_setzero_ps(), _mm512_setzero_ps(), _mm512_setzero_ps(),
                     _mm512_setzero_ps()};
    for (Index p = 0; p < k16; p += 16) {
      const __m512 av = _mm512_loadu_ps(a + p);
#pragma GCC unroll 4
      for (int q = 0; q < 4; ++q) {
        acc[q] = _mm512_fmadd_ps(av, _mm512_loadu_ps(b + (j + q) * ldb + p), acc[q]);
      }
    }
    if (tail != 0) {
      const __m512 av = _mm512_maskz_loadu_ps(tail, a + k16);
#pragma GCC unroll 4
      for (int q = 0; q < 4; ++q) {
        acc[q] = _mm512_fmadd_ps(av, _mm512_maskz_loadu_ps(tail, b + (j + q) * ldb + k16), acc[q]);
      }
    }
#pragma GCC unroll 4
    for (int q = 0; q < 4; ++q) c[(j + q) * ldc] = _mm512_reduce_add_ps(acc[q]);
  }
  for (; j < n; ++j) {
    __m512 acc = _mm512_setzero_ps();
    for (Index p = 0; p < k16; p += 16) {
      acc = _mm512_fmadd_ps(_mm512_loadu_ps(a + p), _mm512_loadu_ps(b + j * ldb + p), acc);
    }
    if (tail != 0) {
      acc = _mm512_fmadd_ps(_mm512_maskz_loadu_ps(tail, a + k16),
                            _mm512_maskz_loadu_ps(tail, b + j * ldb + k16), acc);
    }
    c[j * ldc] = _mm512_reduce_add_ps(acc);
  }
}

template <bool BT>
void run_any(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
             float* c, Index ldc, Epilogue e, const float* aux, Index aux_ld) {
  switch (e) {
    case Epilogue::kStore:
      return run<BT, Epilogue::kStore>(m, n, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
    case Epilogue::kBias:
      return run<BT, Epilogue::kBias>(m, n, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
    case Epilogue::kBiasRelu:
      return run<BT, Epilogue::kBiasRelu>(m, n, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
    case Epilogue::kReluMask:
      return run<BT, Epilogue::kReluMask>(m, n, k, a, lda, b, ldb, c, ldc, aux, aux_ld);
  }
}

#endif  // AUVRL_GEMM_AVX512

}  // namespace

bool uses_avx512() {
#if defined(AUVRL_GEMM_AVX512)
  return true;
#else
  return false;
#endif
}

void multiply_nn(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                 float* c, Index ldc, Epilogue e, const float* aux, Index aux_ld) {
#if defined(AUVRL_GEMM_AVX512)
  if (m > 1) return run_any<false>(m, n, k, a, lda, b, ldb, c, ldc, e, aux, aux_ld);
  // A single output row (the critic's Q) would use one lane of 16 in the tiles: dot products.
  if (lda == 1) {
    row_times_matrix(n, k, a, b, ldb, c, ldc);
    apply_epilogue(m, n, c, ldc, e, aux, aux_ld);
    return;
  }
#endif
  eigen_nn(m, n, k, a, lda, b, ldb, c, ldc, e, aux, aux_ld);
}

void multiply_nt(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                 float* c, Index ldc) {
#if defined(AUVRL_GEMM_AVX512)
  if (m > 1) return run_any<true>(m, n, k, a, lda, b, ldb, c, ldc, Epilogue::kStore, nullptr, 0);
#endif
  MatrixMap cm(c, m, n, Eigen::OuterStride<>(ldc));
  cm.noalias() = ConstMatrixMap(a, m, k, Eigen::OuterStride<>(lda)) *
                 ConstMatrixMap(b, n, k, Eigen::OuterStride<>(ldb)).transpose();
}

void multiply_tn(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                 float* c, Index ldc, float* scratch, Epilogue e, const float* aux, Index aux_ld) {
#if defined(AUVRL_GEMM_AVX512)
  if (m > 1) {
    transpose(k, m, a, lda, scratch, m);
    return run_any<false>(m, n, k, scratch, m, b, ldb, c, ldc, e, aux, aux_ld);
  }
#endif
  (void)scratch;
  MatrixMap cm(c, m, n, Eigen::OuterStride<>(ldc));
  cm.noalias() = ConstMatrixMap(a, k, m, Eigen::OuterStride<>(lda)).transpose() *
                 ConstMatrixMap(b, k, n, Eigen::OuterStride<>(ldb));
  apply_epilogue(m, n, c, ldc, e, aux, aux_ld);
}

}  // namespace auvrl::nn::gemm
