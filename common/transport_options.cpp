#include "common/transport_options.hpp"

#include "common/cli.hpp"
#include "common/transport_dds.hpp"

namespace auvrl::transport {

std::vector<std::string> parse_peer_list(const std::string& text) {
  std::vector<std::string> peers;
  std::size_t pos = 0;
  while (true) {
    const auto comma = text.find(',', pos);
    const std::string item =
        text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    if (item.empty()) {
      throw TransportError("empty item in the peer list '" + text + "' (expected host[,host...])");
    }
    peers.push_back(item);
    if (comma == std::string::npos) return peers;
    pos = comma + 1;
  }
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

void read_transport_section(config::Section s, TransportConfig& config) {
  std::string kind = to_string(config.kind);
  s.read("kind", kind);
  try {
    config.kind = parse_transport_kind(kind);
  } catch (const TransportError& e) {
    s.fail("kind", e.what());
  }
  s.read("lcm_url", config.lcm_url);
  s.read("dds_domain", config.dds.domain_id);
  if (s.has("dds_peers")) {
    std::string peers;
    s.read("dds_peers", peers);
    try {
      config.dds.peers = parse_peer_list(peers);
    } catch (const TransportError& e) {
      s.fail("dds_peers", e.what());
    }
  }
  if (s.has("dds_config")) {
    std::string path;
    s.read("dds_config", path);
    config.dds.config_path = config::resolve_path(s, path);
  }
  s.read("allow_off_host", config.allow_off_host);
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
    s.fail(s.has("dds_config")  ? "dds_config"
           : s.has("dds_peers") ? "dds_peers"
                                : "kind",
           e.what());
  }
}

}  // namespace auvrl::transport
