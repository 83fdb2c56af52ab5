// LCM and DDS have no authentication: anyone who reaches the multicast group or a DDS peer can
// inject commands or weights. Every process that opens a transport (auv_sim, auv_actor,
// auv_learner, auv_logger, auv_bridge, auvrl train) must refuse, before it sends anything, a
// configuration whose traffic could leave this host: an LCM URL with ttl > 0, a tcpq hub on
// another host, a DDS peer off this host, a Cyclone XML file, and (simulator and actor) such a
// lockstep bus; auvrl train also from its configuration file's transport section. Each
// refusal exits non-zero and names --allow-off-host. Runs inside a private network namespace,
// so even a process that wrongly accepted could not reach the network.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "child_process.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;

const std::string kPreset = std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml";

/// The widening flag sets every process is checked with.
std::vector<std::vector<std::string>> widening_flags(const std::string& tmp) {
  const std::string xml = tmp + "/cyclone.xml";
  std::ofstream(xml) << "<CycloneDDS><Domain id=\"any\"/></CycloneDDS>\n";
  return {
      {"--lcm-url", "udpm://239.255.76.67:7667?ttl=1"},
      {"--lcm-url", "udpm://239.255.76.67:7667?ttl=255"},
      {"--lcm-url", "tcpq://10.11.12.13:7700"},
      {"--transport", "dds", "--dds-peers", "127.0.0.1,10.11.12.13"},
      {"--transport", "dds", "--dds-config", xml},
  };
}

/// Runs argv + flags; expects a refusal naming --allow-off-host.
void expect_refused(std::vector<std::string> argv, const std::vector<std::string>& flags,
                    const std::string& log_path) {
  std::string shown;
  for (const auto& a : flags) shown += " " + a;
  argv.insert(argv.end(), flags.begin(), flags.end());
  ChildProcess p(argv, log_path);
  const int status = p.wait_for_exit(std::chrono::seconds(30));
  ASSERT_NE(status, -1) << argv[0] << shown << ": still running, it accepted: " << p.log();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << argv[0] << shown << p.log();
  EXPECT_NE(p.log().find("allow-off-host"), std::string::npos) << argv[0] << shown << p.log();
}

TEST(OffHostRefusal, EveryProcessRefusesAWideningTransportWithoutTheExplicitOption) {
  const std::string tmp = test_support::make_temp_dir("auvrl_off_host_");
  const std::vector<std::vector<std::string>> processes = {
      {test_support::bin_path("auv_sim")},
      {test_support::bin_path("auv_actor"), "--config", kPreset},
      {test_support::bin_path("auv_learner"), "--config", kPreset},
      {test_support::bin_path("auv_logger"), "--dir", tmp + "/logs"},
      {test_support::bin_path("auv_bridge"), "--from", "dds", "--to", "lcm"},
  };
  int n = 0;
  for (const auto& process : processes) {
    for (const auto& flags : widening_flags(tmp)) {
      expect_refused(process, flags, tmp + "/p" + std::to_string(n++) + ".log");
    }
  }
  for (const auto& flags : widening_flags(tmp)) {
    std::vector<std::string> train = {test_support::bin_path("auvrl"),
                                      "train",
                                      "--config",
                                      kPreset,
                                      "--run-dir",
                                      tmp + "/run" + std::to_string(n),
                                      "--network",
                                      "host",
                                      "--no-eval",
                                      "--max-seconds",
                                      "5"};
    expect_refused(train, flags, tmp + "/p" + std::to_string(n++) + ".log");
  }
}

TEST(OffHostRefusal, LockstepBusesAreCheckedToo) {
  const std::string tmp = test_support::make_temp_dir("auvrl_off_host_lockstep_");
  const std::vector<std::string> bus = {"--lockstep-lcm-url", "udpm://239.255.76.67:7668?ttl=1"};
  expect_refused({test_support::bin_path("auv_sim")}, bus, tmp + "/sim.log");
  expect_refused({test_support::bin_path("auv_actor"), "--config", kPreset}, bus,
                 tmp + "/actor.log");
}

TEST(OffHostRefusal, RunConfigurationTransportSectionIsChecked) {
  const std::string tmp = test_support::make_temp_dir("auvrl_off_host_config_");
  for (const std::string section : {"transport:\n  lcm_url: udpm://239.255.76.67:7667?ttl=1\n",
                                    "transport:\n  kind: dds\n  dds_peers: 10.11.12.13\n"}) {
    const std::string config = tmp + "/widening.yaml";
    {
      std::ifstream in(kPreset);
      std::ofstream out(config);
      std::string line;
      while (std::getline(in, line)) {
        if (line.rfind("vehicle:", 0) == 0) {
          line = "vehicle: " + std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
        }
        out << line << "\n";
      }
      out << section;
    }
    static int n = 0;
    expect_refused({test_support::bin_path("auvrl"), "train", "--config", config, "--run-dir",
                    tmp + "/run" + std::to_string(n), "--network", "host", "--no-eval"},
                   {}, tmp + "/train" + std::to_string(n) + ".log");
    ++n;
  }
}

}  // namespace
