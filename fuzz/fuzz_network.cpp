// The network loader (common/nn/serialize): bytes as a serialised network, read both ways the
// system reads one: network_from_bytes (the actor's weights, the evaluation's policy file)
// and load_network into a fixed architecture (checkpoints). A bad network must be refused with
// std::runtime_error; an accepted one then runs forward once.
#include "common/nn/serialize.hpp"
#include "fuzz/fuzz_util.hpp"

using namespace auvrl;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    nn::Mlp net = nn::network_from_bytes(data, size, 2);
    const nn::Matrix input = nn::Matrix::Zero(net.spec().input_dim, 1);
    if (net.spec().extra_input_dim > 0) {
      (void)net.forward(input, nn::Matrix::Zero(net.spec().extra_input_dim, 1));
    } else {
      (void)net.forward(input);
    }
  } catch (const std::runtime_error&) {
  }
  static nn::Mlp fixed = [] {
    nn::MlpSpec spec;
    spec.input_dim = 4;
    spec.hidden = {8, 8};
    spec.output_dim = 2;
    spec.output_activation = nn::Activation::kTanh;
    return nn::Mlp(spec, 2);
  }();
  try {
    nn::load_network(fixed, data, size);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
