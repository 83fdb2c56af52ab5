// The transport's configuration as processes take it: the shared command-line flags, the flags
// a launcher passes on, the `transport:` section of a run configuration and the private
// lockstep bus of a simulator/actor pair. No transport is opened here.
#include <gtest/gtest.h>

#include <fstream>

#include "child_process.hpp"
#include "common/cli.hpp"
#include "common/transport_dds.hpp"
#include "common/transport_options.hpp"

namespace {

using namespace auvrl;
using transport::TransportConfig;
using transport::TransportKind;

bool parse(cli::CommandLine& cmd, std::vector<std::string> args) {
  args.insert(args.begin(), "prog");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  return cmd.parse(static_cast<int>(argv.size()), argv.data());
}

TEST(TransportOptions, FlagsFillTheConfigurationAndAreRecorded) {
  TransportConfig config;
  std::vector<std::string> given;
  cli::CommandLine cmd("prog", "");
  transport::add_transport_options(cmd, config, &given);
  ASSERT_TRUE(parse(cmd, {"--transport", "dds", "--dds-domain", "5", "--dds-peers",
                          "127.0.0.1,10.1.2.3", "--allow-off-host"}));
  EXPECT_EQ(config.kind, TransportKind::kDds);
  EXPECT_EQ(config.dds.domain_id, 5);
  EXPECT_EQ(config.dds.peers, (std::vector<std::string>{"127.0.0.1", "10.1.2.3"}));
  EXPECT_TRUE(config.allow_off_host);
  EXPECT_EQ(given,
            (std::vector<std::string>{"--transport", "dds", "--dds-domain", "5", "--dds-peers",
                                      "127.0.0.1,10.1.2.3", "--allow-off-host"}));
  // Recorded flags applied over another configuration give the same one.
  TransportConfig other;
  transport::apply_transport_arguments(given, other);
  EXPECT_EQ(transport::transport_arguments(other), transport::transport_arguments(config));
}

TEST(TransportOptions, BadValuesNameTheOption) {
  TransportConfig config;
  cli::CommandLine cmd("prog", "");
  transport::add_transport_options(cmd, config);
  try {
    parse(cmd, {"--transport", "zeromq"});
    FAIL() << "accepted --transport zeromq";
  } catch (const cli::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--transport"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse(cmd, {"--dds-peers", "127.0.0.1,,x"}), cli::UsageError);
  EXPECT_THROW(parse(cmd, {"--dds-domain", "3x"}), cli::UsageError);
}

TEST(TransportOptions, ArgumentsReproduceTheConfiguration) {
  TransportConfig lcm;
  EXPECT_EQ(
      transport::transport_arguments(lcm),
      (std::vector<std::string>{"--transport", "lcm", "--lcm-url", transport::kDefaultLcmUrl}));
  TransportConfig dds;
  dds.kind = TransportKind::kDds;
  dds.dds.domain_id = 9;
  EXPECT_EQ(transport::transport_arguments(dds),
            (std::vector<std::string>{"--transport", "dds", "--dds-domain", "9", "--dds-peers",
                                      "127.0.0.1"}));
  dds.dds.config_path = "/etc/cyclone.xml";
  dds.allow_off_host = true;
  EXPECT_EQ(transport::transport_arguments(dds),
            (std::vector<std::string>{"--transport", "dds", "--dds-domain", "9", "--dds-config",
                                      "/etc/cyclone.xml", "--allow-off-host"}));
}

TEST(TransportOptions, SecurityIsPassedOnAndChecked) {
  TransportConfig config;
  std::vector<std::string> given;
  cli::CommandLine cmd("prog", "");
  transport::add_transport_options(cmd, config, &given);
  ASSERT_TRUE(parse(cmd, {"--transport", "dds", "--dds-security", "/pki", "--dds-identity",
                          "actor-1", "--dds-peers", "10.0.0.2"}));
  EXPECT_EQ(config.dds.security_dir, "/pki");
  EXPECT_EQ(config.dds.security_identity, "actor-1");
  EXPECT_EQ(transport::transport_arguments(config),
            (std::vector<std::string>{"--transport", "dds", "--dds-domain", "0", "--dds-peers",
                                      "10.0.0.2", "--dds-security", "/pki", "--dds-identity",
                                      "actor-1"}));
  // Secured, a peer off this host needs no opt-out; a domain past the governance's 230 and a
  // Cyclone file of one's own are refused.
  EXPECT_NO_THROW(transport::check_dds_settings(config.dds, false));
  config.dds.domain_id = 231;
  EXPECT_THROW(transport::check_dds_settings(config.dds, false), transport::TransportError);
  config.dds.domain_id = 0;
  config.dds.config_path = "/etc/hosts";
  EXPECT_THROW(transport::check_dds_settings(config.dds, true), transport::TransportError);
  config.dds.config_path.clear();
  config.dds.security_dir.clear();
  EXPECT_THROW(transport::check_dds_settings(config.dds, false), transport::TransportError);
}

TEST(TransportOptions, LockstepBusIsAPortOrADomainOfItsOwn) {
  TransportConfig lcm;
  EXPECT_FALSE(transport::lockstep_bus_config(lcm, {}).has_value());
  const auto lcm_bus = transport::lockstep_bus_config(lcm, {"udpm://239.255.76.67:7670?ttl=0", -1});
  ASSERT_TRUE(lcm_bus.has_value());
  EXPECT_EQ(lcm_bus->lcm_url, "udpm://239.255.76.67:7670?ttl=0");
  TransportConfig dds;
  dds.kind = TransportKind::kDds;
  dds.dds.peers = {"10.0.0.1", "10.0.0.2"};
  dds.dds.security_dir = "/pki";
  EXPECT_FALSE(transport::lockstep_bus_config(dds, {}).has_value());
  EXPECT_FALSE(transport::lockstep_bus_config(dds, {"", 0}).has_value()) << "the same domain";
  const auto dds_bus = transport::lockstep_bus_config(dds, {"", 3});
  ASSERT_TRUE(dds_bus.has_value());
  EXPECT_EQ(dds_bus->kind, TransportKind::kDds);
  EXPECT_EQ(dds_bus->dds.domain_id, 3);
  // The pair's bus stays on its host, secured as the system's.
  EXPECT_EQ(dds_bus->dds.peers, std::vector<std::string>{"127.0.0.1"});
  EXPECT_TRUE(dds_bus->dds.private_lockstep_bus);
  EXPECT_EQ(dds_bus->dds.security_dir, "/pki");
}

class TransportSection : public ::testing::Test {
 protected:
  TransportConfig read(const std::string& yaml) {
    const std::string path = dir_ + "/run.yaml";
    std::ofstream(path) << yaml;
    config::Section root = config::load_file(path);
    TransportConfig c;
    transport::read_transport_section(root.child("transport"), c);
    config::finish_run_file(root);
    return c;
  }
  std::string dir_ = test_support::make_temp_dir("auvrl_transport_yaml_");
};

TEST_F(TransportSection, AbsentMeansLcm) {
  const TransportConfig c = read("run:\n  actors: 1\n");
  EXPECT_EQ(c.kind, TransportKind::kLcm);
}

TEST_F(TransportSection, DdsWithDomainAndPeers) {
  const TransportConfig c = read(
      "transport:\n  kind: dds\n  dds_domain: 4\n  dds_peers: 127.0.0.1,127.0.0.2\n"
      "run:\n  actors: 1\n");
  EXPECT_EQ(c.kind, TransportKind::kDds);
  EXPECT_EQ(c.dds.domain_id, 4);
  EXPECT_EQ(c.dds.peers, (std::vector<std::string>{"127.0.0.1", "127.0.0.2"}));
}

// Found by fuzz_run_config: a complex key ended the process (uncaught yaml-cpp error).
TEST_F(TransportSection, AComplexKeyIsAnErrorNotACrash) {
  try {
    read("? [a, b]\n: 1\nrun:\n  actors: 1\n");
    FAIL() << "a complex key was accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("expected names as keys"), std::string::npos) << e.what();
  }
}

TEST_F(TransportSection, ErrorsNameTheKey) {
  EXPECT_THROW(read("transport:\n  kind: zmq\n"), config::ConfigError);
  EXPECT_THROW(read("transport:\n  knid: dds\n"), config::ConfigError);
  EXPECT_THROW(read("transport:\n  kind: dds\n  dds_domain: 300\n"), config::ConfigError);
  try {
    read("transport:\n  kind: dds\n  dds_peers: 10.0.0.2\n");
    FAIL() << "an off-host peer was accepted without allow_off_host";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("allow-off-host"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dds_peers"), std::string::npos) << e.what();
  }
  try {
    read("transport:\n  lcm_url: udpm://239.255.76.67:7667?ttl=1\n");
    FAIL() << "an LCM URL with ttl=1 was accepted without allow_off_host";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("lcm_url"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(read("transport:\n  kind: dds\n  dds_peers: 10.0.0.2\n  allow_off_host: true\n"));
}

}  // namespace
