#include "common/transport_options.hpp"

#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/transport_dds.hpp"

namespace auvrl::transport {

std::vector<std::string> parse_comma_list(const std::string& text, const std::string& what) {
  std::vector<std::string> items;
  std::size_t pos = 0;
  while (true) {
    const auto comma = text.find(',', pos);
    const std::string item =
        text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    if (item.empty()) {
      throw TransportError("empty item in the " + what + " list '" + text + "' (expected " + what +
                           "[," + what + "...])");
    }
    items.push_back(item);
    if (comma == std::string::npos) return items;
    pos = comma + 1;
  }
}

std::vector<std::string> parse_peer_list(const std::string& text) {
  return parse_comma_list(text, "host");
}

void add_transport_options(cli::CommandLine& cmd, TransportConfig& config,
                           std::vector<std::string>* given) {
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
  cmd.custom_option(
      "dds-security",
      [&config, record](const std::string& v) {
        config.dds.security_dir = v;
        record("dds-security", v);
      },
      "",
      "DDS Security: a directory made by scripts/pki.sh, or one participant's directory in it "
      "(authentication, access control, encryption)");
  cmd.custom_option(
      "dds-identity",
      [&config, record](const std::string& v) {
        config.dds.security_identity = v;
        record("dds-identity", v);
      },
      "", "DDS Security: this participant's name in the --dds-security directory (actor-0, ...)");
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

void add_lockstep_options(cli::CommandLine& cmd, LockstepBusOptions& options) {
  cmd.option("lockstep-lcm-url", &options.lcm_url,
             "LCM: a bus of its own for the lockstep commands and states (default: the "
             "system's bus)");
  cmd.option("lockstep-dds-domain", &options.dds_domain_id,
             "DDS: a domain of its own for the lockstep commands and states (-1: the system's)");
}

std::optional<TransportConfig> lockstep_bus_config(const TransportConfig& system,
                                                   const LockstepBusOptions& options) {
  TransportConfig bus = system;
  if (system.kind == TransportKind::kLcm) {
    if (options.lcm_url.empty()) return std::nullopt;
    bus.lcm_url = options.lcm_url;
    return bus;
  }
  if (options.dds_domain_id < 0 || options.dds_domain_id == system.dds.domain_id) {
    return std::nullopt;
  }
  bus.dds.domain_id = options.dds_domain_id;
  // The pair runs on one host: its bus never leaves it (loopback only, whatever the system's
  // peers), so no other host can reach the simulator's commands.
  bus.dds.peers = {"127.0.0.1"};
  bus.dds.config_path.clear();
  bus.dds.private_lockstep_bus = true;
  return bus;
}

std::vector<std::string> transport_arguments(const TransportConfig& config) {
  std::vector<std::string> args = {"--transport", to_string(config.kind)};
  if (config.kind == TransportKind::kLcm) {
    args.insert(args.end(), {"--lcm-url", config.lcm_url});
  } else {
    args.insert(args.end(), {"--dds-domain", std::to_string(config.dds.domain_id)});
    if (config.dds.config_path.empty()) {
      std::string peers;
      for (const std::string& p : config.dds.peers) peers += (peers.empty() ? "" : ",") + p;
      args.insert(args.end(), {"--dds-peers", peers});
    } else {
      args.insert(args.end(), {"--dds-config", config.dds.config_path});
    }
  }
  if (config.kind == TransportKind::kDds && !config.dds.security_dir.empty()) {
    args.insert(args.end(), {"--dds-security", config.dds.security_dir});
    if (!config.dds.security_identity.empty()) {
      args.insert(args.end(), {"--dds-identity", config.dds.security_identity});
    }
  }
  if (config.kind == TransportKind::kDds && !config.dds.lockstep_reliable) {
    args.push_back("--dds-lockstep-best-effort");
  }
  if (config.allow_off_host) args.push_back("--allow-off-host");
  return args;
}

void apply_transport_arguments(const std::vector<std::string>& args, TransportConfig& config) {
  cli::CommandLine cmd("transport", "");
  add_transport_options(cmd, config);
  std::vector<const char*> argv = {"transport"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  cmd.parse(static_cast<int>(argv.size()), argv.data());
}

namespace {

config::Table<TransportConfig> make_transport_table() {
  using C = TransportConfig;
  config::Table<C> t("transport",
                     "the transport of every process (flags: --transport, --lcm-url, "
                     "--dds-domain, --dds-peers, --dds-config, --dds-security, --allow-off-host)");
  t.text_field(
      "kind", &C::kind, parse_transport_kind, [](TransportKind k) { return to_string(k); },
      "one of lcm, dds", "", "LCM (UDP multicast) or Cyclone DDS (unicast discovery)");
  t.field("lcm_url", &C::lcm_url, "", "LCM URL of the system's bus");
  t.field(
      "dds_domain", [](C& c) -> int& { return c.dds.domain_id; }, "0..232", "DDS domain id");
  t.text_field(
      "dds_peers", [](C& c) -> std::vector<std::string>& { return c.dds.peers; }, parse_peer_list,
      [](const std::vector<std::string>& peers) {
        std::string text;
        for (const std::string& p : peers) text += (text.empty() ? "" : ",") + p;
        return text;
      },
      "string", "host[,host...]",
      "hosts of the other DDS participants (anything but loopback needs allow_off_host)");
  t.field(
      "dds_config", [](C& c) -> std::string& { return c.dds.config_path; },
      "path, relative to the configuration file",
      "a Cyclone XML file replacing the generated configuration (needs allow_off_host)");
  t.field(
      "dds_security", [](C& c) -> std::string& { return c.dds.security_dir; },
      "path, relative to the configuration file",
      "DDS Security: a directory made by scripts/pki.sh (authentication, access control, "
      "encryption)");
  t.field("allow_off_host", &C::allow_off_host, "",
          "accept a transport whose traffic can leave this host (no authentication!)");
  return t;
}

}  // namespace

const config::Table<TransportConfig>& transport_table() {
  static const config::Table<TransportConfig> table = make_transport_table();
  return table;
}

void read_transport_section(config::Section s, TransportConfig& config) {
  transport_table().read_keys(s, config);
  if (s.has("dds_config")) {
    config.dds.config_path = config::resolve_path(s, config.dds.config_path);
  }
  if (s.has("dds_security")) {
    config.dds.security_dir = config::resolve_path(s, config.dds.security_dir);
  }
  s.finish();
  // Name the key that widens the configuration: the URL for LCM, the DDS settings otherwise.
  try {
    if (config.kind == TransportKind::kLcm) {
      check_url_is_host_only(config.lcm_url, config.allow_off_host);
    }
  } catch (const TransportError& e) {
    s.fail("lcm_url", e.what());
  }
  try {
    if (config.kind == TransportKind::kDds) check_dds_settings(config.dds, config.allow_off_host);
  } catch (const TransportError& e) {
    s.fail(s.has("dds_config")     ? "dds_config"
           : s.has("dds_security") ? "dds_security"
           : s.has("dds_peers")    ? "dds_peers"
                                   : "kind",
           e.what());
  }
}

}  // namespace auvrl::transport
