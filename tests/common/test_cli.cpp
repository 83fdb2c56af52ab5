#include <gtest/gtest.h>

#include "common/channels.hpp"
#include "common/cli.hpp"

namespace {

using auvrl::cli::CommandLine;
using auvrl::cli::UsageError;

struct Parsed {
  std::string name = "default";
  int count = 3;
  double gain = 0.5;
  bool verbose = false;
};

CommandLine make(Parsed& p) {
  CommandLine cmd("prog", "a test program");
  cmd.option("name", &p.name, "a name");
  cmd.option("count", &p.count, "a count");
  cmd.option("gain", &p.gain, "a gain");
  cmd.flag("verbose", &p.verbose, "talk");
  return cmd;
}

bool parse(CommandLine& cmd, std::vector<const char*> args) {
  args.insert(args.begin(), "prog");
  return cmd.parse(static_cast<int>(args.size()), args.data());
}

TEST(CommandLine, KeepsDefaultsAndParsesValues) {
  Parsed p;
  auto cmd = make(p);
  ASSERT_TRUE(parse(cmd, {}));
  EXPECT_EQ(p.name, "default");
  EXPECT_EQ(p.count, 3);
  ASSERT_TRUE(parse(cmd, {"--name", "x", "--count=7", "--gain", "1.25", "--verbose"}));
  EXPECT_EQ(p.name, "x");
  EXPECT_EQ(p.count, 7);
  EXPECT_DOUBLE_EQ(p.gain, 1.25);
  EXPECT_TRUE(p.verbose);
}

TEST(CommandLine, ErrorsNameTheOption) {
  Parsed p;
  auto cmd = make(p);
  try {
    parse(cmd, {"--count", "seven"});
    FAIL() << "accepted a non-integer";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--count"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse(cmd, {"--nope"}), UsageError);
  EXPECT_THROW(parse(cmd, {"--gain", "nan"}), UsageError);
  EXPECT_THROW(parse(cmd, {"--gain"}), UsageError);
  EXPECT_THROW(parse(cmd, {"--verbose=1"}), UsageError);
  EXPECT_THROW(parse(cmd, {"stray"}), UsageError);
  EXPECT_THROW(parse(cmd, {"--count", "99999999999"}), UsageError);
}

TEST(CommandLine, HelpListsOptionsWithDefaults) {
  Parsed p;
  auto cmd = make(p);
  const std::string usage = cmd.usage();
  EXPECT_NE(usage.find("--count VALUE"), std::string::npos);
  EXPECT_NE(usage.find("(default: 3)"), std::string::npos);
}

TEST(Channels, VehicleIdRoundTrip) {
  using namespace auvrl::channels;
  EXPECT_EQ(vehicle_id_of(sim_command(0)), 0);
  EXPECT_EQ(vehicle_id_of(sim_state(17)), 17);
  EXPECT_EQ(vehicle_id_of("SIM_CMD_"), -1);
  EXPECT_EQ(vehicle_id_of("SIM_CMD_1x"), -1);
  EXPECT_EQ(vehicle_id_of("SIM_CMD_99999999999999"), -1);
}

}  // namespace
