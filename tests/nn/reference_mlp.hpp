// Independent double-precision forward pass of an Mlp's architecture, written per sample from
// the documented parameter layout, as the reference for gradient checks.
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "common/nn/mlp.hpp"

namespace auvrl::test {

/// y = net(x, e) for each column, in double, from flat parameters `p` in Mlp's layout (every
/// layer's weights column-major, then every layer's biases).
inline Eigen::MatrixXd reference_forward(const nn::MlpSpec& s, const Eigen::VectorXd& p,
                                         const Eigen::MatrixXd& x, const Eigen::MatrixXd& e) {
  const int layers = static_cast<int>(s.hidden.size()) + 1;
  auto out_of = [&](int l) {
    return l < layers - 1 ? s.hidden[static_cast<size_t>(l)] : s.output_dim;
  };
  auto base_in = [&](int l) { return l == 0 ? s.input_dim : s.hidden[static_cast<size_t>(l - 1)]; };
  auto has_extra = [&](int l) { return s.extra_input_dim > 0 && s.extra_input_layer == l; };
  std::vector<Eigen::Index> w_off, b_off;
  Eigen::Index off = 0;
  for (int l = 0; l < layers; ++l) {
    w_off.push_back(off);
    off += Eigen::Index{out_of(l)} * (base_in(l) + (has_extra(l) ? s.extra_input_dim : 0));
  }
  for (int l = 0; l < layers; ++l) {
    b_off.push_back(off);
    off += out_of(l);
  }
  Eigen::MatrixXd y(s.output_dim, x.cols());
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    Eigen::VectorXd h = x.col(n);
    for (int l = 0; l < layers; ++l) {
      Eigen::VectorXd in = h;
      if (has_extra(l)) {
        in.resize(h.size() + s.extra_input_dim);
        in << h, e.col(n);
      }
      const Eigen::Map<const Eigen::MatrixXd> w(p.data() + w_off[static_cast<size_t>(l)], out_of(l),
                                                in.size());
      const Eigen::Map<const Eigen::VectorXd> b(p.data() + b_off[static_cast<size_t>(l)],
                                                out_of(l));
      Eigen::VectorXd z = w * in + b;
      const nn::Activation a = l < layers - 1 ? nn::Activation::kRelu : s.output_activation;
      for (Eigen::Index i = 0; i < z.size(); ++i) {
        if (a == nn::Activation::kRelu) z[i] = std::max(z[i], 0.0);
        if (a == nn::Activation::kTanh) z[i] = std::tanh(z[i]);
      }
      h = z;
    }
    y.col(n) = h;
  }
  return y;
}

}  // namespace auvrl::test
