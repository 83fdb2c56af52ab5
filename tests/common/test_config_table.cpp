// config::Table: one declaration per setting drives the YAML reader, the flags and the docs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"

namespace {

using namespace auvrl;

enum class Mode { kFast, kSlow };
Mode parse_mode(const std::string& text) {
  if (text == "fast") return Mode::kFast;
  if (text == "slow") return Mode::kSlow;
  throw std::invalid_argument("expected fast or slow, got '" + text + "'");
}
const char* to_string(Mode m) { return m == Mode::kFast ? "fast" : "slow"; }

struct Inner {
  double depth_m = 10.0;
};

struct Settings {
  int batch_size = 64;
  std::uint64_t replay_capacity = 1000;
  float rate = 0.5f;
  bool verbose = false;
  bool filter = true;
  std::string name = "x";
  std::vector<int> hidden{400, 300};
  Eigen::Vector3d start{0, 0, 5};
  std::vector<std::vector<double>> knots{{0, 1.5}};
  Mode mode = Mode::kFast;
  struct {
    int timeout_ms = 200;
  } lockstep;
  Inner inner;
};

config::Table<Settings> make_table() {
  config::Table<Inner> inner("inner", "a sub-map");
  inner.field("depth_m", &Inner::depth_m, "m", "a depth");
  config::Table<Settings> t("test", "settings of the test");
  t.field("batch_size", &Settings::batch_size, "transitions", "minibatch").range(1);
  t.field("replay_capacity", &Settings::replay_capacity, "transitions", "capacity");
  t.field("rate", &Settings::rate, "", "a rate").range(0, 1);
  t.field("verbose", &Settings::verbose, "", "talk");
  t.field("filter", &Settings::filter, "", "filter");
  t.field("name", &Settings::name, "", "a name");
  t.field("hidden", &Settings::hidden, "units", "hidden sizes");
  t.field("start", &Settings::start, "m", "start position");
  t.field("knots", &Settings::knots, "", "knots");
  t.choice("mode", &Settings::mode, parse_mode, to_string, "fast, slow", "the mode");
  t.field(
      "timeout_ms", [](Settings& s) -> int& { return s.lockstep.timeout_ms; }, "ms", "timeout");
  t.section("inner", inner, &Settings::inner);
  return t;
}

config::Section load(const std::string& text) {
  // One file per test: CTest runs the tests of this executable in parallel processes.
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string path =
      (std::filesystem::temp_directory_path() / ("auvrl_test_config_table_" + name + ".yaml"))
          .string();
  std::ofstream(path) << text;
  return config::load_file(path);
}

std::string read_error(const std::string& text) {
  Settings s;
  try {
    make_table().read(load(text).child("test"), s);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

bool parse(cli::CommandLine& cmd, std::vector<const char*> args) {
  args.insert(args.begin(), "prog");
  return cmd.parse(static_cast<int>(args.size()), args.data());
}

TEST(ConfigTable, ReadsEveryTypeFromYaml) {
  Settings s;
  make_table().read(load("test:\n  batch_size: 32\n  replay_capacity: 500\n  rate: 0.25\n"
                         "  verbose: true\n  name: abc\n  hidden: [64, 64]\n  start: [1, 2, 3]\n"
                         "  knots: [[0, 1], [10, 0.5]]\n  mode: slow\n  timeout_ms: 50\n"
                         "  inner:\n    depth_m: 2.5\n")
                        .child("test"),
                    s);
  EXPECT_EQ(s.batch_size, 32);
  EXPECT_EQ(s.replay_capacity, 500u);
  EXPECT_FLOAT_EQ(s.rate, 0.25f);
  EXPECT_TRUE(s.verbose);
  EXPECT_EQ(s.name, "abc");
  EXPECT_EQ(s.hidden, (std::vector<int>{64, 64}));
  EXPECT_EQ(s.start, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.knots.size(), 2u);
  EXPECT_EQ(s.mode, Mode::kSlow);
  EXPECT_EQ(s.lockstep.timeout_ms, 50);
  EXPECT_DOUBLE_EQ(s.inner.depth_m, 2.5);
}

TEST(ConfigTable, AbsentKeysKeepTheirValues) {
  Settings s;
  s.batch_size = 7;
  make_table().read(load("test:\n  name: y\n").child("test"), s);
  EXPECT_EQ(s.batch_size, 7);
  EXPECT_EQ(s.name, "y");
}

TEST(ConfigTable, UnknownKeyNamesDottedKeyAndLine) {
  const std::string e = read_error("test:\n  batch_size: 3\n  bacth_size: 4\n");
  EXPECT_NE(e.find("'test.bacth_size': unknown key (line 3"), std::string::npos) << e;
  const std::string nested = read_error("test:\n  inner:\n    depht_m: 1\n");
  EXPECT_NE(nested.find("'test.inner.depht_m'"), std::string::npos) << nested;
  EXPECT_NE(nested.find("line 3"), std::string::npos) << nested;
}

TEST(ConfigTable, WrongTypeNamesFileKeyAndLine) {
  const std::string e = read_error("test:\n  name: a\n  batch_size: many\n");
  EXPECT_NE(e.find("auvrl_test_config_table_WrongType"), std::string::npos) << e;
  EXPECT_NE(e.find("'test.batch_size': expected an integer"), std::string::npos) << e;
  EXPECT_NE(e.find("(line 3)"), std::string::npos) << e;
  EXPECT_NE(read_error("test:\n  mode: medium\n").find("'test.mode': expected fast or slow"),
            std::string::npos);
  EXPECT_NE(read_error("test:\n  start: [1, 2]\n").find("'test.start'"), std::string::npos);
}

TEST(ConfigTable, RangeIsCheckedOnReading) {
  const std::string e = read_error("test:\n  batch_size: 0\n");
  EXPECT_NE(e.find("'test.batch_size': expected >= 1, got 0 (line 2)"), std::string::npos) << e;
  EXPECT_NE(read_error("test:\n  rate: 1.5\n").find("expected 0..1"), std::string::npos);
}

TEST(ConfigTable, FlagsUseTheKeyNames) {
  Settings s;
  cli::CommandLine cmd("prog", "test");
  const auto table = make_table();
  table.add_flags(cmd, s);
  ASSERT_TRUE(
      parse(cmd, {"--batch-size", "16", "--replay-capacity", "99", "--verbose", "--no-filter",
                  "--hidden", "32-16", "--start", "0,0,7", "--mode", "slow", "--timeout-ms", "20",
                  "--inner-depth-m", "3", "--knots", "[[0, 2], [5, 1]]"}));
  EXPECT_EQ(s.batch_size, 16);
  EXPECT_EQ(s.replay_capacity, 99u);
  EXPECT_TRUE(s.verbose);
  EXPECT_FALSE(s.filter);
  EXPECT_EQ(s.hidden, (std::vector<int>{32, 16}));
  EXPECT_EQ(s.start, Eigen::Vector3d(0, 0, 7));
  EXPECT_EQ(s.mode, Mode::kSlow);
  EXPECT_EQ(s.lockstep.timeout_ms, 20);
  EXPECT_DOUBLE_EQ(s.inner.depth_m, 3.0);
  EXPECT_EQ(s.knots, (std::vector<std::vector<double>>{{0, 2}, {5, 1}}));
}

TEST(ConfigTable, BadFlagValuesAreUsageErrors) {
  Settings s;
  cli::CommandLine cmd("prog", "test");
  make_table().add_flags(cmd, s);
  EXPECT_THROW(parse(cmd, {"--batch-size", "0"}), cli::UsageError);
  EXPECT_THROW(parse(cmd, {"--batch-size", "3x"}), cli::UsageError);
  EXPECT_THROW(parse(cmd, {"--mode", "medium"}), cli::UsageError);
  EXPECT_THROW(parse(cmd, {"--batch", "3"}), cli::UsageError);
}

TEST(ConfigTable, HelpListsUnitsAndDefaults) {
  Settings s;
  s.batch_size = 128;  // e.g. from a configuration file: the default the flag shows
  cli::CommandLine cmd("prog", "test");
  make_table().add_flags(cmd, s);
  const std::string help = cmd.usage();
  EXPECT_NE(help.find("--batch-size"), std::string::npos) << help;
  // CLI11's form: --key TYPE=DEFAULT, then the doc with the unit or range.
  EXPECT_NE(help.find("--batch-size INTEGER=128"), std::string::npos) << help;
  EXPECT_NE(help.find("minibatch [transitions, >= 1]"), std::string::npos) << help;
  EXPECT_NE(help.find("--inner-depth-m NUMBER=10"), std::string::npos) << help;
  EXPECT_NE(help.find("a depth [m]"), std::string::npos) << help;
  EXPECT_NE(help.find("=[400, 300]"), std::string::npos) << help;
}

TEST(ConfigTable, DocsHaveEveryKeyWithItsDefault) {
  const auto rows = make_table().docs();
  ASSERT_EQ(rows.size(), 12u);
  EXPECT_EQ(rows[0].key, "batch_size");
  EXPECT_EQ(rows[0].default_text, "64");
  EXPECT_EQ(rows[0].unit, "transitions, >= 1");
  EXPECT_EQ(rows.back().key, "inner.depth_m");
  const std::string md = config::render_markdown({config::section_doc(make_table())}, "# x\n");
  EXPECT_NE(md.find("| `batch_size` | integer | `64` | transitions, >= 1 | minibatch |"),
            std::string::npos)
      << md;
}

// ---- Fixed-size vectors, square matrices, lists of maps, positive(), validate(). ----------

struct Leg {
  std::string name;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
};

struct Body {
  Eigen::Matrix<double, 4, 1> gains = Eigen::Matrix<double, 4, 1>::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  double mass = 1.0;
  double a = 0, b = 0;
  std::vector<Leg> legs;
};

config::Table<Body> make_body_table() {
  config::Table<Leg> leg("legs", "a leg");
  leg.field("name", &Leg::name, "", "label").required();
  leg.field("at", &Leg::at, "m", "where");
  config::Table<Body> t("body", "a body");
  t.field("gains", &Body::gains, "", "four gains");
  t.field("inertia", &Body::inertia, "kg m^2", "inertia");
  t.field("mass", &Body::mass, "kg", "mass").positive();
  t.field("a", &Body::a, "", "a (or b)");
  t.field("b", &Body::b, "", "b (or a)");
  t.validate([](const config::Section& s, Body&) {
    if (s.has("a") && s.has("b")) s.fail("a", "give a or b, not both");
  });
  t.list("legs", leg, &Body::legs, 1, 2).required();
  return t;
}

std::string read_body_error(const std::string& text) {
  Body b;
  try {
    make_body_table().read(load(text).child("body"), b);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigTable, ReadsVectorsMatricesAndListsOfMaps) {
  Body b;
  make_body_table().read(load("body:\n  gains: [1, 2, 3, 4]\n  inertia: [[2, 0.5, 0], [0.5, 3, 0],"
                              " [0, 0, 4]]\n  legs:\n    - name: l\n      at: [1, 0, 0]\n"
                              "    - name: r\n")
                             .child("body"),
                         b);
  EXPECT_EQ(b.gains, Eigen::Vector4d(1, 2, 3, 4));
  EXPECT_EQ(b.inertia(0, 1), 0.5);
  EXPECT_EQ(b.inertia(1, 0), 0.5);
  EXPECT_EQ(b.inertia(2, 2), 4.0);
  ASSERT_EQ(b.legs.size(), 2u);
  EXPECT_EQ(b.legs[0].at, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(b.legs[1].name, "r");
  EXPECT_EQ(b.legs[1].at, Eigen::Vector3d::Zero());
  // A square matrix may be written as its diagonal.
  make_body_table().read(load("body:\n  inertia: [5, 6, 7]\n  legs: [{name: x}]\n").child("body"),
                         b);
  EXPECT_EQ(b.inertia, Eigen::Matrix3d(Eigen::Vector3d(5, 6, 7).asDiagonal()));
}

TEST(ConfigTable, VectorMatrixAndListErrorsNameKeyAndLine) {
  const std::string legs = "  legs: [{name: x}]\n";
  EXPECT_NE(read_body_error("body:\n  gains: [1, 2, 3]\n" + legs)
                .find("'body.gains': expected a list of 4 numbers, got 3 (line 2)"),
            std::string::npos);
  EXPECT_NE(read_body_error("body:\n  inertia: [[1, 0], [0, 1], [0, 0]]\n" + legs)
                .find("'body.inertia': expected 3 rows of 3 numbers"),
            std::string::npos);
  const std::string entry =
      read_body_error("body:\n  legs:\n    - name: x\n    - name: y\n      nam: z\n");
  EXPECT_NE(entry.find("'body.legs[1].nam': unknown key (line 5"), std::string::npos) << entry;
  const std::string missing = read_body_error("body:\n  legs:\n    - at: [0, 0, 1]\n");
  EXPECT_NE(missing.find("'body.legs[0].name': missing (in the block 'body.legs[0]' starting at"
                         " line 3)"),
            std::string::npos)
      << missing;
  EXPECT_NE(read_body_error("body:\n  legs: []\n").find("expected at least 1 entry, got 0"),
            std::string::npos);
  EXPECT_NE(read_body_error("body:\n  legs: [{name: a}, {name: b}, {name: c}]\n")
                .find("'body.legs': expected at most 2 entries, got 3 (line 2)"),
            std::string::npos);
  EXPECT_NE(read_body_error("body:\n  legs: [1, 2]\n").find("'body.legs[0]' must be a map"),
            std::string::npos);
  EXPECT_NE(read_body_error("body:\n  mass: 1\n").find("'body.legs': missing"), std::string::npos);
}

TEST(ConfigTable, PositiveAndValidate) {
  const std::string legs = "  legs: [{name: x}]\n";
  EXPECT_NE(read_body_error("body:\n  mass: 0\n" + legs)
                .find("'body.mass': expected > 0, got 0 (line 2)"),
            std::string::npos);
  EXPECT_EQ(read_body_error("body:\n  a: 1\n" + legs), "");
  EXPECT_NE(read_body_error("body:\n  a: 1\n  b: 2\n" + legs)
                .find("'body.a': give a or b, not both (line 2)"),
            std::string::npos);
}

TEST(ConfigTable, ListEntriesAreDocumentedButGetNoFlags) {
  const auto rows = make_body_table().docs();
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[1].type, "3x3 matrix: 3 rows, or the diagonal alone");
  EXPECT_EQ(rows[1].default_text, "[1, 1, 1]");
  EXPECT_EQ(rows[2].unit, "kg, > 0");
  EXPECT_EQ(rows[5].key, "legs[].name");
  EXPECT_TRUE(rows[5].required);
  EXPECT_EQ(rows[6].default_text, "[0, 0, 0]");
  const std::string md = config::render_markdown({config::section_doc(make_body_table())}, "");
  EXPECT_NE(md.find("| `legs[].name` | string | required |  | label |"), std::string::npos) << md;
  Body b;
  cli::CommandLine cmd("prog", "test");
  make_body_table().add_flags(cmd, b);
  const std::string help = cmd.usage();
  EXPECT_EQ(help.find("--legs"), std::string::npos) << help;
  ASSERT_TRUE(parse(cmd, {"--gains", "1,2,3,4", "--inertia", "[[1, 0, 0], [0, 2, 0], [0, 0, 3]]"}));
  EXPECT_EQ(b.gains, Eigen::Vector4d(1, 2, 3, 4));
  EXPECT_EQ(b.inertia(1, 1), 2.0);
  EXPECT_THROW(parse(cmd, {"--gains", "1,2"}), cli::UsageError);
}

TEST(ConfigTable, FilesThatCannotBeReadAreErrorsNamingThem) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "auvrl_test_config_table_unreadable";
  std::filesystem::create_directories(dir);
  for (const std::string& path : {(dir / "absent.yaml").string(), dir.string()}) {
    try {
      config::load_file(path);
      ADD_FAILURE() << path << " accepted";
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
