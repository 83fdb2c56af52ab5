#include "common/dds_security.hpp"

#include <fmt/format.h>
#include <openssl/bio.h>
#include <openssl/cms.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include "common/channels.hpp"
#include "common/openssl_error.hpp"
#include "common/transport.hpp"

namespace auvrl::transport {

namespace {

namespace fs = std::filesystem;

/// Every topic of the system (the roles that read everything).
std::vector<int> all_topics() {
  std::vector<int> all;
  for (int t = 0; t < channels::kDdsTopicCount; ++t) all.push_back(t);
  return all;
}

/// The topics by name, so that the role table reads as what it grants.
int topic(const char* name) {
  for (int t = 0; t < channels::kDdsTopicCount; ++t) {
    if (std::string(channels::kDdsTopics[t].name) == name) return t;
  }
  throw TransportError(std::string("no DDS topic ") + name);
}

std::vector<DdsRole> make_roles() {
  const int weights = topic("auvrl_weights"), experience = topic("auvrl_experience"),
            request = topic("auvrl_weights_request"), command = topic("auvrl_sim_command"),
            reset = topic("auvrl_sim_reset"), state = topic("auvrl_sim_state"),
            event = topic("auvrl_sim_event"), stats = topic("auvrl_learner_stats"),
            heartbeat = topic("auvrl_heartbeat"), mission = topic("auvrl_mission"),
            status = topic("auvrl_mission_status");
  return {
      {"learner", "auv_learner: publishes the weights", {weights, stats}, {experience, request}},
      {"actor",
       "auv_actor: publishes experience and episode reports, drives its simulator",
       {experience, request, command, reset},
       {weights, state}},
      {"simulator",
       "auv_sim: publishes vehicle states",
       {state, heartbeat},
       {command, reset, event}},
      {"controller",
       "auv_controller: publishes thruster commands on a vehicle",
       {command, status},
       {state, event, mission}},
      {"logger", "auv_logger: reads everything", {heartbeat}, all_topics()},
      {"operator",
       "auvrl run, a person: missions, resets, faults and currents; reads everything",
       {reset, event, mission},
       all_topics()},
      {"observer",
       "the launcher, probes, monitors: reads everything, publishes nothing",
       {},
       all_topics()},
  };
}

/// Every domain a secured system may use, as governance and permissions write it.
std::string all_domains() {
  return fmt::format("<id_range><min>0</min><max>{}</max></id_range>", kSecuredMaxDomainId);
}

std::string topic_list(const std::vector<int>& topics) {
  std::string xml;
  for (int t : topics) xml += fmt::format("<topic>{}</topic>", channels::kDdsTopics[t].name);
  return xml;
}

using Bio = std::unique_ptr<BIO, decltype(&BIO_free)>;
using Cert = std::unique_ptr<X509, decltype(&X509_free)>;
using Store = std::unique_ptr<X509_STORE, decltype(&X509_STORE_free)>;

Bio open_bio(const std::string& path) {
  Bio bio(BIO_new_file(path.c_str(), "r"), BIO_free);
  if (!bio) throw TransportError("DDS Security: cannot read " + path);
  return bio;
}

Cert read_cert(const std::string& path) {
  Bio bio = open_bio(path);
  Cert cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr), X509_free);
  if (!cert) throw TransportError("DDS Security: " + path + " is not a PEM certificate");
  return cert;
}

/// A store that trusts the certificate in ca_path alone.
Store store_of(const std::string& ca_path) {
  Cert ca = read_cert(ca_path);
  Store store(X509_STORE_new(), X509_STORE_free);
  if (!store || X509_STORE_add_cert(store.get(), ca.get()) != 1) {
    throw TransportError("DDS Security: cannot use " + ca_path + openssl_error());
  }
  return store;
}

void check_certificate(const DdsSecurityFiles& f) {
  Cert cert = read_cert(f.certificate);
  Store store = store_of(f.identity_ca);
  std::unique_ptr<X509_STORE_CTX, decltype(&X509_STORE_CTX_free)> ctx(X509_STORE_CTX_new(),
                                                                      X509_STORE_CTX_free);
  if (!ctx || X509_STORE_CTX_init(ctx.get(), store.get(), cert.get(), nullptr) != 1) {
    throw TransportError("DDS Security: cannot check " + f.certificate + openssl_error());
  }
  if (X509_verify_cert(ctx.get()) != 1) {
    throw TransportError("DDS Security: the certificate " + f.certificate +
                         " is refused by the identity CA " + f.identity_ca + ": " +
                         X509_verify_cert_error_string(X509_STORE_CTX_get_error(ctx.get())));
  }
  Bio key_bio = open_bio(f.private_key);
  std::unique_ptr<EVP_PKEY, decltype(&EVP_PKEY_free)> key(
      PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, nullptr), EVP_PKEY_free);
  if (!key) throw TransportError("DDS Security: " + f.private_key + " is not a PEM private key");
  if (X509_check_private_key(cert.get(), key.get()) != 1) {
    ERR_clear_error();
    throw TransportError("DDS Security: the key " + f.private_key +
                         " is not the key of the certificate " + f.certificate);
  }
}

