// Eigen types of the learning core: float32, column-major, one column per sample.
#pragma once

#include <Eigen/Core>

namespace auvrl::nn {

/// A batch of vectors: features x batch, column-major (each sample is one contiguous column).
using Matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor>;
/// A flat parameter or feature vector.
using Vector = Eigen::VectorXf;
/// Read-only view of any column-major float matrix or block with unit inner stride (no copy).
using ConstMatrixRef = Eigen::Ref<const Matrix>;
/// Writable view of any column-major float matrix or block with unit inner stride.
using MatrixRef = Eigen::Ref<Matrix>;
/// Read-only view of a contiguous float vector.
using ConstVectorRef = Eigen::Ref<const Vector>;
/// Writable view of a contiguous float vector.
using VectorRef = Eigen::Ref<Vector>;

}  // namespace auvrl::nn
