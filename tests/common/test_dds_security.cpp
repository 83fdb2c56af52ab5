// DDS Security: the roles' grants, the documents, the checks of a participant's files, and a
// secured transport across two processes (tests/common/dds_peer.cpp), inside the test's private
// network namespace. The PKIs come from scripts/pki.sh, as users make them.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/dds_security.hpp"
#include "common/transport.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// The roles that may publish on a topic.
std::vector<std::string> publishers_of(const std::string& topic) {
  std::vector<std::string> roles;
  for (const transport::DdsRole& r : transport::dds_roles()) {
    for (int t : r.publish) {
      if (channels::kDdsTopics[t].name == topic) roles.push_back(r.name);
    }
  }
  return roles;
}

TEST(DdsSecurityRoles, OnlyTheirOwnPublish) {
  using V = std::vector<std::string>;
  EXPECT_EQ(publishers_of("auvrl_weights"), V{"learner"});
  EXPECT_EQ(publishers_of("auvrl_experience"), V{"actor"});
  EXPECT_EQ(publishers_of("auvrl_sim_command"), (V{"actor", "controller"}));
  EXPECT_EQ(publishers_of("auvrl_sim_state"), V{"simulator"});
  EXPECT_EQ(publishers_of("auvrl_other"), V{});
  EXPECT_EQ(std::string(transport::dds_role("observer").name), "observer");
  EXPECT_TRUE(transport::dds_role("observer").publish.empty());
  try {
    transport::dds_role("admin");
    FAIL() << "an unknown role was accepted";
  } catch (const transport::TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("learner, actor"), std::string::npos) << e.what();
  }
}

TEST(DdsSecurityDocuments, GovernanceClosesTheDomainAndPermissionsGrantPerSubject) {
  const std::string governance = transport::dds_governance_xml(3);
  EXPECT_NE(governance.find("<allow_unauthenticated_participants>false<"), std::string::npos);
  EXPECT_NE(governance.find("<data_protection_kind>ENCRYPT<"), std::string::npos);
  EXPECT_NE(governance.find("<max>230</max>"), std::string::npos);
  // The system's domain first, everything encrypted; then the lockstep buses, whose simulator
  // topics are not.
  const auto system_rule = governance.find("<domains><id>3</id></domains>");
  const auto sim_rule = governance.find("<topic_expression>auvrl_sim_*</topic_expression>");
  ASSERT_NE(system_rule, std::string::npos);
  ASSERT_NE(sim_rule, std::string::npos);
  EXPECT_LT(system_rule, sim_rule);
  EXPECT_EQ(governance.find("<data_protection_kind>NONE<"),
            governance.find("<data_protection_kind>", sim_rule));
  EXPECT_THROW(transport::dds_governance_xml(231), transport::TransportError);
  const std::string permissions = transport::dds_permissions_xml(
      transport::dds_role("learner"), {"CN=learner,O=x", "CN=learner-2,O=x"}, "2026-01-01T00:00:00",
      "2027-01-01T00:00:00");
  EXPECT_NE(permissions.find("<subject_name>CN=learner-2,O=x</subject_name>"), std::string::npos);
  EXPECT_NE(permissions.find("<publish><topics><topic>auvrl_weights</topic>"), std::string::npos);
  EXPECT_EQ(std::count(permissions.begin(), permissions.end(), '\n') > 0, true);
  std::size_t grants = 0;
  for (std::size_t at = permissions.find("<grant "); at != std::string::npos;
       at = permissions.find("<grant ", at + 1)) {
    ++grants;
  }
  EXPECT_EQ(grants, 2u);
  EXPECT_THROW(transport::dds_permissions_xml(transport::dds_role("actor"), {"CN=<x>"}, "a", "b"),
               transport::TransportError);
}

/// Runs scripts/pki.sh into dir (once per test binary and dir).
std::string make_pki(const std::string& dir, const std::string& extra = "") {
  const std::string command =
      "AUVRL_BIN_DIR=" + fs::path(test_support::bin_path("auvrl")).parent_path().string() +
      " " AUVRL_SOURCE_DIR "/scripts/pki.sh --out " + dir + " --actors 1 --controllers 0 " + extra +
      " >/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return dir;
}

