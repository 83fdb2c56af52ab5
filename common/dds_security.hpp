// DDS Security for the Cyclone transport: who may publish and subscribe to what (the roles),
// the governance and permissions documents that say so, the files of one participant's
// identity as scripts/pki.sh writes them, their checks before Cyclone reads them, and the
// <Security> section of the Cyclone configuration that turns on authentication (PKI-DH),
// access control and encryption (AES-GCM) with Cyclone's own plugins.
//
// A participant's directory (what goes to the host that runs it):
//   identity_ca.pem     the run's certificate authority (authenticates every participant)
//   cert.pem, key.pem   this participant's certificate (CN = its name) and private key
//   permissions_ca.pem  the authority that signed the two documents below (the same CA)
//   governance.p7s      the domain's rules (signed): nothing unauthenticated, all encrypted
//   permissions.p7s     its role's grants (signed): the topics each participant of the role may
//                       publish and subscribe to
#pragma once

#include <string>
#include <vector>

namespace auvrl::transport {

/// A role of a secured system: the DDS topics (indices into channels::kDdsTopics) that its
/// participants may publish and subscribe to.
struct DdsRole {
  const char* name;
  const char* description;
  std::vector<int> publish;
  std::vector<int> subscribe;
};

/// The roles: learner, actor, simulator, controller, logger, operator, observer.
const std::vector<DdsRole>& dds_roles();

/// The role of that name; throws TransportError listing the roles otherwise.
const DdsRole& dds_role(const std::string& name);

/// The highest domain id a secured system may use (the governance's id range; Cyclone's access
/// control refuses a range beyond 230).
inline constexpr int kSecuredMaxDomainId = 230;

/// The governance document (unsigned XML): every domain 0..kSecuredMaxDomainId closed to
/// unauthenticated participants, join access control on, discovery and liveliness encrypted,
/// read and write access control on every topic; in system_domain (the bus that crosses
/// hosts) every topic's submessages and data encrypted; in the others (the lockstep pairs'
/// loopback-only buses) the simulator topics not encrypted, everything else encrypted.
std::string dds_governance_xml(int system_domain);

/// The permissions document (unsigned XML) of a role: one grant per subject (an X.509 subject
/// name, "CN=actor-0,O=auvrl"), valid from not_before to not_after (YYYY-MM-DDTHH:MM:SS),
/// allowing the role's topics in domains 0..kSecuredMaxDomainId and denying everything else.
std::string dds_permissions_xml(const DdsRole& role, const std::vector<std::string>& subjects,
                                const std::string& not_before, const std::string& not_after);

/// The files of one participant's identity (see the top of this file).
struct DdsSecurityFiles {
  std::string dir;
  std::string identity_ca;
  std::string certificate;
  std::string private_key;
  std::string permissions_ca;
  std::string governance;
  std::string permissions;
};

/// The participant's files from dir: a participant's directory (it holds cert.pem), or a
/// directory made by scripts/pki.sh whose subdirectory `identity` is the participant's. Throws
/// TransportError naming what is missing.
DdsSecurityFiles resolve_dds_security(const std::string& dir, const std::string& identity);

/// Checks a participant's files before Cyclone reads them, so that a bad one is refused at
/// start with its name and the reason: each is readable; the certificate was issued by the
/// identity CA and is valid now; the key is the certificate's; the governance and permissions
/// documents carry a valid signature of the permissions CA (a tampered document does not).
/// Throws TransportError.
void check_dds_security_files(const DdsSecurityFiles& files);

/// Checks the files of every participant `names` in dir, a directory made by scripts/pki.sh (a
/// single participant's directory is refused): what a program that starts several processes
/// does before starting any. Throws TransportError naming the first that fails.
void check_dds_identities(const std::string& dir, const std::vector<std::string>& names);

/// The system domain a signed governance document (governance.p7s) was made for: its first
/// domain rule's single id. Throws TransportError if it has none.
int dds_governance_system_domain(const std::string& governance_path);

/// The <Security> element of a Cyclone domain configuration for these files (as
/// resolve_dds_security gives them: absolute paths, checked free of XML characters).
std::string dds_security_config_xml(const DdsSecurityFiles& files);

}  // namespace auvrl::transport
