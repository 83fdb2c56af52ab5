// The runtime schema: every .lcm type parses and its fingerprint equals the one lcm-gen put in
// the generated C++ (getHash()); the parsed structure is right; bad .lcm text gives an error
// that names the file, the line and what was expected.
#include <gtest/gtest.h>

#include <set>

#include "generated_types.hpp"
#include "logger/schema.hpp"

namespace {

using namespace auvrl::logger;

TEST(Schema, FingerprintOfEveryTypeMatchesTheGeneratedCode) {
  const Schema schema = test_types::all_types_schema();
  const auto generated = test_types::generated_types();
  ASSERT_GE(generated.size(), 10u);  // 7+ wire types and 4 test types at the time of writing
  std::set<std::string> seen;
  for (const auto& type : generated) {
    const StructType* parsed = schema.find_by_name(type.full_name);
    ASSERT_NE(parsed, nullptr) << type.full_name << " has generated code but was not parsed";
    EXPECT_EQ(parsed->fingerprint, type.hash)
        << type.full_name << ": schema " << fingerprint_hex(parsed->fingerprint) << ", lcm-gen "
        << fingerprint_hex(type.hash);
    EXPECT_EQ(schema.find_by_fingerprint(type.hash), parsed) << type.full_name;
    seen.insert(type.full_name);
  }
  // And every parsed type has generated code, so none escapes the comparison.
  for (const auto& type : schema.types()) {
    EXPECT_EQ(seen.count(type->full_name), 1u) << type->full_name << " has no generated code";
  }
}

TEST(Schema, ParsesMembersDimensionsAndConstants) {
  const Schema schema = test_types::all_types_schema();
  const StructType* t = schema.find_by_name("auvrl_logger_test.nested_arrays_t");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->package, "auvrl_logger_test");
  EXPECT_EQ(t->short_name, "nested_arrays_t");
  std::vector<std::string> names;
  for (const Member& m : t->members) names.push_back(m.name);
  EXPECT_EQ(names, (std::vector<std::string>{"rows", "cols", "n", "count64", "grid", "fixed2d",
                                             "mixed", "mixed2", "points", "corners", "origin",
                                             "names", "flags", "blob", "blobs2d", "a", "b", "c"}));
  const Member& grid = t->members[4];
  ASSERT_EQ(grid.dimensions.size(), 2u);
  EXPECT_TRUE(grid.dimensions[0].variable);
  EXPECT_EQ(grid.dimensions[0].size_member, 0);
  EXPECT_EQ(grid.dimensions[1].size_member, 1);
  const Member& mixed2 = t->members[7];
  EXPECT_FALSE(mixed2.dimensions[0].variable);
  EXPECT_EQ(mixed2.dimensions[0].fixed_size, 2);
  EXPECT_TRUE(mixed2.dimensions[1].variable);
  const Member& corners = t->members[9];
  EXPECT_FALSE(corners.is_primitive);
  EXPECT_EQ(corners.nested, schema.find_by_name("auvrl_logger_test.point_t"));
  EXPECT_EQ(t->members[10].nested, corners.nested);  // unqualified name, same package

  const StructType* prims = schema.find_by_name("all_primitives_t");  // short name works
  ASSERT_NE(prims, nullptr);
  EXPECT_EQ(prims->members.size(), 9u);  // constants are not members
  ASSERT_EQ(prims->constants.size(), 3u);
  EXPECT_EQ(prims->constants[1].name, "HEX");
  EXPECT_EQ(prims->constants[1].value_text, "0x10");
  // Floating-point constants parse too (lcm-gen's C++ for them does not compile, so no test
  // type has one).
  const Schema floats = Schema::from_sources(
      {{"f.lcm", "struct f_t { const double SCALE = 1.5e-3; const float NEG = -2.5; int8_t x; }"}});
  EXPECT_EQ(floats.find_by_name("f_t")->constants.size(), 2u);

