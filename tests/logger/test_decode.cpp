// Decoding with the runtime schema, against the generated C++: every type round-trips through
// the generated decode/encode byte for byte, named fields carry the values the generated
// structs were given, and malformed bytes (truncated, flipped, absurd lengths) give errors,
// never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_logger_test/all_primitives_t.hpp>
#include <auvrl_logger_test/nested_arrays_t.hpp>
#include <map>
#include <random>

#include "generated_types.hpp"
#include "logger/decode.hpp"
#include "logger/sample.hpp"

namespace {

using namespace auvrl::logger;

template <class Msg>
std::vector<std::uint8_t> encode(const Msg& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return bytes;
}

/// Decodes and returns columns by name (fails the test on a decode error).
std::map<std::string, FieldValue> decode_by_name(const Schema& schema,
                                                 const std::vector<std::uint8_t>& bytes,
                                                 DecodeOptions options = {}) {
  DecodedMessage message;
  std::string error;
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error, options),
            DecodeStatus::kOk)
      << error;
  std::map<std::string, FieldValue> by_name;
  for (const FieldValue& f : message.fields) {
    EXPECT_TRUE(by_name.emplace(f.name, f).second) << "duplicate column " << f.name;
  }
  return by_name;
}

TEST(Decode, EveryTypeRoundTripsThroughTheGeneratedCode) {
  const Schema schema = test_types::all_types_schema();
  for (const auto& type : test_types::generated_types()) {
    const StructType* parsed = schema.find_by_name(type.full_name);
    ASSERT_NE(parsed, nullptr) << type.full_name;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      SampleOptions options;
      options.min_variable_length = seed == 1 ? 0 : 1;  // empty arrays once
      const std::vector<std::uint8_t> sample = make_sample_message(*parsed, seed, options);
      // The generated code accepts the bytes as exactly one message and writes them back
      // unchanged: the schema's layout is lcm-gen's.
      std::vector<std::uint8_t> again;
      ASSERT_TRUE(type.reencode(sample, again)) << type.full_name << " seed " << seed;
      ASSERT_EQ(again, sample) << type.full_name << " seed " << seed;
      DecodedMessage message;
      std::string error;
      ASSERT_EQ(decode_message(schema, again.data(), again.size(), message, error),
                DecodeStatus::kOk)
          << type.full_name << ": " << error;
      EXPECT_EQ(message.type, parsed);
      EXPECT_FALSE(message.fields.empty());
    }
  }
}