/// Checks the S/MIME signature of a governance or permissions document against the
/// permissions CA.
void check_signed_document(const std::string& path, const std::string& ca_path) {
  Bio bio = open_bio(path);
  BIO* content_raw = nullptr;
  std::unique_ptr<CMS_ContentInfo, decltype(&CMS_ContentInfo_free)> cms(
      SMIME_read_CMS(bio.get(), &content_raw), CMS_ContentInfo_free);
  Bio content(content_raw, BIO_free);
  if (!cms) {
    throw TransportError("DDS Security: " + path + " is not an S/MIME signed document" +
                         openssl_error());
  }
  Store store = store_of(ca_path);
  Bio out(BIO_new(BIO_s_mem()), BIO_free);
  if (CMS_verify(cms.get(), nullptr, store.get(), content.get(), out.get(), CMS_TEXT) != 1) {
    throw TransportError(
        "DDS Security: the signature of " + path + " does not verify against the permissions CA " +
        ca_path + " (the document was altered, or signed by another authority)" + openssl_error());
  }
}

}  // namespace

const std::vector<DdsRole>& dds_roles() {
  static const std::vector<DdsRole> roles = make_roles();
  return roles;
}

const DdsRole& dds_role(const std::string& name) {
  std::string names;
  for (const DdsRole& r : dds_roles()) {
    if (name == r.name) return r;
    names += (names.empty() ? "" : ", ") + std::string(r.name);
  }
  throw TransportError("unknown DDS Security role '" + name + "' (expected one of " + names + ")");
}

namespace {

/// A governance topic rule: access control on, the given protection of submessages and data.
std::string topic_rule(const char* expression, const char* protection) {
  return fmt::format(
      "        <topic_rule>\n"
      "          <topic_expression>{}</topic_expression>\n"
      "          <enable_discovery_protection>true</enable_discovery_protection>\n"
      "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
      "          <enable_read_access_control>true</enable_read_access_control>\n"
      "          <enable_write_access_control>true</enable_write_access_control>\n"
      "          <metadata_protection_kind>{}</metadata_protection_kind>\n"
      "          <data_protection_kind>{}</data_protection_kind>\n"
      "        </topic_rule>\n",
      expression, protection, protection);
}

/// A governance domain rule: closed to the unauthenticated, join access control, discovery
/// and liveliness encrypted, then the topic rules (the first that matches a topic applies).
std::string domain_rule(const std::string& domains, const std::string& topic_rules) {
  return fmt::format(
      "    <domain_rule>\n"
      "      <domains>{}</domains>\n"
      "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
      "      <enable_join_access_control>true</enable_join_access_control>\n"
      "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
      "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
      "      <rtps_protection_kind>NONE</rtps_protection_kind>\n"
      "      <topic_access_rules>\n{}      </topic_access_rules>\n"
      "    </domain_rule>\n",
      domains, topic_rules);
}

}  // namespace

std::string dds_governance_xml(int system_domain) {
  if (system_domain < 0 || system_domain > kSecuredMaxDomainId) {
    throw TransportError(fmt::format("DDS Security: the system's domain {} is out of range (0..{})",
                                     system_domain, kSecuredMaxDomainId));
  }
  // The system's bus (the domain that crosses hosts): everything encrypted. Any other domain
  // is a lockstep pair's private bus, loopback only (lockstep_bus_config): its simulator
  // topics are authenticated and access-controlled but not encrypted, since per-message
  // cryptography there halves the steps a pair makes and the bus never leaves its host.
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
)" + domain_rule(fmt::format("<id>{}</id>", system_domain), topic_rule("*", "ENCRYPT")) +
         domain_rule(all_domains(),
                     topic_rule("auvrl_sim_*", "NONE") + topic_rule("*", "ENCRYPT")) +
         "  </domain_access_rules>\n</dds>\n";
}

