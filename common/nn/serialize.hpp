// The one serialised form of a network, used for checkpoints, for the weights message and for
// deploying a trained policy.
//
// Format version 1, every integer and float little-endian:
//   char[8]  magic "AUVRLNN\0"
//   u32      format version (1)
//   u32      input_dim
//   u32      number of hidden layers H, then u32[H] their sizes
//   u32      output_dim
//   u32      extra_input_dim, u32 extra_input_layer (see MlpSpec)
//   u8[H+1]  activation of each weight layer (Activation values: 0 identity, 1 relu, 2 tanh)
//   u64      number of parameters P
//   f32[P]   Mlp::params() (each layer's weights column-major, then each layer's biases)
//   u32      CRC-32 (zlib's) of every byte above
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/nn/mlp.hpp"

namespace auvrl::nn {

/// Current network format version.
inline constexpr std::uint32_t kNetworkFormatVersion = 1;

/// The network's architecture and parameters in the format above.
std::vector<std::uint8_t> network_to_bytes(const Mlp& net);

/// Replaces net's parameters with those in `data`, after checking the magic, the version, the
/// sizes, the checksum and that the stored architecture equals net.spec(). Throws
/// std::runtime_error saying what was expected and what was found; net is unchanged then.
void load_network(Mlp& net, const std::uint8_t* data, std::size_t size);
inline void load_network(Mlp& net, const std::vector<std::uint8_t>& bytes) {
  load_network(net, bytes.data(), bytes.size());
}

/// A new network with whatever architecture `data` holds (all checks but the architecture's).
Mlp network_from_bytes(const std::uint8_t* data, std::size_t size, int max_batch);
inline Mlp network_from_bytes(const std::vector<std::uint8_t>& bytes, int max_batch) {
  return network_from_bytes(bytes.data(), bytes.size(), max_batch);
}

/// Writes network_to_bytes(net) to `path` atomically (temporary file + rename).
void save_network_file(const std::string& path, const Mlp& net);
/// load_network() from a file; errors name the path.
void load_network_file(const std::string& path, Mlp& net);

}  // namespace auvrl::nn
