// GCC 12 with -march=native on AVX-512 reports false (maybe-)uninitialized reads inside Eigen's
// vectorised kernels (its own _mm512_undefined_ps idiom, GCC bug 105593); not in our code. Before
// the includes, because the warnings are located in the headers.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include "common/nn/mlp.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/nn/denormals.hpp"
#include "common/nn/gemm.hpp"

namespace auvrl::nn {
namespace {

// Eigen built with OpenMP would use every core by default; see set_num_threads().
[[maybe_unused]] const bool kOneThreadByDefault = [] {
  Eigen::setNbThreads(1);
  return true;
}();

[[noreturn]] void invalid(const std::string& what) { throw std::invalid_argument(what); }

}  // namespace

const char* to_string(Activation a) {
  switch (a) {
    case Activation::kIdentity:
      return "identity";
    case Activation::kRelu:
      return "relu";
    case Activation::kTanh:
      return "tanh";
  }
  return "unknown";
}

MlpSpec MlpSpec::actor(int state_dim, std::vector<int> hidden, int action_dim) {
  MlpSpec s;
  s.input_dim = state_dim;
  s.hidden = std::move(hidden);
  s.output_dim = action_dim;
  s.output_activation = Activation::kTanh;
  return s;
}

MlpSpec MlpSpec::critic(int state_dim, int action_dim, std::vector<int> hidden, int action_layer) {
  MlpSpec s;
  s.input_dim = state_dim;
  s.hidden = std::move(hidden);
  s.output_dim = 1;
  s.output_activation = Activation::kIdentity;
  s.extra_input_dim = action_dim;
  s.extra_input_layer = action_layer;
  return s;
}

int MlpSpec::layer_out(int l) const {
  return l < static_cast<int>(hidden.size()) ? hidden[static_cast<std::size_t>(l)] : output_dim;
}

int MlpSpec::layer_in(int l) const {
  const int base = l == 0 ? input_dim : hidden[static_cast<std::size_t>(l - 1)];
  return base + ((extra_input_dim > 0 && extra_input_layer == l) ? extra_input_dim : 0);
}

Activation MlpSpec::layer_activation(int l) const {
  return l + 1 < num_layers() ? Activation::kRelu : output_activation;
}

void MlpSpec::validate() const {
  if (input_dim < 1) invalid("network spec: input_dim must be >= 1, got " + describe());
  if (output_dim < 1) invalid("network spec: output_dim must be >= 1, got " + describe());
  for (int h : hidden) {
    if (h < 1) invalid("network spec: hidden sizes must be >= 1, got " + describe());
  }
  if (extra_input_dim < 0) invalid("network spec: extra_input_dim must be >= 0");
  if (extra_input_dim > 0 &&
      (extra_input_layer < 0 || extra_input_layer > static_cast<int>(hidden.size()))) {
    invalid("network spec: extra_input_layer must be in 0.." + std::to_string(hidden.size()) +
            ", got " + std::to_string(extra_input_layer));
  }
  switch (output_activation) {
    case Activation::kIdentity:
    case Activation::kRelu:
    case Activation::kTanh:
      break;
    default:
      invalid("network spec: unknown output activation");
  }
}

std::string MlpSpec::describe() const {
  std::ostringstream os;
  os << "in=" << input_dim << " hidden=";
  if (hidden.empty()) os << "none";
  for (std::size_t i = 0; i < hidden.size(); ++i) os << (i ? "-" : "") << hidden[i];
  os << " out=" << output_dim << " (" << to_string(output_activation) << ")";
  if (extra_input_dim > 0) os << " extra=" << extra_input_dim << " at layer " << extra_input_layer;
  return os.str();
}

bool MlpSpec::operator==(const MlpSpec& o) const {
  return input_dim == o.input_dim && hidden == o.hidden && output_dim == o.output_dim &&
         output_activation == o.output_activation && extra_input_dim == o.extra_input_dim &&
         (extra_input_dim == 0 || extra_input_layer == o.extra_input_layer);
}

Mlp::Mlp(MlpSpec spec, int max_batch) : spec_(std::move(spec)), max_batch_(max_batch) {
  spec_.validate();
  if (max_batch_ < 1) invalid("Mlp: max_batch must be >= 1");
  if (spec_.extra_input_dim == 0) spec_.extra_input_layer = 0;
  const int num_layers = spec_.num_layers();
  Eigen::Index offset = 0;
  for (int l = 0; l < num_layers; ++l) {
    weight_offset_.push_back(offset);
    offset += Eigen::Index{spec_.layer_out(l)} * spec_.layer_in(l);
  }
  num_weights_ = offset;
  for (int l = 0; l < num_layers; ++l) {
    bias_offset_.push_back(offset);
    offset += spec_.layer_out(l);
  }
  params_ = Vector::Zero(offset);
  grads_ = Vector::Zero(offset);
  x0_ = Matrix::Zero(spec_.layer_in(0), max_batch_);
  dx0_ = Matrix::Zero(spec_.layer_in(0), max_batch_);
  Eigen::Index largest = 0;
  for (int l = 0; l < num_layers; ++l) {
    largest = std::max(largest, Eigen::Index{spec_.layer_out(l)} * spec_.layer_in(l));
  }
  scratch_ = Vector::Zero(largest);
  for (int l = 0; l < num_layers; ++l) {
    // The layer whose output the extra input joins keeps room for it below its own rows.
    const bool feeds_extra = spec_.extra_input_dim > 0 && spec_.extra_input_layer == l + 1;
    const int rows = spec_.layer_out(l) + (feeds_extra ? spec_.extra_input_dim : 0);
    act_.push_back(Matrix::Zero(rows, max_batch_));
    delta_.push_back(Matrix::Zero(rows, max_batch_));
  }
}

void Mlp::init_lillicrap(Rng& rng) {
  const int num_layers = spec_.num_layers();
  for (int l = 0; l < num_layers; ++l) {
    const float bound =
        l + 1 < num_layers ? 1.0f / std::sqrt(static_cast<float>(spec_.layer_in(l))) : 3e-3f;
    auto w = weight(l);
    for (Eigen::Index j = 0; j < w.cols(); ++j) {
      for (Eigen::Index i = 0; i < w.rows(); ++i) w(i, j) = uniform(rng, -bound, bound);
    }
    auto b = bias(l);
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = uniform(rng, -bound, bound);
  }
}

Eigen::Map<Matrix> Mlp::weight(int l) {
  return Eigen::Map<Matrix>(params_.data() + weight_offset_[static_cast<std::size_t>(l)],
                            spec_.layer_out(l), spec_.layer_in(l));
}

Eigen::Map<const Matrix> Mlp::weight(int l) const {
  return Eigen::Map<const Matrix>(params_.data() + weight_offset_[static_cast<std::size_t>(l)],
                                  spec_.layer_out(l), spec_.layer_in(l));
}

Eigen::Map<Vector> Mlp::bias(int l) {
  return Eigen::Map<Vector>(params_.data() + bias_offset_[static_cast<std::size_t>(l)],
                            spec_.layer_out(l));
}

Eigen::Map<const Vector> Mlp::bias(int l) const {
  return Eigen::Map<const Vector>(params_.data() + bias_offset_[static_cast<std::size_t>(l)],
                                  spec_.layer_out(l));
}

Eigen::Map<const Matrix> Mlp::weight_grad(int l) const {
  return Eigen::Map<const Matrix>(grads_.data() + weight_offset_[static_cast<std::size_t>(l)],
                                  spec_.layer_out(l), spec_.layer_in(l));
}

Eigen::Map<const Vector> Mlp::bias_grad(int l) const {
  return Eigen::Map<const Vector>(grads_.data() + bias_offset_[static_cast<std::size_t>(l)],
                                  spec_.layer_out(l));
}

Eigen::Block<const Matrix> Mlp::forward(const ConstMatrixRef& input) {
  if (spec_.extra_input_dim > 0) {
    invalid("Mlp::forward: this network (" + spec_.describe() + ") needs its extra input");
  }
  return forward(input, Matrix());
}

Eigen::Block<const Matrix> Mlp::forward(const ConstMatrixRef& input, const ConstMatrixRef& extra) {
  const Eigen::Index n = input.cols();
  if (input.rows() != spec_.input_dim) {
    invalid("Mlp::forward: input has " + std::to_string(input.rows()) + " rows, expected " +
            std::to_string(spec_.input_dim));
  }
  if (n < 1 || n > max_batch_) {
    invalid("Mlp::forward: batch of " + std::to_string(n) + ", expected 1.." +
            std::to_string(max_batch_));
  }
  if (spec_.extra_input_dim > 0 && (extra.rows() != spec_.extra_input_dim || extra.cols() != n)) {
    invalid("Mlp::forward: extra input is " + std::to_string(extra.rows()) + "x" +
            std::to_string(extra.cols()) + ", expected " + std::to_string(spec_.extra_input_dim) +
            "x" + std::to_string(n));
  }
  const ScopedFlushDenormals flush;
  batch_ = static_cast<int>(n);
  x0_.block(0, 0, spec_.input_dim, n) = input;
  if (spec_.extra_input_dim > 0) {
    const int k = spec_.extra_input_layer;
    if (k == 0) {
      x0_.block(spec_.input_dim, 0, spec_.extra_input_dim, n) = extra;
    } else {
      act_[static_cast<std::size_t>(k - 1)].block(spec_.layer_out(k - 1), 0, spec_.extra_input_dim,
                                                  n) = extra;
    }
  }
  forward_layers();
  return output();
}

void Mlp::forward_layers() {
  const int num_layers = spec_.num_layers();
  const Eigen::Index n = batch_;
  for (int l = 0; l < num_layers; ++l) {
    Matrix& a = act_[static_cast<std::size_t>(l)];
    const Matrix& in = l == 0 ? x0_ : act_[static_cast<std::size_t>(l - 1)];
    const int out = spec_.layer_out(l);
    const Activation act = spec_.layer_activation(l);
    const float* bias = params_.data() + bias_offset_[static_cast<std::size_t>(l)];
    // z = W in + b, with the ReLU applied in the same store.
    gemm::multiply_nn(
        out, n, spec_.layer_in(l), params_.data() + weight_offset_[static_cast<std::size_t>(l)],
        out, in.data(), in.rows(), a.data(), a.rows(),
        act == Activation::kRelu ? gemm::Epilogue::kBiasRelu : gemm::Epilogue::kBias, bias);
    if (act == Activation::kTanh) {
      // The output layer's block is contiguous (no extra rows): one vectorised pass over it.
      Eigen::Map<Eigen::ArrayXf> c(a.data(), a.rows() * n);
      c = c.tanh();
    }
  }
}

Eigen::Block<const Matrix> Mlp::output() const {
  const Matrix& a = act_.back();
  return a.block(0, 0, spec_.output_dim, batch_);
}

void Mlp::backward(const ConstMatrixRef& d_output, GradRequest what) {
  const Eigen::Index n = batch_;
  if (n == 0) invalid("Mlp::backward: no forward pass to differentiate");
  if (d_output.rows() != spec_.output_dim || d_output.cols() != n) {
    invalid("Mlp::backward: d_output is " + std::to_string(d_output.rows()) + "x" +
            std::to_string(d_output.cols()) + ", expected " + std::to_string(spec_.output_dim) +
            "x" + std::to_string(n));
  }
  const ScopedFlushDenormals flush;
  const int num_layers = spec_.num_layers();
  const int extra = spec_.extra_input_dim;
  const int extra_layer = spec_.extra_input_layer;

  // Output layer: dL/dz = dL/dy * f'(z), with f' written in terms of y.
  {
    const int last = num_layers - 1;
    auto d = delta_[static_cast<std::size_t>(last)].block(0, 0, spec_.output_dim, n);
    const auto y = output();
    switch (spec_.output_activation) {
      case Activation::kIdentity:
        d = d_output;
        break;
      case Activation::kTanh:
        d.array() = d_output.array() * (1.0f - y.array().square());
        break;
      case Activation::kRelu:
        d.array() = d_output.array() * (y.array() > 0.0f).cast<float>();
        break;
    }
  }

  float* const scratch = scratch_.data();
  for (int l = num_layers - 1; l >= 0; --l) {
    const Matrix& dl = delta_[static_cast<std::size_t>(l)];
    const Matrix& in = l == 0 ? x0_ : act_[static_cast<std::size_t>(l - 1)];
    const int out = spec_.layer_out(l);
    const int in_dim = spec_.layer_in(l);
    const float* w = params_.data() + weight_offset_[static_cast<std::size_t>(l)];
    const bool extra_here = extra > 0 && extra_layer == l;

    if (what.params) {
      // dL/dW = delta in^T; dL/db = delta summed over the batch.
      gemm::multiply_nt(out, in_dim, n, dl.data(), dl.rows(), in.data(), in.rows(),
                        grads_.data() + weight_offset_[static_cast<std::size_t>(l)], out);
      // Sixteen rows at a time summed in a register across the batch, then stored once.
      using Chunk = Eigen::Array<float, 16, 1>;
      float* db = grads_.data() + bias_offset_[static_cast<std::size_t>(l)];
      const Eigen::Index stride = dl.rows();
      const float* dp = dl.data();
      int i = 0;
      for (; i + 16 <= out; i += 16) {
        Chunk sum = Eigen::Map<const Chunk>(dp + i);
        for (Eigen::Index j = 1; j < n; ++j) sum += Eigen::Map<const Chunk>(dp + j * stride + i);
        Eigen::Map<Chunk>(db + i) = sum;
      }
      for (; i < out; ++i) {
        float sum = 0.0f;
        for (Eigen::Index j = 0; j < n; ++j) sum += dp[j * stride + i];
        db[i] = sum;
      }
    }

    if (l == 0) {
      if (what.input) {
        gemm::multiply_tn(in_dim, n, out, w, out, dl.data(), dl.rows(), dx0_.data(), dx0_.rows(),
                          scratch);
      } else if (what.extra_input && extra_here) {
        // Only the extra input's columns of W.
        gemm::multiply_tn(extra, n, out, w + Eigen::Index{spec_.input_dim} * out, out, dl.data(),
                          dl.rows(), dx0_.data() + spec_.input_dim, dx0_.rows(), scratch);
      }
      break;
    }

    Matrix& below = delta_[static_cast<std::size_t>(l - 1)];
    const int out_below = spec_.layer_out(l - 1);
    const bool need_below = what.params || what.input || (what.extra_input && extra_layer < l);
    if (need_below) {
      // dL/d(input of l) = W^T delta, through the ReLU of layer l-1 (zero where its output was
      // zero) in the same store.
      const Matrix& a = act_[static_cast<std::size_t>(l - 1)];
      gemm::multiply_tn(out_below, n, out, w, out, dl.data(), dl.rows(), below.data(), below.rows(),
                        scratch, gemm::Epilogue::kReluMask, a.data(), a.rows());
    }
    if (extra_here && what.extra_input) {
      // The extra input's rows: no activation below them.
      gemm::multiply_tn(extra, n, out, w + Eigen::Index{out_below} * out, out, dl.data(), dl.rows(),
                        below.data() + out_below, below.rows(), scratch);
    }
    if (!need_below) break;
  }
}

Eigen::Block<const Matrix> Mlp::input_grad() const {
  const Matrix& g = dx0_;
  return g.block(0, 0, spec_.input_dim, batch_);
}

Eigen::Block<const Matrix> Mlp::extra_input_grad() const {
  const int k = spec_.extra_input_layer;
  if (k == 0) {
    const Matrix& g = dx0_;
    return g.block(spec_.input_dim, 0, spec_.extra_input_dim, batch_);
  }
  const Matrix& g = delta_[static_cast<std::size_t>(k - 1)];
  return g.block(spec_.layer_out(k - 1), 0, spec_.extra_input_dim, batch_);
}

void Mlp::copy_params_from(const Mlp& other) {
  if (other.spec_ != spec_) {
    invalid("Mlp::copy_params_from: spec " + other.spec_.describe() + ", expected " +
            spec_.describe());
  }
  params_ = other.params_;
}

void soft_update(Mlp& target, const Mlp& source, float tau) {
  if (target.spec() != source.spec()) {
    invalid("soft_update: source " + source.spec().describe() + " differs from target " +
            target.spec().describe());
  }
  const ScopedFlushDenormals flush;
  target.params() = tau * source.params() + (1.0f - tau) * target.params();
}

Mlp mean_of(const std::vector<const Mlp*>& nets) {
  if (nets.empty()) invalid("mean_of: no network");
  Mlp mean = *nets.front();
  for (std::size_t i = 1; i < nets.size(); ++i) {
    if (nets[i]->spec() != mean.spec()) {
      invalid("mean_of: network " + std::to_string(i + 1) + " " + nets[i]->spec().describe() +
              " differs from the first " + mean.spec().describe());
    }
    mean.params() += nets[i]->params();
  }
  mean.params() /= static_cast<float>(nets.size());
  return mean;
}

void set_num_threads(int n) { Eigen::setNbThreads(std::max(n, 1)); }

int num_threads() { return Eigen::nbThreads(); }

}  // namespace auvrl::nn
