// Multi-layer perceptron on Eigen for the actor and the critic of DDPG/TD3: float32, batched
// (features x batch, one matrix product per layer), preallocated workspaces so that forward and
// backward passes allocate nothing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/nn/random.hpp"
#include "common/nn/types.hpp"

namespace auvrl::nn {

/// Element-wise activation after a layer's affine map. The values are part of the serialised
/// format: never renumber.
enum class Activation : std::uint8_t {
  kIdentity = 0,  ///< y = z (critic output)
  kRelu = 1,      ///< y = max(z, 0) (every hidden layer)
  kTanh = 2,      ///< y = tanh(z) (actor output: commands in [-1, 1])
};

/// Name of an activation ("identity", "relu", "tanh").
const char* to_string(Activation a);

/// Architecture of a perceptron: input -> hidden layers (ReLU) -> output (identity or tanh).
/// An optional second input (the critic's action) is concatenated below the input of one
/// weight layer: layer 0 takes [input; extra], or, as in Lillicrap et al.'s critic, layer 1
/// takes [first hidden layer's output; extra].
struct MlpSpec {
  int input_dim = 0;
  std::vector<int> hidden;  ///< sizes of the hidden layers, first to last (may be empty)
  int output_dim = 0;
  Activation output_activation = Activation::kIdentity;
  int extra_input_dim = 0;    ///< 0: no second input
  int extra_input_layer = 0;  ///< weight layer that receives it: 0 .. hidden.size()

  /// Policy network: state -> hidden (ReLU) -> action (tanh).
  static MlpSpec actor(int state_dim, std::vector<int> hidden, int action_dim);
  /// Value network: (state, action) -> hidden (ReLU) -> Q (identity); the action enters weight
  /// layer `action_layer` (0: with the state; 1: after the first hidden layer, as Lillicrap).
  static MlpSpec critic(int state_dim, int action_dim, std::vector<int> hidden, int action_layer);

  /// Number of weight layers (hidden.size() + 1).
  int num_layers() const { return static_cast<int>(hidden.size()) + 1; }
  /// Output size of weight layer l.
  int layer_out(int l) const;
  /// Input size of weight layer l, counting the extra input where it enters.
  int layer_in(int l) const;
  /// Activation of weight layer l (ReLU for hidden layers).
  Activation layer_activation(int l) const;
  /// Throws std::invalid_argument naming the problem if the spec is not usable.
  void validate() const;
  /// One line such as "in=29 hidden=400-300 out=6 (tanh)" or "... extra=6 at layer 1".
  std::string describe() const;

  bool operator==(const MlpSpec& o) const;
  bool operator!=(const MlpSpec& o) const { return !(*this == o); }
};

/// What backward() computes.
struct GradRequest {
  bool params = true;        ///< gradients of the loss w.r.t. weights and biases (grads())
  bool input = false;        ///< gradient w.r.t. the primary input (input_grad())
  bool extra_input = false;  ///< gradient w.r.t. the extra input, e.g. dQ/da (extra_input_grad())
};

/// A perceptron with its parameters, their gradients and the workspaces of one batched
/// forward/backward pass of up to max_batch samples.
///
/// Parameters live in one flat float vector (params()) laid out as every layer's weight matrix
/// (out x in, column-major), layer 0 first, followed by every layer's bias; so the first
/// num_weights() entries are exactly the weights (what L2 weight decay applies to) and the same
/// layout serves the optimiser, soft target updates and serialisation. grads() has the same
/// layout.
///
/// Not thread-safe: a forward pass overwrites the workspaces of the previous one. Copies are deep
/// (a target network is a copy).
class Mlp {
 public:
  /// Zero parameters; call init_lillicrap() (or load) before use. Throws std::invalid_argument
  /// for an invalid spec or max_batch < 1.
  Mlp(MlpSpec spec, int max_batch);

  const MlpSpec& spec() const { return spec_; }
  int max_batch() const { return max_batch_; }
  int num_layers() const { return spec_.num_layers(); }

  /// Lillicrap et al. (2016) initialisation: hidden layers' weights and biases uniform in
  /// [-1/sqrt(fan_in), 1/sqrt(fan_in)], the output layer's in [-3e-3, 3e-3] so that initial
  /// outputs (actions, Q values) are near zero.
  void init_lillicrap(Rng& rng);

