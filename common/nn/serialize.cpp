#include "common/nn/serialize.hpp"

#include <stdexcept>

#include "common/nn/byte_io.hpp"
#include "common/nn/file_io.hpp"

namespace auvrl::nn {
namespace {

constexpr char kMagic[8] = {'A', 'U', 'V', 'R', 'L', 'N', 'N', '\0'};
// Bounds on what a header may claim, so that corrupted sizes fail cleanly instead of
// allocating gigabytes before the checksum is reached.
constexpr std::uint32_t kMaxDim = 1u << 16;
constexpr std::uint32_t kMaxHidden = 64;

struct Parsed {
  MlpSpec spec;
  Vector params;
};

std::uint32_t bounded(Reader& r, const char* what, std::uint32_t lo, std::uint32_t hi) {
  const std::uint32_t v = r.u32();
  if (v < lo || v > hi) {
    r.fail(std::string(what) + " = " + std::to_string(v) + ", expected " + std::to_string(lo) +
           ".." + std::to_string(hi));
  }
  return v;
}

Parsed parse(const std::uint8_t* data, std::size_t size, const std::string& context) {
  SpanSource src(data, size);
  Reader r(src, context);
  r.expect_magic(kMagic);
  const std::uint32_t version = r.u32();
  if (version != kNetworkFormatVersion) {
    r.fail("unsupported format version " + std::to_string(version) + ", expected " +
           std::to_string(kNetworkFormatVersion));
  }
  Parsed p;
  MlpSpec& s = p.spec;
  s.input_dim = static_cast<int>(bounded(r, "input_dim", 1, kMaxDim));
  const std::uint32_t num_hidden = bounded(r, "number of hidden layers", 0, kMaxHidden);
  for (std::uint32_t i = 0; i < num_hidden; ++i) {
    s.hidden.push_back(static_cast<int>(bounded(r, "hidden layer size", 1, kMaxDim)));
  }
  s.output_dim = static_cast<int>(bounded(r, "output_dim", 1, kMaxDim));
  s.extra_input_dim = static_cast<int>(bounded(r, "extra_input_dim", 0, kMaxDim));
  s.extra_input_layer = static_cast<int>(bounded(r, "extra_input_layer", 0, num_hidden));
  if (s.extra_input_dim == 0) s.extra_input_layer = 0;
  for (std::uint32_t l = 0; l <= num_hidden; ++l) {
    const std::uint8_t a = r.u8();
    if (a > static_cast<std::uint8_t>(Activation::kTanh)) {
      r.fail("unknown activation kind " + std::to_string(a) + " for layer " + std::to_string(l));
    }
    if (l < num_hidden && a != static_cast<std::uint8_t>(Activation::kRelu)) {
      r.fail("hidden layer " + std::to_string(l) + " has activation " +
             to_string(static_cast<Activation>(a)) + ", expected relu");
    }
    if (l == num_hidden) s.output_activation = static_cast<Activation>(a);
  }
  // Parameter count implied by the architecture.
  std::uint64_t expected = 0;
  for (int l = 0; l < s.num_layers(); ++l) {
    expected += std::uint64_t(s.layer_out(l)) * std::uint64_t(s.layer_in(l)) + s.layer_out(l);
  }
  const std::uint64_t count = r.u64();
  if (count != expected) {
    r.fail("parameter count " + std::to_string(count) + ", but the architecture (" + s.describe() +
           ") has " + std::to_string(expected));
  }
  if (count * sizeof(float) > src.remaining()) {
    r.fail("truncated: " + std::to_string(count) + " parameters need " +
           std::to_string(count * sizeof(float)) + " bytes, only " +
           std::to_string(src.remaining()) + " left");
  }
  p.params.resize(static_cast<Eigen::Index>(count));
  r.f32_array(p.params.data(), count);
  r.verify_checksum();
  if (src.remaining() != 0) {
    r.fail(std::to_string(src.remaining()) + " unexpected bytes after the checksum");
  }
  return p;
}

}  // namespace

std::vector<std::uint8_t> network_to_bytes(const Mlp& net) {
  const MlpSpec& s = net.spec();
  std::vector<std::uint8_t> out;
  out.reserve(64 + 4 * s.hidden.size() + 4 * static_cast<std::size_t>(net.num_params()));
  VectorSink sink(out);
  Writer w(sink);
  w.bytes(kMagic, sizeof kMagic);
  w.u32(kNetworkFormatVersion);
  w.u32(static_cast<std::uint32_t>(s.input_dim));
  w.u32(static_cast<std::uint32_t>(s.hidden.size()));
  for (int h : s.hidden) w.u32(static_cast<std::uint32_t>(h));
  w.u32(static_cast<std::uint32_t>(s.output_dim));
  w.u32(static_cast<std::uint32_t>(s.extra_input_dim));
  w.u32(static_cast<std::uint32_t>(s.extra_input_dim > 0 ? s.extra_input_layer : 0));
  for (int l = 0; l < s.num_layers(); ++l) w.u8(static_cast<std::uint8_t>(s.layer_activation(l)));
  w.u64(static_cast<std::uint64_t>(net.num_params()));
  w.f32_array(net.params().data(), static_cast<std::size_t>(net.num_params()));
  w.checksum();
  return out;
}

void load_network(Mlp& net, const std::uint8_t* data, std::size_t size) {
  Parsed p = parse(data, size, "network");
  if (p.spec != net.spec()) {
    throw std::runtime_error("network: architecture mismatch: expected " + net.spec().describe() +
                             ", the data holds " + p.spec.describe());
  }
  net.params() = p.params;
}

Mlp network_from_bytes(const std::uint8_t* data, std::size_t size, int max_batch) {
  Parsed p = parse(data, size, "network");
  Mlp net(p.spec, max_batch);
  net.params() = p.params;
  return net;
}

void save_network_file(const std::string& path, const Mlp& net) {
  write_file_atomically(path, network_to_bytes(net));
}

void load_network_file(const std::string& path, Mlp& net) {
  const std::vector<std::uint8_t> bytes = read_file(path);
  try {
    load_network(net, bytes);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace auvrl::nn