TEST(Decode, NamedColumnsHoldTheGeneratedStructsValues) {
  const Schema schema = test_types::all_types_schema();
  auvrl_lcm::vehicle_state_t state{};
  state.utime = 1234567890123456;
  state.vehicle_id = 3;
  state.seq = -42;
  state.position_ned_m[1] = 6.25;
  state.euler_rpy_rad[2] = -0.1;
  state.num_thrusters = 6;
  state.thrust_realised_n = {1.5, -2.5, 3.5, -4.5, 5.5, 1e-300};
  state.current_ned_mps[0] = 0.125;
  state.status = auvrl_lcm::vehicle_state_t::STATUS_SPEED_LIMIT;
  auto columns = decode_by_name(schema, encode(state));
  EXPECT_EQ(columns.at("utime").integer, 1234567890123456);
  EXPECT_EQ(columns.at("vehicle_id").integer, 3);
  EXPECT_EQ(columns.at("seq").integer, -42);
  EXPECT_EQ(columns.at("position_ned_m[1]").real, 6.25);
  EXPECT_EQ(columns.at("euler_rpy_rad[2]").real, -0.1);
  EXPECT_EQ(columns.at("num_thrusters").integer, 6);
  EXPECT_EQ(columns.at("thrust_realised_n[1]").real, -2.5);
  EXPECT_EQ(columns.at("thrust_realised_n[5]").real, 1e-300);
  EXPECT_EQ(columns.count("thrust_realised_n[6]"), 0u);
  EXPECT_EQ(columns.at("current_ned_mps[0]").real, 0.125);
  EXPECT_EQ(columns.at("status").integer, 2);
  EXPECT_EQ(columns.count("STATUS_OK"), 0u);  // constants are not columns
  EXPECT_EQ(format_value(columns.at("euler_rpy_rad[2]")), "-0.10000000000000001");
  EXPECT_EQ(std::stod(format_value(columns.at("euler_rpy_rad[2]"))), -0.1);

  auvrl_logger_test::nested_arrays_t n{};
  n.rows = 2;
  n.cols = 3;
  n.n = 2;
  n.count64 = 1;
  n.grid = {{1, 2, 3}, {4, 5, 6.5}};
  n.fixed2d[1][2] = 0.1f;
  n.mixed = {{1, 2, 3, 4}, {5, 6, 7, -8}};
  n.mixed2 = {{1, 2, 3}, {4, 5, -6}};
  n.points.resize(2);
  n.points[1].xyz[2] = 9.5;
  n.points[0].label = "first, \"quoted\"";
  n.corners[1].label = "corner";
  n.origin.xyz[0] = -1;
  n.names = {"a", "\xc3\xa9t\xc3\xa9"};
  n.flags = {{0, 1}, {1, 0}};
  n.blob = {0x00, 0xff};
  n.blobs2d = {{1, 2, 3}, {0xde, 0xad, 0xbe}};
  n.a = -7;
  n.b[1] = 8;
  n.c = {{100, -100}};
  columns = decode_by_name(schema, encode(n));
  EXPECT_EQ(columns.at("grid[1][2]").real, 6.5);
  EXPECT_EQ(columns.count("grid[2][0]"), 0u);
  EXPECT_EQ(columns.at("fixed2d[1][2]").type, Primitive::kFloat);
  EXPECT_EQ(columns.at("fixed2d[1][2]").real, static_cast<double>(0.1f));
  EXPECT_EQ(format_value(columns.at("fixed2d[1][2]")), "0.100000001");
  EXPECT_EQ(columns.at("mixed[1][3]").integer, -8);
  EXPECT_EQ(columns.at("mixed2[1][2]").integer, -6);
  EXPECT_EQ(columns.at("points[1].xyz[2]").real, 9.5);
  EXPECT_EQ(columns.at("points[0].label").text, "first, \"quoted\"");
  EXPECT_EQ(columns.at("corners[1].label").text, "corner");
  EXPECT_EQ(columns.at("origin.xyz[0]").real, -1.0);
  EXPECT_EQ(columns.at("names[1]").text, "\xc3\xa9t\xc3\xa9");
  EXPECT_EQ(columns.at("flags[0][1]").integer, 1);
  EXPECT_EQ(columns.at("flags[1][1]").integer, 0);
  // Byte arrays: the innermost dimension is one hex column by default...
  EXPECT_TRUE(columns.at("blob").blob);
  EXPECT_EQ(format_value(columns.at("blob")), "00ff");
  EXPECT_EQ(format_value(columns.at("blobs2d[1]")), "deadbe");
  EXPECT_EQ(columns.at("a").integer, -7);
  EXPECT_EQ(columns.at("b[1]").integer, 8);
  EXPECT_EQ(columns.at("c[0][1]").integer, -100);
  // ...and one column per byte on request.
  DecodeOptions expand;
  expand.byte_arrays_as_blobs = false;
  columns = decode_by_name(schema, encode(n), expand);
  EXPECT_EQ(columns.at("blob[1]").integer, 255);
  EXPECT_EQ(columns.at("blobs2d[1][0]").integer, 0xde);
  EXPECT_EQ(columns.count("blob"), 0u);

  auvrl_logger_test::all_primitives_t p{};
  p.i8 = -128;
  p.i16 = -32768;
  p.i32 = INT32_MIN;
  p.i64 = INT64_MIN;
  p.b = 200;
  p.f = -3.25f;
  p.d = 6.02214076e23;
  p.s = "";
  p.flag = 1;
  columns = decode_by_name(schema, encode(p));
  EXPECT_EQ(columns.at("i8").integer, -128);
  EXPECT_EQ(columns.at("i16").integer, -32768);
  EXPECT_EQ(columns.at("i32").integer, INT32_MIN);
  EXPECT_EQ(columns.at("i64").integer, INT64_MIN);
  EXPECT_EQ(columns.at("b").integer, 200);
  EXPECT_EQ(format_value(columns.at("f")), "-3.25");
  EXPECT_EQ(columns.at("d").real, 6.02214076e23);
  EXPECT_EQ(columns.at("s").text, "");
  EXPECT_EQ(format_value(columns.at("flag")), "1");
  EXPECT_EQ(columns.size(), 9u);
}

