// The lcm-spy jar decodes every one of our types: C++ encodes each type (the generated
// encode(), on values drawn for every field), a Java program decodes the log with the jar's
// classes (the same classes lcm-spy loads) and prints every field; each printed value must be
// the value C++ encoded. Covers every .lcm file in lcmtypes/ and the logger's test types.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include "child_process.hpp"
#include "generated_types.hpp"
#include "logger/decode.hpp"
#include "logger/event_log.hpp"
#include "logger/sample.hpp"

namespace {

using namespace auvrl;
using namespace auvrl::logger;

/// What Java should print for a field C++ encoded.
bool java_agrees(const FieldValue& field, const std::string& java) {
  switch (field.type) {
    case Primitive::kString:
      return java == "s:" + to_hex(field.text);
    case Primitive::kBoolean:
      return java == (field.integer != 0 ? "true" : "false");
    case Primitive::kByte:  // Java's byte is signed
      return java == std::to_string(static_cast<std::int8_t>(field.integer));
    case Primitive::kFloat: {
      char* end = nullptr;
      const float value = std::strtof(java.c_str(), &end);
      return *end == '\0' && value == static_cast<float>(field.real);
    }
    case Primitive::kDouble: {
      char* end = nullptr;
      const double value = std::strtod(java.c_str(), &end);
      return *end == '\0' && value == field.real;
    }
    default:
      return java == std::to_string(field.integer);
  }
}

TEST(JarDecode, TheJarDecodesEveryTypeToTheValuesCppEncoded) {
  const Schema schema = logger::test_types::all_types_schema();
  const std::string dir = test_support::make_temp_dir("auvrl_jar_decode_");
  const std::string log_dir = dir + "/log";
  DecodeOptions per_byte;
  per_byte.byte_arrays_as_blobs = false;  // Java has no blob notion: one value per byte

  // Write each type, three times with different values, through the generated encode().
  std::vector<std::pair<std::string, std::vector<FieldValue>>> expected;
  RotatingLogWriter writer(log_dir, "types", 1u << 30);
  for (const auto& type : logger::test_types::generated_types()) {
    const StructType* parsed = schema.find_by_name(type.full_name);
    ASSERT_NE(parsed, nullptr) << type.full_name;
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      std::vector<std::uint8_t> encoded;
      ASSERT_TRUE(type.reencode(make_sample_message(*parsed, seed * 101), encoded));
      writer.write(type.full_name, encoded.data(), encoded.size(), static_cast<std::int64_t>(seed));
      DecodedMessage message;
      std::string error;
      ASSERT_EQ(decode_message(schema, encoded.data(), encoded.size(), message, error, per_byte),
                DecodeStatus::kOk)
          << error;
      expected.emplace_back(type.full_name, message.fields);
    }
  }
  writer.close();

  const std::string java_out = dir + "/java.txt";
  test_support::ChildProcess java(
      {AUVRL_JAVA, "-cp", AUVRL_JAR_DECODE_CLASSPATH, "JarDecode", writer.files().at(0), java_out},
      dir + "/java.log");
  const int status = java.wait_for_exit(std::chrono::seconds(60));
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << java.log();

  // Parse "== CHANNEL" blocks of name=value lines.
  std::vector<std::pair<std::string, std::map<std::string, std::string>>> decoded;
  std::ifstream in(java_out);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("== ", 0) == 0) {
      decoded.emplace_back(line.substr(3), std::map<std::string, std::string>());
      continue;
    }
    ASSERT_FALSE(decoded.empty()) << line;
    const auto eq = line.find('=');
    ASSERT_NE(eq, std::string::npos) << line;
    decoded.back().second[line.substr(0, eq)] = line.substr(eq + 1);
  }
  ASSERT_EQ(decoded.size(), expected.size()) << java.log();
  std::size_t fields_compared = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto& [type_name, fields] = expected[i];
    const auto& [channel, java_fields] = decoded[i];
    ASSERT_EQ(channel, type_name);
    EXPECT_EQ(java_fields.size(), fields.size()) << type_name;
    for (const FieldValue& field : fields) {
      const auto it = java_fields.find(field.name);
      ASSERT_NE(it, java_fields.end()) << type_name << ": Java has no field " << field.name;
      EXPECT_TRUE(java_agrees(field, it->second)) << type_name << "." << field.name << ": C++ "
                                                  << format_value(field) << ", Java " << it->second;
      ++fields_compared;
    }
  }
  EXPECT_GT(fields_compared, 1000u);
  std::filesystem::remove_all(dir);
}

}  // namespace