  /// All parameters, flat (layout in the class comment).
  Eigen::Map<Vector> params() { return Eigen::Map<Vector>(params_.data(), params_.size()); }
  Eigen::Map<const Vector> params() const {
    return Eigen::Map<const Vector>(params_.data(), params_.size());
  }
  /// Gradients from the last backward() with GradRequest::params, same layout as params().
  Eigen::Map<Vector> grads() { return Eigen::Map<Vector>(grads_.data(), grads_.size()); }
  Eigen::Map<const Vector> grads() const {
    return Eigen::Map<const Vector>(grads_.data(), grads_.size());
  }
  Eigen::Index num_params() const { return params_.size(); }
  /// Number of leading entries of params() that are weights (the rest are biases).
  Eigen::Index num_weights() const { return num_weights_; }

  /// Weight matrix of layer l (out x in) and its bias, as views into params().
  Eigen::Map<Matrix> weight(int l);
  Eigen::Map<const Matrix> weight(int l) const;
  Eigen::Map<Vector> bias(int l);
  Eigen::Map<const Vector> bias(int l) const;
  /// Their gradients, as views into grads().
  Eigen::Map<const Matrix> weight_grad(int l) const;
  Eigen::Map<const Vector> bias_grad(int l) const;

  /// Forward pass on a batch (input_dim x n, 1 <= n <= max_batch) for a network without an extra
  /// input; returns the output (output_dim x n), valid until the next forward().
  Eigen::Block<const Matrix> forward(const ConstMatrixRef& input);
  /// Forward pass with the extra input (extra_input_dim x n), e.g. the critic's action.
  Eigen::Block<const Matrix> forward(const ConstMatrixRef& input, const ConstMatrixRef& extra);
  /// Output of the last forward pass.
  Eigen::Block<const Matrix> output() const;
  /// Batch size of the last forward pass (0 before the first).
  int batch() const { return batch_; }

  /// Backward pass for the last forward pass, given dL/d(output) (output_dim x n). Computes only
  /// what `what` asks for and stops as low in the network as that allows (the critic's dQ/da in
  /// the actor update needs no parameter gradients and, with the action at layer 1, no pass
  /// through layer 0). Gradients are set, not accumulated.
  void backward(const ConstMatrixRef& d_output, GradRequest what);
  /// dL/d(input) (input_dim x n) from the last backward() with GradRequest::input.
  Eigen::Block<const Matrix> input_grad() const;
  /// dL/d(extra input) (extra_input_dim x n) from the last backward() with
  /// GradRequest::extra_input.
  Eigen::Block<const Matrix> extra_input_grad() const;

  /// Copies the parameters of a network of the same spec (throws std::invalid_argument if not).
  void copy_params_from(const Mlp& other);

 private:
  void forward_layers();

  MlpSpec spec_;
  int max_batch_;
  int batch_ = 0;
  Eigen::Index num_weights_ = 0;
  std::vector<Eigen::Index> weight_offset_;
  std::vector<Eigen::Index> bias_offset_;
  Vector params_;
  Vector grads_;
  // x0_: input of layer 0 ([input; extra] when the extra input enters there).
  // act_[l]: output of layer l after its activation; for l = extra_input_layer - 1 it has the
  //   extra input below, so it is directly the input of the next layer.
  // delta_[l]: dL/d(pre-activation) of layer l, with rows for dL/d(extra) below where act_[l]
  //   has them (the product W^T delta writes both at once).
  // dx0_: dL/d(x0_).
  Matrix x0_;
  std::vector<Matrix> act_;
  std::vector<Matrix> delta_;
  Matrix dx0_;
  Vector scratch_;  // W^T of one layer at a time (gemm::multiply_tn)
};

/// Soft target update theta' <- tau theta + (1 - tau) theta' (Algorithm 1, lines 19-20);
/// tau = 1 copies. Throws std::invalid_argument if the specs differ.
void soft_update(Mlp& target, const Mlp& source, float tau);

/// The network whose every parameter is the mean of the networks' (a uniform "model soup",
/// Wortsman et al. 2022, for networks fine-tuned from one start), with the first one's
/// max_batch. Throws std::invalid_argument when there is none or their specs differ.
Mlp mean_of(const std::vector<const Mlp*>& nets);

/// Sets how many threads the layer products may use (needs OpenMP; 1 otherwise): large products
/// are split by columns. Programs linking this library start with 1: several learning processes
/// share a machine, one thread is what allocates nothing in the update loop, and on a machine
/// with more runnable threads than cores the products' barriers make several threads far
/// slower than one.
void set_num_threads(int n);
/// The current setting of set_num_threads().
int num_threads();

}  // namespace auvrl::nn
