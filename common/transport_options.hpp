// The transport's configuration as every process and the launcher take it: the same command-
// line flags everywhere (--transport lcm|dds, --lcm-url, --dds-domain, --dds-peers,
// --dds-config, --allow-off-host), the `transport:` section of a run configuration, the flags
// that pass a configuration on to a child process, and the private lockstep bus of a
// simulator/actor pair.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"
#include "common/transport.hpp"

namespace auvrl::transport {

/// Parses a comma-separated list of DDS peers ("127.0.0.1,10.0.0.2"); empty items are errors.
std::vector<std::string> parse_peer_list(const std::string& text);

/// Adds the transport flags to a command line (cli::CommandLine, any subcommand of it),
/// bound to config. When given is set, every transport flag parsed is also appended to it as
/// "--name" "value" (a launcher passes them on or merges them over a configuration file).
template <class CommandLineT>
void add_transport_options(CommandLineT& cmd, TransportConfig& config,
                           std::vector<std::string>* given = nullptr) {
  const auto record = [given](const std::string& name, const std::string& value) {
    if (given == nullptr) return;
    given->push_back("--" + name);
    if (!value.empty()) given->push_back(value);
  };
  cmd.custom_option(
      "transport",
      [&config, record](const std::string& v) {
        config.kind = parse_transport_kind(v);
        record("transport", v);
      },
      to_string(config.kind), "lcm (UDP multicast) or dds (Cyclone DDS, unicast discovery)");
  cmd.custom_option(
      "lcm-url",
      [&config, record](const std::string& v) {
        config.lcm_url = v;
        record("lcm-url", v);
      },
      config.lcm_url, "LCM URL of the system's bus (--transport lcm)");
  cmd.custom_option(
      "dds-domain",
      [&config, record](const std::string& v) {
        std::size_t used = 0;
        const int domain = std::stoi(v, &used);
        if (used != v.size()) throw TransportError("expected an integer, got '" + v + "'");
        config.dds.domain_id = domain;
        record("dds-domain", v);
      },
      std::to_string(config.dds.domain_id), "DDS domain id, 0..232 (--transport dds)");
  cmd.custom_option(
      "dds-peers",
      [&config, record](const std::string& v) {
        config.dds.peers = parse_peer_list(v);
        record("dds-peers", v);
      },
      "127.0.0.1",
      "hosts of the other DDS participants, comma-separated (unicast discovery; anything but "
      "loopback needs --allow-off-host)");
  cmd.custom_option(
      "dds-config",
      [&config, record](const std::string& v) {
        config.dds.config_path = v;
        record("dds-config", v);
      },
      "", "a Cyclone XML file replacing the generated configuration (needs --allow-off-host)");
  cmd.custom_flag(
      "dds-lockstep-best-effort",
      [&config, record] {
        config.dds.lockstep_reliable = false;
        record("dds-lockstep-best-effort", "");
      },
      "DDS: lockstep commands and states best effort instead of reliable (every process of "
      "a lockstep pair must agree)");
  cmd.custom_flag(
      "allow-off-host",
      [&config, record] {
        config.allow_off_host = true;
        record("allow-off-host", "");
      },
      "accept a transport whose traffic can leave this host (LCM URL with ttl > 0, DDS peers "
      "off this host or a DDS configuration file; no authentication!)");
}

/// The private bus of a simulator and its actor (lockstep commands and states only): over LCM
/// a URL of its own, over DDS a domain of its own.
struct LockstepBusOptions {
  std::string lcm_url;     ///< LCM: the pair's URL ("" = the system's bus)
  int dds_domain_id = -1;  ///< DDS: the pair's domain (-1 = the system's domain)
};

/// Adds --lockstep-lcm-url and --lockstep-dds-domain.
template <class CommandLineT>
void add_lockstep_options(CommandLineT& cmd, LockstepBusOptions& options) {
  cmd.option("lockstep-lcm-url", &options.lcm_url,
             "LCM: a bus of its own for the lockstep commands and states (default: the "
             "system's bus)");
  cmd.option("lockstep-dds-domain", &options.dds_domain_id,
             "DDS: a domain of its own for the lockstep commands and states (-1: the system's)");
}

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
///     allow_off_host: false
void read_transport_section(config::Section section, TransportConfig& config);

/// The keys of a `transport:` section (documentation and reading).
const config::Table<TransportConfig>& transport_table();

}  // namespace auvrl::transport
