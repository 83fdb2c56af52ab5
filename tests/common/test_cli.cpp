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

TEST(CommandLine, ErrorsSayWhatWasExpected) {
  Parsed p;
  auto cmd = make(p);
  const auto message = [&cmd](std::vector<const char*> args) {
    try {
      parse(cmd, std::move(args));
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({"--count", "seven"}), "option --count: expected an integer, got 'seven'");
  EXPECT_EQ(message({"--gain", "inf"}), "option --gain: expected a finite number, got 'inf'");
  EXPECT_EQ(message({"--nope", "1"}), "unknown option --nope (see prog --help)");
  EXPECT_EQ(message({"stray"}), "unexpected argument 'stray'");
  EXPECT_NE(message({"--gain"}).find("--gain"), std::string::npos);
}

TEST(CommandLine, LastValueWinsAndNegativeNumbersAreValues) {
  Parsed p;
  auto cmd = make(p);
  ASSERT_TRUE(parse(cmd, {"--count", "1", "--count", "-2", "--gain", "-0.5"}));
  EXPECT_EQ(p.count, -2);
  EXPECT_DOUBLE_EQ(p.gain, -0.5);
}

TEST(CommandLine, CustomOptionsRunInOrderAndNameTheOption) {
  CommandLine cmd("prog", "");
  std::vector<std::string> seen;
  cmd.custom_option(
      "mode",
      [&seen](const std::string& v) {
        if (v == "bad") throw std::invalid_argument("not a mode");
        seen.push_back("mode=" + v);
      },
      "auto", "a mode");
  cmd.custom_flag(
      "fast", [&seen] { seen.push_back("fast"); }, "go fast");
  ASSERT_TRUE(parse(cmd, {"--fast", "--mode", "a", "--mode=b"}));
  EXPECT_EQ(seen, (std::vector<std::string>{"fast", "mode=a", "mode=b"}));
  try {
    parse(cmd, {"--mode", "bad"});
    FAIL() << "accepted a bad mode";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "option --mode: not a mode");
  }
  EXPECT_NE(cmd.usage().find("auto"), std::string::npos) << cmd.usage();
}

TEST(CommandLine, PositionalAndRepeatable) {
  CommandLine cmd("prog", "");
  std::vector<std::string> logs, where;
  std::string out;
  cmd.option("out", &out, "output");
  cmd.repeatable("where", &where, "FIELD=VALUE");
  cmd.positionals("LOG", &logs, "log files");
  ASSERT_TRUE(parse(cmd, {"a.log", "--where", "x=1", "--out", "o.csv", "b.log", "--where=y=2"}));
  EXPECT_EQ(logs, (std::vector<std::string>{"a.log", "b.log"}));
  EXPECT_EQ(where, (std::vector<std::string>{"x=1", "y=2"}));
  EXPECT_EQ(out, "o.csv");
  EXPECT_THROW(parse(cmd, {"--out", "o.csv"}), UsageError);  // LOG is required
}

TEST(CommandLine, Subcommands) {
  CommandLine cmd("tool", "a tool");
  std::string types = "types", channel;
  std::vector<std::string> logs;
  cmd.option("types-dir", &types, "types");
  CommandLine& list = cmd.subcommand("list", "lists");
  list.positionals("LOG", &logs, "logs");
  CommandLine& filter = cmd.subcommand("filter", "filters");
  filter.option("channel", &channel, "channel");
  filter.positionals("LOG", &logs, "logs");
  cmd.require_subcommand();
  EXPECT_NE(cmd.usage().find("filters"), std::string::npos) << cmd.usage();
  ASSERT_TRUE(parse(cmd, {"--types-dir", "t", "filter", "x.log", "--channel", "C"}));
  EXPECT_EQ(cmd.chosen(), "filter");
  EXPECT_EQ(types, "t");
  EXPECT_EQ(channel, "C");
  EXPECT_EQ(logs, (std::vector<std::string>{"x.log"}));
  EXPECT_THROW(parse(cmd, {}), UsageError);
  EXPECT_THROW(parse(cmd, {"list", "--channel", "C", "x.log"}), UsageError);
  EXPECT_NE(filter.usage().find("tool filter"), std::string::npos) << filter.usage();
}

TEST(CommandLine, SubcommandsThatParseTheirOwnOptions) {
  CommandLine cmd("front", "");
  cmd.subcommand("train", "trains").pass_on_rest();
  cmd.subcommand("eval", "evaluates").pass_on_rest();
  cmd.require_subcommand();
  ASSERT_TRUE(parse(cmd, {"eval", "--seed", "3", "--out=d", "--help", "x"}));
  ASSERT_EQ(cmd.chosen(), "eval");
  const CommandLine::Rest rest = cmd.subcommand("eval").rest();
  ASSERT_EQ(rest.argc(), 6);
  EXPECT_EQ(std::vector<std::string>(rest.argv(), rest.argv() + rest.argc()),
            (std::vector<std::string>{"front eval", "--seed", "3", "--out=d", "--help", "x"}));
  EXPECT_THROW(parse(cmd, {"nope"}), UsageError);
}

TEST(CommandLine, HelpListsOptionsWithDefaults) {
  Parsed p;
  auto cmd = make(p);
  const std::string usage = cmd.usage();
  EXPECT_NE(usage.find("--count INT=3"), std::string::npos) << usage;
  EXPECT_NE(usage.find("--name TEXT=default"), std::string::npos) << usage;
  EXPECT_NE(usage.find("a test program"), std::string::npos) << usage;
}

TEST(CommandLine, FindValueBeforeParsing) {
  const std::vector<const char*> args = {"prog", "--seed", "3", "--config=c.yaml", "--x"};
  const int argc = static_cast<int>(args.size());
  EXPECT_EQ(CommandLine::find_value(argc, args.data(), "config"), "c.yaml");
  EXPECT_EQ(CommandLine::find_value(argc, args.data(), "seed"), "3");
  EXPECT_EQ(CommandLine::find_value(argc, args.data(), "other"), "");
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