TEST(Decode, EveryTruncationIsAnErrorNamingTheField) {
  const Schema schema = test_types::all_types_schema();
  for (const auto& type : schema.types()) {
    const std::vector<std::uint8_t> sample = make_sample_message(*type, 7);
    DecodedMessage message;
    std::string error;
    for (std::size_t size = 0; size < sample.size(); ++size) {
      ASSERT_EQ(decode_message(schema, sample.data(), size, message, error),
                DecodeStatus::kMalformed)
          << type->full_name << " cut to " << size << " bytes";
      ASSERT_FALSE(error.empty());
    }
    // One byte too many is refused as well: the generated code would not accept it either.
    std::vector<std::uint8_t> longer = sample;
    longer.push_back(0);
    ASSERT_EQ(decode_message(schema, longer.data(), longer.size(), message, error),
              DecodeStatus::kMalformed);
    EXPECT_NE(error.find("1 bytes left over"), std::string::npos) << error;
  }
}

TEST(Decode, AStringWithANulBeforeItsEndIsMalformed) {
  // The generated code re-encodes a string up to its first NUL: a NUL inside is not a string
  // it could have sent (found by the random corruption below).
  const Schema schema = test_types::all_types_schema();
  auvrl_lcm::vehicle_state_t state{};
  state.vehicle_name = "nessie7";
  std::vector<std::uint8_t> bytes = encode(state);
  const auto at =
      std::search(bytes.begin(), bytes.end(), state.vehicle_name.begin(), state.vehicle_name.end());
  ASSERT_NE(at, bytes.end());
  DecodedMessage message;
  std::string error;
  ASSERT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error), DecodeStatus::kOk)
      << error;
  *(at + 3) = 0;  // "nes\0ie7"
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kMalformed);
  EXPECT_NE(error.find("vehicle_name"), std::string::npos) << error;
  EXPECT_NE(error.find("a NUL byte inside the string"), std::string::npos) << error;
}

TEST(Decode, RandomCorruptionNeverCrashesAndAgreesWithTheGeneratedCode) {
  const Schema schema = test_types::all_types_schema();
  std::mt19937_64 rng(11);
  for (const auto& type : test_types::generated_types()) {
    const StructType* parsed = schema.find_by_name(type.full_name);
    const std::vector<std::uint8_t> sample = make_sample_message(*parsed, 3);
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<std::uint8_t> bytes = sample;
      // Flip 1-3 bytes after the fingerprint (lengths, counts, values).
      const int flips = 1 + static_cast<int>(rng() % 3);
      for (int f = 0; f < flips && bytes.size() > 8; ++f) {
        bytes[8 + rng() % (bytes.size() - 8)] ^= static_cast<std::uint8_t>(1 + rng() % 255);
      }
      DecodedMessage message;
      std::string error;
      const DecodeStatus status =
          decode_message(schema, bytes.data(), bytes.size(), message, error);
      if (status != DecodeStatus::kOk && error.find("cannot fit") != std::string::npos) {
        // The generated code would first allocate the absurd length (up to gigabytes), then
        // fail: not worth running.
        continue;
      }
      std::vector<std::uint8_t> again;
      const bool generated_ok = type.reencode(bytes, again);
      // What the schema decoder accepts, the generated code accepts too; the other way round
      // only a negative array length that is never used (an outer dimension of 0) separates
      // them: the generated code ignores it, the decoder refuses it as malformed.
      if (status == DecodeStatus::kOk) {
        EXPECT_TRUE(generated_ok) << type.full_name << " trial " << trial;
      } else if (generated_ok) {
        EXPECT_NE(error.find("negative"), std::string::npos)
            << type.full_name << " trial " << trial << ": " << error;
      }
    }
  }
}