  // vehicle_state_t's constants (several in one declaration) are not members either.
  const StructType* state = schema.find_by_name("auvrl_lcm.vehicle_state_t");
  ASSERT_NE(state, nullptr);
  EXPECT_EQ(state->constants.size(), 4u);
  for (const Member& m : state->members) EXPECT_NE(m.name.rfind("STATUS_", 0), 0u) << m.name;
}

TEST(Schema, MinimumEncodedSizeCountsFixedPartsOnly) {
  const Schema schema = Schema::from_sources({{"a.lcm", R"(
    package p;
    struct inner_t { int16_t x; double v[2]; }
    struct outer_t { int8_t n; inner_t fixed[3]; inner_t var[n]; string s; boolean b; }
  )"}});
  EXPECT_EQ(schema.find_by_name("p.inner_t")->min_encoded_size, 2u + 16u);
  EXPECT_EQ(schema.find_by_name("p.outer_t")->min_encoded_size, 1u + 3u * 18u + 0u + 5u + 1u);
}

TEST(Schema, StructurallyEqualTypesShareAFingerprintAndBothAreNamed) {
  const Schema schema = Schema::from_sources({{"a.lcm", "package p; struct a_t { double x; }"},
                                              {"b.lcm", "package p; struct b_t { double x; }"}});
  const auto fp = schema.find_by_name("p.a_t")->fingerprint;
  EXPECT_EQ(schema.find_by_name("p.b_t")->fingerprint, fp);
  EXPECT_EQ(schema.names_for(fp), "p.a_t or p.b_t");
  EXPECT_EQ(schema.names_for(12345), "unknown type 0x0000000000003039");
}

/// The error text for a schema source, or "" if it parses.
std::string error_for(const std::string& text) {
  try {
    Schema::from_sources({{"bad.lcm", text}});
  } catch (const SchemaError& e) {
    return e.what();
  }
  return "";
}

TEST(Schema, ErrorsNameTheFileTheLineAndWhatWasExpected) {
  EXPECT_EQ(error_for("package p;\nstruct a_t\n{\n  nope_t x;\n}"),
            "bad.lcm:4: member 'x' of p.a_t has type p.nope_t, which is neither an LCM primitive "
            "nor a type in the files read");
  EXPECT_NE(error_for("struct a_t {\n double v[n];\n}").find("bad.lcm:2: array size must be"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t {\n double n;\n double v[n];\n}")
                .find("bad.lcm:3: array size member must be a scalar int"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t {\n double v[0];\n}").find("constant array size > 0"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t { double x; double x; }").find("duplicate member name"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t { double x }").find("expected ';'"), std::string::npos);
  EXPECT_NE(error_for("struct a_t { double x;").find("end of file, expected"), std::string::npos);
  EXPECT_NE(error_for("/* open\nstruct a_t { double x; }").find("bad.lcm:1: comment '/*'"),
            std::string::npos);
  EXPECT_NE(error_for("enum e_t { A, B }").find("enums are not supported"), std::string::npos);
  EXPECT_NE(error_for("struct a_t { const string S = 1; }").find("expected a constant type"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t { const int8_t K = x; }").find("expected a int8_t value"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t { double x; }\nstruct a_t { double y; }")
                .find("type a_t is already declared"),
            std::string::npos);
  EXPECT_NE(error_for("struct a_t { double x; } @").find("unexpected character '@'"),
            std::string::npos);
  EXPECT_EQ(error_for("// just a comment\npackage p;\n"), "");
}

TEST(Schema, MissingDirectoryIsAClearError) {
  try {
    Schema::from_directories({"/nonexistent/types"});
    FAIL() << "no error";
  } catch (const SchemaError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/types"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("--types-dir"), std::string::npos);
  }
}

TEST(Schema, DefaultTypesDirectoryHoldsTheWireTypes) {
  const Schema schema = Schema::from_directories({default_types_dir()});
  EXPECT_NE(schema.find_by_name("auvrl_lcm.vehicle_state_t"), nullptr);
  EXPECT_NE(schema.find_by_name("auvrl_lcm.logger_heartbeat_t"), nullptr);
}

}  // namespace
