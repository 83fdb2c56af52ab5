#include "common/transport.hpp"

#include <lcm/lcm.h>

#include <cerrno>
#include <chrono>
#include <map>
#include <regex>

#include "common/transport_dds.hpp"

namespace auvrl::transport {

namespace {

/// Value of a query parameter in a URL ("" if absent).
std::optional<std::string> url_param(const std::string& url, const std::string& key) {
  const auto query = url.find('?');
  if (query == std::string::npos) return std::nullopt;
  std::size_t pos = query + 1;
  while (pos <= url.size()) {
    const auto end = std::min(url.find('&', pos), url.size());
    const std::string item = url.substr(pos, end - pos);
    const auto eq = item.find('=');
    if (item.substr(0, eq) == key) {
      return eq == std::string::npos ? std::string() : item.substr(eq + 1);
    }
    pos = end + 1;
  }
  return std::nullopt;
}

/// The LCM implementation of Transport, over the C API (one lcm_t, one thread).
class LcmTransport final : public Transport {
 public:
  explicit LcmTransport(const std::string& url) : url_(url) {
    lcm_ = lcm_create(url.c_str());
    if (lcm_ == nullptr) {
      throw TransportError(
          "cannot open LCM at '" + url +
          "': for udpm a multicast route is needed (run inside scripts/netns.sh, which adds "
          "224.0.0.0/4 on lo)");
    }
  }
  ~LcmTransport() override {
    for (auto& [id, sub] : subscriptions_) lcm_unsubscribe(lcm_, sub->lcm_subscription);
    lcm_destroy(lcm_);
  }

  void publish(const std::string& channel, const void* data, std::size_t size) override {
    if (size > static_cast<std::size_t>(INT32_MAX) ||
        lcm_publish(lcm_, channel.c_str(), data, static_cast<unsigned int>(size)) != 0) {
      throw TransportError("LCM publish failed on channel " + channel + " (" +
                           std::to_string(size) + " bytes)");
    }
  }

  SubscriptionId subscribe(const std::string& channel_regex, RawHandler handler,
                           int queue_capacity) override {
    auto sub = std::make_unique<Subscription>();
    sub->handler = std::move(handler);
    sub->lcm_subscription =
        lcm_subscribe(lcm_, channel_regex.c_str(), &LcmTransport::dispatch, sub.get());
    if (sub->lcm_subscription == nullptr) {
      throw TransportError("LCM cannot subscribe to '" + channel_regex + "'");
    }
    lcm_subscription_set_queue_capacity(sub->lcm_subscription, queue_capacity);
    const SubscriptionId id = next_id_++;
    subscriptions_.emplace(id, std::move(sub));
    return id;
  }

  void unsubscribe(SubscriptionId id) override {
    const auto it = subscriptions_.find(id);
    if (it == subscriptions_.end()) return;
    lcm_unsubscribe(lcm_, it->second->lcm_subscription);
    subscriptions_.erase(it);
  }

  bool handle_one(int timeout_ms) override {
    errno = 0;
    const int status = lcm_handle_timeout(lcm_, timeout_ms);
    // A signal (SIGTERM for a clean stop) interrupts the wait: not a failure.
    if (status < 0 && errno == EINTR) return false;
    if (status < 0) throw TransportError("LCM receive failed on " + url_);
    return status > 0;
  }

 private:
  struct Subscription {
    RawHandler handler;
    lcm_subscription_t* lcm_subscription = nullptr;
  };

  static void dispatch(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
    const std::string channel_name(channel);
    const RawMessage raw{channel_name, static_cast<const std::uint8_t*>(rbuf->data),
                         rbuf->data_size, rbuf->recv_utime};
    static_cast<Subscription*>(user)->handler(raw);
  }

  std::string url_;
  lcm_t* lcm_ = nullptr;
  std::map<SubscriptionId, std::unique_ptr<Subscription>> subscriptions_;
  SubscriptionId next_id_ = 0;
};

}  // namespace

void check_url_is_host_only(const std::string& url, bool allow_off_host) {
  if (allow_off_host) return;
  const auto scheme_end = url.find("://");
  const std::string scheme = scheme_end == std::string::npos ? "" : url.substr(0, scheme_end);
  if (scheme == "memq" || scheme == "file") return;
  if (scheme == "udpm") {
    // LCM's own default ttl is 0; any other value lets datagrams be routed off the host.
    const auto ttl = url_param(url, "ttl");
    if (!ttl || *ttl == "0") return;
    throw TransportError("refusing LCM URL '" + url + "': ttl=" + *ttl +
                         " lets traffic leave this host, and LCM has no authentication; pass "
                         "--allow-off-host (or set allow_off_host) to accept it");
  }
  if (scheme == "tcpq") {
    const std::string rest = url.substr(scheme_end + 3);
    if (rest.empty() || rest.rfind("127.", 0) == 0 || rest.rfind("localhost", 0) == 0) return;
    throw TransportError("refusing LCM URL '" + url +
                         "': the tcpq hub is not on this host; pass --allow-off-host to accept it");
  }
  throw TransportError("refusing LCM URL '" + url +
                       "': unknown provider (expected udpm://, memq://, file:// or tcpq://)");
}

int Transport::drain() {
  int count = 0;
  while (handle_one(0)) ++count;
  return count;
}

int Transport::handle(int timeout_ms) {
  if (!handle_one(timeout_ms)) return 0;
  return 1 + drain();
}

std::string to_string(TransportKind kind) { return kind == TransportKind::kDds ? "dds" : "lcm"; }

TransportKind parse_transport_kind(const std::string& text) {
  if (text == "lcm") return TransportKind::kLcm;
  if (text == "dds") return TransportKind::kDds;
  throw TransportError("unknown transport '" + text + "' (expected lcm or dds)");
}

std::unique_ptr<Transport> make_transport(const TransportConfig& config) {
  if (config.kind == TransportKind::kDds) {
    return make_dds_transport(config.dds, config.allow_off_host);
  }
  check_url_is_host_only(config.lcm_url, config.allow_off_host);
  return std::make_unique<LcmTransport>(config.lcm_url);
}

std::string describe(const TransportConfig& config) {
  if (config.kind == TransportKind::kLcm) return config.lcm_url;
  std::string text = "dds domain " + std::to_string(config.dds.domain_id);
  if (!config.dds.config_path.empty()) return text + ", config " + config.dds.config_path;
  text += ", peers ";
  for (std::size_t i = 0; i < config.dds.peers.size(); ++i) {
    text += (i ? "," : "") + config.dds.peers[i];
  }
  return text;
}

std::unique_ptr<Transport> make_in_process_transport() {
  return std::make_unique<LcmTransport>("memq://");
}

std::int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::vector<std::string> Transport::wait_for_readers(const std::string&,
                                                     const std::vector<std::string>&,
                                                     std::chrono::milliseconds) {
  return {};
}

}  // namespace auvrl::transport
