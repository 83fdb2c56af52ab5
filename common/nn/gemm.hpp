// The dense products of the perceptron's layers, with the bias, the ReLU or the ReLU's
// derivative fused into the store.
//
// Why not Eigen's product alone: at the sizes of these networks (64-400 units, batches of
// 64-256) Eigen packs both operands into buffers before every product and zeroes the result
// first, and the bias and activation need passes of their own. With AVX-512 the kernels below
// work on the operands where they lie (columns of A are contiguous, entries of B are
// broadcast), keep a 64 x 6 block of C in registers and apply the epilogue before the only
// store (faster than Eigen's products at these sizes: docs/results.md, benchmarks). Without
// AVX-512 (or with AUVRL_NN_PORTABLE) the same functions use Eigen's
// products plus an epilogue pass.
#pragma once

#include <Eigen/Core>

namespace auvrl::nn::gemm {

using Index = Eigen::Index;

/// What is done to each entry of the product before it is stored in C.
enum class Epilogue {
  kStore,     ///< C = P
  kBias,      ///< C = P + bias (aux: m values, one per row)
  kBiasRelu,  ///< C = max(P + bias, 0)
  kReluMask,  ///< C = P where mask > 0, else 0 (aux: m x n mask, column-major, leading dim
              ///< aux_ld): back through a ReLU whose output was `mask`
};

/// C = epilogue(A B): A is m x k column-major (leading dimension lda), B is k x n column-major
/// (ldb), C is m x n column-major (ldc). m, n, k >= 1.
void multiply_nn(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                 float* c, Index ldc, Epilogue e = Epilogue::kStore, const float* aux = nullptr,
                 Index aux_ld = 0);

/// C = A B^T: A is m x k column-major (lda), B is n x k column-major (ldb). For weight gradients
/// dW = delta x^T.
void multiply_nt(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                 float* c, Index ldc);

/// C = epilogue(A^T B): A is k x m column-major (lda), B is k x n column-major (ldb). For input
/// gradients W^T delta. `scratch` must hold m * k floats (A^T is formed there).
void multiply_tn(Index m, Index n, Index k, const float* a, Index lda, const float* b, Index ldb,
                 float* c, Index ldc, float* scratch, Epilogue e = Epilogue::kStore,
                 const float* aux = nullptr, Index aux_ld = 0);

/// True when the AVX-512 kernels are compiled in (else the Eigen fallback runs).
bool uses_avx512();

}  // namespace auvrl::nn::gemm