std::string dds_permissions_xml(const DdsRole& role, const std::vector<std::string>& subjects,
                                const std::string& not_before, const std::string& not_after) {
  std::string xml = R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
)";
  int n = 0;
  for (const std::string& subject : subjects) {
    if (subject.find_first_of("<>&\"'") != std::string::npos) {
      throw TransportError("DDS Security: the subject '" + subject + "' has XML characters");
    }
    std::string rule = "<domains>" + all_domains() + "</domains>";
    if (!role.publish.empty())
      rule += "<publish><topics>" + topic_list(role.publish) + "</topics></publish>";
    if (!role.subscribe.empty()) {
      rule += "<subscribe><topics>" + topic_list(role.subscribe) + "</topics></subscribe>";
    }
    xml += fmt::format(
        "    <grant name=\"{}_{}\">\n      <subject_name>{}</subject_name>\n"
        "      <validity><not_before>{}</not_before><not_after>{}</not_after></validity>\n"
        "      <allow_rule>{}</allow_rule>\n      <default>DENY</default>\n    </grant>\n",
        role.name, n++, subject, not_before, not_after, rule);
  }
  return xml + "  </permissions>\n</dds>\n";
}

DdsSecurityFiles resolve_dds_security(const std::string& dir, const std::string& identity) {
  if (!fs::is_directory(dir)) {
    throw TransportError("DDS Security: '" + dir + "' is not a directory (expected one made by " +
                         "scripts/pki.sh, or a participant's directory in it)");
  }
  fs::path base = dir;
  if (!fs::exists(base / "cert.pem")) {
    if (identity.empty() || !fs::exists(base / identity / "cert.pem")) {
      throw TransportError("DDS Security: " + dir +
                           " is neither a participant's directory (no cert.pem) nor holds one " +
                           (identity.empty()
                                ? std::string("(name the participant: --dds-identity)")
                                : "for participant '" + identity + "' (" +
                                      (base / identity / "cert.pem").string() + " is missing)"));
    }
    base /= identity;
  }
  DdsSecurityFiles f;
  f.dir = base.string();
  f.identity_ca = (base / "identity_ca.pem").string();
  f.certificate = (base / "cert.pem").string();
  f.private_key = (base / "key.pem").string();
  f.permissions_ca = (base / "permissions_ca.pem").string();
  f.governance = (base / "governance.p7s").string();
  f.permissions = (base / "permissions.p7s").string();
  for (std::string* p : {&f.identity_ca, &f.certificate, &f.private_key, &f.permissions_ca,
                         &f.governance, &f.permissions}) {
    if (access(p->c_str(), R_OK) != 0) {
      throw TransportError("DDS Security: " + *p + " is missing or cannot be read");
    }
    *p = fs::absolute(*p).lexically_normal().string();
    if (p->find_first_of("<>&\"'") != std::string::npos) {
      throw TransportError("DDS Security: the path '" + *p + "' has XML characters");
    }
  }
  return f;
}

void check_dds_security_files(const DdsSecurityFiles& f) {
  check_certificate(f);
  check_signed_document(f.governance, f.permissions_ca);
  check_signed_document(f.permissions, f.permissions_ca);
}

void check_dds_identities(const std::string& dir, const std::vector<std::string>& names) {
  if (fs::exists(fs::path(dir) / "cert.pem")) {
    throw TransportError("DDS Security: " + dir +
                         " is one participant's directory; this needs the whole directory that "
                         "scripts/pki.sh made (it gives each process its own identity)");
  }
  for (const std::string& name : names) {
    check_dds_security_files(resolve_dds_security(dir, name));
  }
}

int dds_governance_system_domain(const std::string& governance_path) {
  std::ifstream in(governance_path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string tag = "<domains><id>";
  const auto at = text.find(tag);
  if (at == std::string::npos) {
    throw TransportError("DDS Security: " + governance_path +
                         " names no system domain (make it with scripts/pki.sh)");
  }
  return std::atoi(text.c_str() + at + tag.size());
}

std::string dds_security_config_xml(const DdsSecurityFiles& f) {
  return fmt::format(
      "<Security><Authentication>"
      R"(<Library path="dds_security_auth" initFunction="init_authentication" )"
      R"(finalizeFunction="finalize_authentication"/>)"
      "<IdentityCA>file:{}</IdentityCA><IdentityCertificate>file:{}</IdentityCertificate>"
      "<PrivateKey>file:{}</PrivateKey></Authentication><AccessControl>"
      R"(<Library path="dds_security_ac" initFunction="init_access_control" )"
      R"(finalizeFunction="finalize_access_control"/>)"
      "<PermissionsCA>file:{}</PermissionsCA><Governance>file:{}</Governance>"
      "<Permissions>file:{}</Permissions></AccessControl><Cryptographic>"
      R"(<Library path="dds_security_crypto" initFunction="init_crypto" )"
      R"(finalizeFunction="finalize_crypto"/>)"
      "</Cryptographic></Security>",
      f.identity_ca, f.certificate, f.private_key, f.permissions_ca, f.governance, f.permissions);
}

}  // namespace auvrl::transport