TEST(Decode, AbsurdArrayLengthsAreRefusedBeforeAllocating) {
  const Schema schema = test_types::all_types_schema();
  auvrl_lcm::thruster_cmd_t cmd{};
  cmd.num_thrusters = 2;
  cmd.thrust_n = {1, 2};
  std::vector<std::uint8_t> bytes = encode(cmd);
  // num_thrusters is the int8 after utime (8), vehicle_id (4), seq (8), past the fingerprint.
  const std::size_t at = 8 + 8 + 4 + 8;
  DecodedMessage message;
  std::string error;
  bytes[at] = 0x7f;  // 127 doubles promised, 2 present
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kMalformed);
  EXPECT_NE(error.find("thrust_n"), std::string::npos) << error;
  EXPECT_NE(error.find("cannot fit"), std::string::npos) << error;
  bytes[at] = 0xff;  // -1
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kMalformed);
  EXPECT_NE(error.find("negative"), std::string::npos) << error;

  // A 2-D array whose dimensions multiply past 64 bits.
  auvrl_logger_test::nested_arrays_t n{};
  bytes = encode(n);
  for (int i = 0; i < 4; ++i) bytes[8 + static_cast<std::size_t>(i)] = i == 0 ? 0x7f : 0xff;
  bytes[12] = 0x7f;  // cols
  bytes[13] = 0xff;
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kMalformed);
  EXPECT_NE(error.find("grid"), std::string::npos) << error;

  // A string length beyond the message, and a zero length (it counts the NUL).
  auvrl_logger_test::all_primitives_t p{};
  p.s = "abc";
  bytes = encode(p);
  const std::size_t s_at = 8 + 1 + 2 + 4 + 8 + 1 + 4 + 8;
  bytes[s_at] = 0x10;
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kMalformed);
  EXPECT_NE(error.find(".s at byte"), std::string::npos) << error;
  bytes[s_at] = 0;
  bytes[s_at + 3] = 0;
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kMalformed);
  EXPECT_NE(error.find("string length 0"), std::string::npos) << error;
}

TEST(Decode, ColumnOrderKeysFollowTheEncodingOrder) {
  const Schema schema = test_types::all_types_schema();
  const StructType& t = *schema.find_by_name("auvrl_logger_test.nested_arrays_t");
  using Key = std::vector<std::int64_t>;
  EXPECT_EQ(column_order_key(t, "points[1].xyz[2]"), (Key{8, 1, 0, 2}));
  EXPECT_EQ(column_order_key(t, "blob"), (Key{13}));
  EXPECT_LT(column_order_key(t, "grid[0][9]"), column_order_key(t, "grid[1][0]"));
  EXPECT_LT(column_order_key(t, "grid[1][10]"), column_order_key(t, "fixed2d[0][0]"));
  EXPECT_LT(column_order_key(t, "b[1]"), column_order_key(t, "c[0][0]"));
  EXPECT_EQ(column_order_key(t, "nope").back(), INT64_MAX);
}

TEST(Decode, UnknownFingerprintIsReportedAsSuch) {
  const Schema schema = test_types::all_types_schema();
  const std::vector<std::uint8_t> bytes = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  DecodedMessage message;
  std::string error;
  EXPECT_EQ(decode_message(schema, bytes.data(), bytes.size(), message, error),
            DecodeStatus::kUnknownType);
  EXPECT_EQ(message.fingerprint, 0x0102030405060708u);
  EXPECT_NE(error.find("0x0102030405060708"), std::string::npos);
  EXPECT_EQ(decode_message(schema, bytes.data(), 3, message, error), DecodeStatus::kMalformed);
}

}  // namespace
