// The network's serialised form: CRC-32, round trips, and every kind of bad buffer rejected with
// the network left untouched.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "common/nn/byte_io.hpp"
#include "common/nn/checksum.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"

namespace auvrl::nn {
namespace {

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "<no exception>";
}

Mlp make_critic(std::uint64_t seed) {
  Mlp net(MlpSpec::critic(29, 6, {64, 48}, 1), 8);
  Rng rng(seed);
  net.init_lillicrap(rng);
  return net;
}

TEST(Crc32, CheckValueAndSplitUpdates) {
  const char* s = "123456789";
  EXPECT_EQ(crc32(s, 9), 0xCBF43926u);
  EXPECT_EQ(crc32(s, 0), 0u);
  std::vector<std::uint8_t> data(1000);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 37 + 11);
  const std::uint32_t whole = crc32(data.data(), data.size());
  for (std::size_t cut : {1, 3, 8, 13, 999}) {
    Crc32 c;
    c.update(data.data(), cut);
    c.update(data.data() + cut, data.size() - cut);
    EXPECT_EQ(c.value(), whole) << cut;
  }
}

TEST(Crc32, MatchesTheValuesOfTheFormerHandWrittenTable) {
  // Computed by the slicing-by-8 code that zlib replaced: stored checksums stay valid.
  std::vector<std::uint8_t> data(100003);
  for (std::size_t i = 0; i < data.size(); ++i) {
    data[i] = static_cast<std::uint8_t>((i * 2654435761u) >> 13);
  }
  EXPECT_EQ(crc32(data.data(), data.size()), 0x732376CEu);
  Crc32 c;
  for (std::size_t at = 0; at < data.size(); at += 4099) {
    c.update(data.data() + at, std::min<std::size_t>(4099, data.size() - at));
  }
  EXPECT_EQ(c.value(), 0x732376CEu);
  Crc32 none;
  none.update(nullptr, 0);
  EXPECT_EQ(none.value(), 0u);
}

TEST(NetworkFormat, FilesWrittenBeforeZlibStillLoad) {
  // A network file written by the former CRC code (params linearly spaced in [-0.75, 1.25]).
  Mlp net(MlpSpec::actor(5, {7, 6}, 3), 1);
  load_network_file(AUVRL_NN_TEST_DATA_DIR "/written_by_slicing_crc.nn", net);
  Mlp expected(MlpSpec::actor(5, {7, 6}, 3), 1);
  expected.params().setLinSpaced(-0.75f, 1.25f);
  EXPECT_EQ(net.params(), expected.params());
  EXPECT_EQ(network_to_bytes(net), read_file(AUVRL_NN_TEST_DATA_DIR "/written_by_slicing_crc.nn"));
}

TEST(NetworkFormat, CommittedPolicyLoadsWithItsChecksum) {
  const std::vector<std::uint8_t> bytes = read_file(AUVRL_CONFIG_DIR "/policies/fast.nn");
  const Mlp policy = network_from_bytes(bytes, 1);  // checks the CRC
  EXPECT_GT(policy.num_params(), 0);
  std::uint32_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 4, 4);
  EXPECT_EQ(stored, crc32(bytes.data(), bytes.size() - 4));
  std::vector<std::uint8_t> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  EXPECT_THROW(network_from_bytes(flipped, 1), std::runtime_error);
}

TEST(NetworkFormat, LayoutIsAsDocumented) {
  Mlp net(MlpSpec::actor(3, {4}, 2), 1);
  net.params().setLinSpaced(-1.0f, 1.0f);
  const std::vector<std::uint8_t> b = network_to_bytes(net);
  // magic 8 + version 4 + input 4 + H 4 + hidden 4 + output 4 + extra 4 + layer 4 + acts 2 +
  // count 8 + params 4*(3*4 + 4*2 + 4 + 2) + crc 4
  EXPECT_EQ(b.size(), 8 + 4 * 7 + 2 + 8 + 4 * 26 + 4u);
  EXPECT_EQ(std::memcmp(b.data(), "AUVRLNN\0", 8), 0);
  EXPECT_EQ(b[8], 1);  // version 1, little-endian
  EXPECT_EQ(b[9] | b[10] | b[11], 0);
  EXPECT_EQ(b[12], 3);  // input_dim
  EXPECT_EQ(b[36], 1);  // hidden activation relu
  EXPECT_EQ(b[37], 2);  // output activation tanh
  float first;
  std::memcpy(&first, b.data() + 46, 4);
  EXPECT_EQ(first, -1.0f);
  std::uint32_t stored;
  std::memcpy(&stored, b.data() + b.size() - 4, 4);
  EXPECT_EQ(stored, crc32(b.data(), b.size() - 4));
}

TEST(NetworkFormat, RoundTripRestoresTheExactNetwork) {
  const Mlp a = make_critic(1);
  Mlp b = make_critic(2);
  ASSERT_NE(a.params(), b.params());
  load_network(b, network_to_bytes(a));
  EXPECT_EQ(a.params(), b.params());
  const Mlp c = network_from_bytes(network_to_bytes(a), 16);
  EXPECT_EQ(c.spec(), a.spec());
  EXPECT_EQ(c.params(), a.params());
  EXPECT_EQ(c.max_batch(), 16);
}

