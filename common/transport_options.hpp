// The transport's configuration as every process and the launcher take it: the same command-
// line flags everywhere (--transport lcm|dds, --lcm-url, --dds-domain, --dds-peers,
// --dds-config, --dds-security, --allow-off-host), the `transport:` section of a run configuration,
// the flags that pass a configuration on to a child process, and the private lockstep bus of a
// simulator/actor pair.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"
#include "common/transport.hpp"

namespace auvrl::transport {

/// Parses a comma-separated list ("a,b"); an empty item is an error naming what the items are.
std::vector<std::string> parse_comma_list(const std::string& text, const std::string& what);

/// Parses a comma-separated list of DDS peers ("127.0.0.1,10.0.0.2"); empty items are errors.
std::vector<std::string> parse_peer_list(const std::string& text);

/// Adds the transport flags to a command line (cli::CommandLine, any subcommand of it),
/// bound to config. When given is set, every transport flag parsed is also appended to it as
/// "--name" "value" (a launcher passes them on or merges them over a configuration file).
void add_transport_options(cli::CommandLine& cmd, TransportConfig& config,
                           std::vector<std::string>* given = nullptr);

/// The private bus of a simulator and its actor (lockstep commands and states only): over LCM
/// a URL of its own, over DDS a domain of its own.
struct LockstepBusOptions {
  std::string lcm_url;     ///< LCM: the pair's URL ("" = the system's bus)
  int dds_domain_id = -1;  ///< DDS: the pair's domain (-1 = the system's domain)
};

/// Adds --lockstep-lcm-url and --lockstep-dds-domain.
void add_lockstep_options(cli::CommandLine& cmd, LockstepBusOptions& options);

/// The configuration of the private lockstep bus, or nothing when the pair uses the system's
/// bus. Over DDS the pair gets a domain of its own rather than sharing the system's: every
/// lockstep channel goes over one DDS topic, so in a shared domain each simulator and actor
/// would receive (and filter out) the ~20k messages/s of every other pair; a domain per pair
/// keeps that traffic between the two processes, as the LCM port per pair does.
std::optional<TransportConfig> lockstep_bus_config(const TransportConfig& system,
                                                   const LockstepBusOptions& options);

/// The flags that make a child process open the same transport as config (for the launcher).
std::vector<std::string> transport_arguments(const TransportConfig& config);

/// Applies recorded transport flags (see add_transport_options' given) over config; throws
/// cli::UsageError on a bad flag.
void apply_transport_arguments(const std::vector<std::string>& args, TransportConfig& config);

/// Reads the `transport:` section of a run configuration:
///   transport:
///     kind: dds                # lcm (default) or dds
///     lcm_url: udpm://...      # LCM
///     dds_domain: 0            # DDS domain id
///     dds_peers: 127.0.0.1     # comma-separated hosts
///     dds_config: cyclone.xml  # a Cyclone XML file (relative to the configuration file)
///     dds_security: pki        # scripts/pki.sh's directory (relative to it too)
///     allow_off_host: false
void read_transport_section(config::Section section, TransportConfig& config);

/// The keys of a `transport:` section (documentation and reading).
const config::Table<TransportConfig>& transport_table();

}  // namespace auvrl::transport