/// Two PKIs of two authorities, made once.
struct Pkis {
  std::string run, other;
};
const Pkis& pkis() {
  static const Pkis p = [] {
    const std::string base = test_support::make_temp_dir("auvrl_pki_");
    return Pkis{make_pki(base + "/run", "--participant simulator:wrong-role"),
                make_pki(base + "/other")};
  }();
  return p;
}

/// The message of the TransportError that checking participant `name` of pki throws ("" if none).
std::string check_error(const std::string& pki, const std::string& name) {
  try {
    transport::check_dds_security_files(transport::resolve_dds_security(pki, name));
    return "";
  } catch (const transport::TransportError& e) {
    return e.what();
  }
}

/// A copy of participant `name`'s directory, to alter.
std::string copy_participant(const std::string& pki, const std::string& name) {
  const std::string dir = test_support::make_temp_dir("auvrl_pki_copy_") + "/" + name;
  fs::copy(pki + "/" + name, dir);
  return dir;
}

TEST(DdsSecurityFiles, ResolveNamesWhatIsMissing) {
  const std::string pki = pkis().run;
  EXPECT_EQ(transport::resolve_dds_security(pki, "learner").certificate,
            fs::absolute(pki + "/learner/cert.pem").lexically_normal().string());
  EXPECT_EQ(transport::resolve_dds_security(pki + "/learner", "").dir, pki + "/learner");
  const auto message = [](const std::string& dir, const std::string& name) {
    try {
      transport::resolve_dds_security(dir, name);
      return std::string();
    } catch (const transport::TransportError& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(message(pki, "").find("--dds-identity"), std::string::npos);
  EXPECT_NE(message(pki, "actor-7").find("actor-7/cert.pem is missing"), std::string::npos);
  EXPECT_NE(message(pki + "/nowhere", "").find("is not a directory"), std::string::npos);
  const std::string dir = copy_participant(pki, "actor-0");
  fs::remove(dir + "/permissions.p7s");
  EXPECT_NE(message(dir, "").find("permissions.p7s is missing"), std::string::npos);
}

TEST(DdsSecurityFiles, TamperedAndForeignFilesAreRefusedByName) {
  const Pkis& p = pkis();
  EXPECT_EQ(check_error(p.run, "learner"), "");
  EXPECT_EQ(check_error(p.other, "actor-0"), "");
  // A permissions document granting more than the authority signed.
  std::string dir = copy_participant(p.run, "learner");
  std::stringstream text;
  text << std::ifstream(dir + "/permissions.p7s").rdbuf();
  std::string doc = text.str();
  const std::string grant = "<topic>auvrl_weights</topic>";
  doc.replace(doc.find(grant), grant.size(), grant + "<topic>auvrl_experience</topic>");
  std::ofstream(dir + "/permissions.p7s") << doc;
  std::string error = check_error(dir, "");
  EXPECT_NE(error.find(dir + "/permissions.p7s does not verify"), std::string::npos) << error;
  // The governance of another authority.
  dir = copy_participant(p.run, "learner");
  fs::copy_file(p.other + "/governance.p7s", dir + "/governance.p7s",
                fs::copy_options::overwrite_existing);
  error = check_error(dir, "");
  EXPECT_NE(error.find("governance.p7s does not verify"), std::string::npos) << error;
  // A certificate of another authority, and a key that is not the certificate's.
  dir = copy_participant(p.run, "actor-0");
  fs::copy_file(p.other + "/actor-0/cert.pem", dir + "/cert.pem",
                fs::copy_options::overwrite_existing);
  error = check_error(dir, "");
  EXPECT_NE(error.find("cert.pem is refused by the identity CA"), std::string::npos) << error;
  dir = copy_participant(p.run, "actor-0");
  fs::copy_file(p.run + "/learner/key.pem", dir + "/key.pem", fs::copy_options::overwrite_existing);
  error = check_error(dir, "");
  EXPECT_NE(error.find("is not the key of the certificate"), std::string::npos) << error;
}

transport::TransportConfig secured(const std::string& pki, const std::string& name) {
  transport::TransportConfig config;
  config.kind = transport::TransportKind::kDds;
  config.dds.security_dir = pki;
  config.dds.security_identity = name;
  return config;
}

TEST(DdsSecurityTransport, TheSystemBusMustBeTheGovernancesDomain) {
  EXPECT_EQ(transport::dds_governance_system_domain(pkis().run + "/governance.p7s"), 0);
  transport::TransportConfig config = secured(pkis().run, "learner");
  config.dds.domain_id = 4;
  try {
    transport::make_transport(config);
    FAIL() << "a system bus outside the governance's domain was opened";
  } catch (const transport::TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("scripts/pki.sh --domain 4"), std::string::npos)
        << e.what();
  }
  config.dds.private_lockstep_bus = true;  // a lockstep pair's bus may be any other domain
  EXPECT_NO_THROW(transport::make_transport(config));
}

TEST(DdsSecurityTransport, ARoleCannotPublishOrReadWhatItIsNotGranted) {
  auto t = transport::make_transport(secured(pkis().run, "wrong-role"));  // a simulator
  const std::uint8_t byte = 1;
  try {
    t->publish(channels::kPolicyWeights, &byte, 1);
    FAIL() << "a simulator published weights";
  } catch (const transport::TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("topic auvrl_weights"), std::string::npos) << e.what();
  }
  EXPECT_THROW(t->subscribe(channels::kExperience, [](const transport::RawMessage&) {}),
               transport::TransportError);
  t->publish(channels::sim_state(0), &byte, 1);
  t->subscribe(channels::kSimCommandPattern, [](const transport::RawMessage&) {});
  // A regex over topics it may and may not read reads those it may.
  t->subscribe("SIM_.*", [](const transport::RawMessage&) {});
}

