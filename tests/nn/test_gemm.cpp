// The layer products against Eigen's, over awkward sizes (tails of rows, columns and depth
// slices), strides and every epilogue.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12 false positive in Eigen AVX-512
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

#include "common/nn/gemm.hpp"
#include "common/nn/mlp.hpp"

namespace auvrl::nn::gemm {
namespace {

using MatrixXf = Eigen::MatrixXf;

// Reference epilogue on an exact product.
MatrixXf expected(const MatrixXf& p, Epilogue e, const Eigen::VectorXf& bias,
                  const MatrixXf& mask) {
  MatrixXf c = p;
  for (Eigen::Index j = 0; j < c.cols(); ++j) {
    for (Eigen::Index i = 0; i < c.rows(); ++i) {
      if (e == Epilogue::kBias) c(i, j) += bias[i];
      if (e == Epilogue::kBiasRelu) c(i, j) = std::max(c(i, j) + bias[i], 0.0f);
      if (e == Epilogue::kReluMask && !(mask(i, j) > 0)) c(i, j) = 0;
    }
  }
  return c;
}

float tolerance(Eigen::Index k) { return 1e-5f * static_cast<float>(k) + 1e-5f; }

TEST(Gemm, AllShapesAndEpiloguesMatchEigen) {
  std::printf("AVX-512 kernels: %s\n", uses_avx512() ? "yes" : "no (Eigen fallback)");
  const std::vector<Eigen::Index> ms = {1, 2, 6, 15, 16, 17, 31, 32, 33, 64, 70, 97};
  const std::vector<Eigen::Index> ns = {1, 3, 7, 8, 9, 17, 100};
  const std::vector<Eigen::Index> ks = {1, 4, 29, 128, 129, 300};
  for (Eigen::Index m : ms) {
    for (Eigen::Index n : ns) {
      for (Eigen::Index k : ks) {
        // Leading dimensions larger than the sizes, as in the network's blocks.
        MatrixXf a_store = MatrixXf::Random(m + 3, k);
        MatrixXf b_store = MatrixXf::Random(k + 2, n);
        MatrixXf bt_store = MatrixXf::Random(n + 5, k);
        MatrixXf at_store = MatrixXf::Random(k + 1, m);
        const MatrixXf a = a_store.topRows(m), b = b_store.topRows(k);
        const MatrixXf bt = bt_store.topRows(n), at = at_store.topRows(k);
        const Eigen::VectorXf bias = Eigen::VectorXf::Random(m);
        MatrixXf mask_store = MatrixXf::Random(m + 4, n);
        const MatrixXf mask = mask_store.topRows(m);
        std::vector<float> scratch(static_cast<std::size_t>(m * k));
        for (Epilogue e :
             {Epilogue::kStore, Epilogue::kBias, Epilogue::kBiasRelu, Epilogue::kReluMask}) {
          const float* aux = e == Epilogue::kReluMask ? mask_store.data() : bias.data();
          const Eigen::Index aux_ld = mask_store.rows();
          MatrixXf c_store = MatrixXf::Constant(m + 2, n, 7.0f);
          multiply_nn(m, n, k, a_store.data(), a_store.rows(), b_store.data(), b_store.rows(),
                      c_store.data(), c_store.rows(), e, aux, aux_ld);
          const MatrixXf want = expected(a * b, e, bias, mask);
          EXPECT_LT((c_store.topRows(m) - want).cwiseAbs().maxCoeff(), tolerance(k))
              << "nn m=" << m << " n=" << n << " k=" << k << " e=" << static_cast<int>(e);
          EXPECT_TRUE((c_store.bottomRows(2).array() == 7.0f).all()) << "wrote past the rows";

          c_store.setConstant(7.0f);
          multiply_tn(m, n, k, at_store.data(), at_store.rows(), b_store.data(), b_store.rows(),
                      c_store.data(), c_store.rows(), scratch.data(), e, aux, aux_ld);
          const MatrixXf want_tn = expected(at.transpose() * b, e, bias, mask);
          EXPECT_LT((c_store.topRows(m) - want_tn).cwiseAbs().maxCoeff(), tolerance(k))
              << "tn m=" << m << " n=" << n << " k=" << k << " e=" << static_cast<int>(e);
          EXPECT_TRUE((c_store.bottomRows(2).array() == 7.0f).all());
        }
        MatrixXf c_store = MatrixXf::Constant(m + 2, n, 7.0f);
        multiply_nt(m, n, k, a_store.data(), a_store.rows(), bt_store.data(), bt_store.rows(),
                    c_store.data(), c_store.rows());
        EXPECT_LT((c_store.topRows(m) - a * bt.transpose()).cwiseAbs().maxCoeff(), tolerance(k))
            << "nt m=" << m << " n=" << n << " k=" << k;
        EXPECT_TRUE((c_store.bottomRows(2).array() == 7.0f).all());
      }
    }
  }
}

// With two threads a large product is split by columns: the result must be the same, bit for
// bit (each entry is still summed by one thread in the same order).
TEST(Gemm, TwoThreadsGiveTheSameResult) {
  const Eigen::Index m = 256, n = 100, k = 256;
  const MatrixXf a = MatrixXf::Random(m, k), b = MatrixXf::Random(k, n);
  const MatrixXf bt = MatrixXf::Random(n, k), mask = MatrixXf::Random(m, n);
  const Eigen::VectorXf bias = Eigen::VectorXf::Random(m);
  std::vector<float> scratch(static_cast<std::size_t>(m * k));
  auto products = [&] {
    std::vector<MatrixXf> out(3, MatrixXf(m, n));
    multiply_nn(m, n, k, a.data(), m, b.data(), k, out[0].data(), m, Epilogue::kBiasRelu,
                bias.data());
    multiply_tn(m, n, k, a.data(), m, b.data(), k, out[1].data(), m, scratch.data(),
                Epilogue::kReluMask, mask.data(), m);
    MatrixXf c(m, k);
    multiply_nt(m, k, n, out[0].data(), m, bt.transpose().eval().data(), k, c.data(), m);
    out[2] = c.leftCols(n);
    return out;
  };
  const std::vector<MatrixXf> one = products();
  set_num_threads(2);
  const std::vector<MatrixXf> two = products();
  set_num_threads(1);
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i], two[i]) << i;
}

}  // namespace
}  // namespace auvrl::nn::gemm
