// The transports a multi-process benchmark compares in one run (--transport lcm, dds,
// dds-secure, both, dds-both, all), and the identities of a secured one: with DDS Security
// (--dds-security, a directory made by scripts/pki.sh) each process is a participant of its own.
#pragma once

#include <string>
#include <vector>

#include "common/cli.hpp"
#include "common/dds_security.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"

namespace auvrl::bench {

/// One transport the bench runs over: its name in the output and its configuration.
struct TransportVariant {
  std::string name;
  transport::TransportConfig config;
};

/// The configuration of participant `identity` (a name in scripts/pki.sh's directory): config
/// itself when it is not secured.
inline transport::TransportConfig as_participant(const transport::TransportConfig& config,
                                                 const std::string& identity) {
  transport::TransportConfig c = config;
  if (!c.dds.security_dir.empty()) c.dds.security_identity = identity;
  return c;
}

/// The transport flags of participant `identity`, for a child process.
inline std::vector<std::string> participant_arguments(const transport::TransportConfig& config,
                                                      const std::string& identity) {
  return transport::transport_arguments(as_participant(config, identity));
}

/// Adds --transport and --dds-security; pki_help names the participants a secured run needs.
inline void add_variant_options(cli::CommandLine& cmd, std::string* which,
                                std::string* security_dir, const std::string& pki_help) {
  cmd.option("transport", which,
             "lcm, dds, dds-secure (DDS Security), both (lcm and dds), dds-both (dds and "
             "dds-secure) or all (one after the other, same run)");
  cmd.choices("transport", {"lcm", "dds", "dds-secure", "both", "dds-both", "all"});
  cmd.option("dds-security", security_dir,
             "dds-secure: a directory made by scripts/pki.sh with the participants " + pki_help);
}

/// The variants --transport `which` selects, dds-secure with scripts/pki.sh's directory, which
/// must hold the participants `names` (else TransportError).
inline std::vector<TransportVariant> select_variants(const std::string& which,
                                                     const std::string& security_dir,
                                                     const std::vector<std::string>& names) {
  TransportVariant lcm{"lcm", {}}, dds{"dds", {}}, secure{"dds-secure", {}};
  dds.config.kind = secure.config.kind = transport::TransportKind::kDds;
  secure.config.dds.security_dir = security_dir;
  std::vector<TransportVariant> variants;
  for (const TransportVariant& v : {lcm, dds, secure}) {
    const bool selected = which == v.name || which == "all" ||
                          (which == "both" && v.name != "dds-secure") ||
                          (which == "dds-both" && v.name != "lcm");
    if (selected) variants.push_back(v);
  }
  if (variants.back().name == "dds-secure") {
    if (security_dir.empty()) {
      throw transport::TransportError("--transport dds-secure needs --dds-security DIR");
    }
    transport::check_dds_identities(security_dir, names);
  }
  return variants;
}

}  // namespace auvrl::bench