/// Runs `dds_peer [--dds-security DIR] latest POLICY_WEIGHTS 3000` while this process serves
/// its weights; returns the peer's line.
std::string latest_weights_at_peer(transport::Transport& t, const std::string& security_dir) {
  std::vector<std::string> argv = {test_support::bin_path("dds_peer")};
  if (!security_dir.empty()) argv.insert(argv.end(), {"--dds-security", security_dir});
  argv.insert(argv.end(), {"latest", channels::kPolicyWeights, "3000"});
  const std::string dir = test_support::make_temp_dir("auvrl_dds_sec_peer_");
  test_support::ChildProcess peer(argv, dir + "/peer.log");
  int status = -1;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (status == -1 && Clock::now() < deadline) {
    t.handle(20);
    status = peer.wait_for_exit(std::chrono::milliseconds(0));
  }
  return peer.log();
}

TEST(DdsSecurityTransport, WeightsReachTheRunsActorAndNoOtherParticipant) {
  const Pkis& p = pkis();
  auto learner = transport::make_transport(secured(p.run, "learner"));
  std::vector<std::uint8_t> weights(4096, 0x5a);
  for (std::int64_t v = 1; v <= 3; ++v) {
    std::copy(reinterpret_cast<const std::uint8_t*>(&v),
              reinterpret_cast<const std::uint8_t*>(&v) + sizeof v, weights.begin());
    learner->publish(channels::kPolicyWeights, weights.data(), weights.size());
  }
  const std::string actor = latest_weights_at_peer(*learner, p.run + "/actor-0");
  EXPECT_NE(actor.find("count=1 size=4096 version=3"), std::string::npos) << actor;
  const std::string foreign = latest_weights_at_peer(*learner, p.other + "/actor-0");
  EXPECT_NE(foreign.find("count=0"), std::string::npos) << foreign;
  const std::string plain = latest_weights_at_peer(*learner, "");
  EXPECT_NE(plain.find("count=0"), std::string::npos) << plain;
}

}  // namespace