TEST(NetworkFormat, EveryCorruptedByteIsRejectedAndTheNetworkKept) {
  const std::vector<std::uint8_t> good = network_to_bytes(make_critic(1));
  Mlp target = make_critic(2);
  const Vector before = target.params();
  // Every header byte and a stride through the parameters and the CRC.
  for (std::size_t i = 0; i < good.size(); i += (i < 64 || i + 8 > good.size()) ? 1 : 97) {
    std::vector<std::uint8_t> bad = good;
    bad[i] ^= 0x10;
    EXPECT_THROW(load_network(target, bad), std::runtime_error) << "byte " << i;
  }
  EXPECT_EQ(target.params(), before);
  std::vector<std::uint8_t> bad = good;
  bad[2000] ^= 0x01;
  EXPECT_NE(message_of([&] { load_network(target, bad); }).find("checksum mismatch"),
            std::string::npos);
}

TEST(NetworkFormat, EveryTruncationIsRejected) {
  const std::vector<std::uint8_t> good = network_to_bytes(make_critic(1));
  Mlp target = make_critic(2);
  const Vector before = target.params();
  for (std::size_t n = 0; n < good.size(); n += (n < 64 || n + 8 > good.size()) ? 1 : 61) {
    EXPECT_THROW(load_network(target, good.data(), n), std::runtime_error) << n;
  }
  EXPECT_EQ(target.params(), before);
  EXPECT_NE(
      message_of([&] { load_network(target, good.data(), good.size() - 1); }).find("truncated"),
      std::string::npos);
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_NE(message_of([&] { load_network(target, longer); }).find("unexpected bytes"),
            std::string::npos);
}

TEST(NetworkFormat, WrongArchitectureMagicOrVersionIsNamed) {
  const Mlp actor(MlpSpec::actor(29, {64, 64}, 6), 4);
  Mlp critic = make_critic(1);
  const std::string msg = message_of([&] { load_network(critic, network_to_bytes(actor)); });
  EXPECT_NE(msg.find("architecture mismatch"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected in=29 hidden=64-48 out=1 (identity) extra=6 at layer 1"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("in=29 hidden=64-64 out=6 (tanh)"), std::string::npos) << msg;

  Mlp other_layer(MlpSpec::critic(29, 6, {64, 48}, 0), 4);
  EXPECT_THROW(load_network(other_layer, network_to_bytes(critic)), std::runtime_error);

  std::vector<std::uint8_t> bytes = network_to_bytes(critic);
  bytes[0] = 'X';
  EXPECT_NE(message_of([&] { load_network(critic, bytes); }).find("bad magic"), std::string::npos);
  bytes = network_to_bytes(critic);
  bytes[8] = 2;
  EXPECT_NE(message_of([&] {
              load_network(critic, bytes);
            }).find("unsupported format version 2, expected 1"),
            std::string::npos);
  bytes = network_to_bytes(critic);
  bytes[16] = 200;  // 200 hidden layers
  EXPECT_NE(message_of([&] { load_network(critic, bytes); }).find("number of hidden layers"),
            std::string::npos);
}

TEST(NetworkFile, AtomicWriteAndReadBack) {
  const std::string path = ::testing::TempDir() + "auvrl_net_" + std::to_string(::getpid());
  const Mlp a = make_critic(3);
  save_network_file(path, a);
  EXPECT_NE(::access(path.c_str(), F_OK), -1);
  EXPECT_EQ(::access((path + ".tmp").c_str(), F_OK), -1);  // no temporary left behind
  Mlp b = make_critic(4);
  load_network_file(path, b);
  EXPECT_EQ(a.params(), b.params());

  // A failing writer leaves the previous file in place.
  EXPECT_THROW(write_file_atomically(path,
                                     [](ByteSink& s) {
                                       s.write("partial", 7);
                                       throw std::runtime_error("disk full");
                                     }),
               std::runtime_error);
  EXPECT_EQ(::access((path + ".tmp").c_str(), F_OK), -1);
  Mlp c = make_critic(5);
  load_network_file(path, c);
  EXPECT_EQ(a.params(), c.params());

  // A corrupted file: the error names the file.
  std::vector<std::uint8_t> bytes = read_file(path);
  bytes[100] ^= 0xFF;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  }
  const std::string msg = message_of([&] { load_network_file(path, c); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("checksum mismatch"), std::string::npos) << msg;
  std::remove(path.c_str());
  EXPECT_NE(message_of([&] { load_network_file(path, c); }).find("cannot open"), std::string::npos);
}

TEST(NetworkFile, ADirectoryIsAnErrorNamingIt) {
  // A directory opens as a stream; its size is not a file's (it once asked for petabytes).
  const std::string dir = ::testing::TempDir();
  const std::string msg = message_of([&] { read_file(dir); });
  EXPECT_NE(msg.find(dir), std::string::npos) << msg;
  EXPECT_NE(msg.find("is a directory"), std::string::npos) << msg;
}

}  // namespace
}  // namespace auvrl::nn
