// The one transport every process uses: publish and subscribe LCM-encoded messages by channel.
// Nothing above this layer knows which wire carries the bytes: LCM UDP multicast (the default)
// or Cyclone DDS (common/transport_dds.hpp), chosen by TransportConfig::kind.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace auvrl::transport {

/// Default LCM URL: multicast that never leaves the host (ttl=0) with a receive buffer sized
/// for the largest message (policy weights of a 400-300 actor are ~0.5 MB; the kernel caps
/// the request at net.core.rmem_max and doubles it).
inline constexpr const char* kDefaultLcmUrl =
    "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";

/// Which implementation carries the messages.
enum class TransportKind {
  kLcm,  ///< LCM (UDP multicast by default; lcm_url)
  kDds,  ///< Cyclone DDS (unicast discovery, reliable, transient-local state; dds)
};

/// "lcm" or "dds".
std::string to_string(TransportKind kind);
/// Parses "lcm" or "dds"; throws TransportError naming the accepted values otherwise.
TransportKind parse_transport_kind(const std::string& text);

/// Cyclone DDS settings. Without config_path the transport generates its Cyclone configuration:
/// interface lo (when every peer is a loopback address), multicast off, unicast discovery of
/// the listed peers, participant index auto up to max_auto_participant_index.
struct DdsSettings {
  /// DDS domain id, 0..232 (the UDP ports are 7400 + 250 * domain + ...).
  int domain_id = 0;
  /// Hosts (addresses or names) where other participants run; discovery is unicast to them.
  /// Anything but loopback addresses needs allow_off_host.
  std::vector<std::string> peers = {"127.0.0.1"};
  /// A Cyclone XML file that replaces the generated configuration entirely (needs
  /// allow_off_host: it may bind any interface).
  std::string config_path;
  /// Processes per host and domain: each needs a participant index (Cyclone's default, 9,
  /// stops the tenth process on a host).
  int max_auto_participant_index = 120;
  /// Lockstep channels (SIM_CMD_/SIM_STATE_/...): reliable (true) or best effort. The sim
  /// client resends a command whose answer is missing, so best effort is safe too; the
  /// docs/results.md compares the two (bench_lockstep).
  bool lockstep_reliable = true;
  /// DDS Security: a directory made by scripts/pki.sh, or one participant's directory in it
  /// ("" = no security). Authentication, access control and encryption in every domain the
  /// process opens; peers off this host are then accepted without allow_off_host.
  std::string security_dir;
  /// The participant's name in security_dir when that is scripts/pki.sh's whole directory
  /// ("learner", "actor-0", ...).
  std::string security_identity;
  /// What this process is (learner, actor, simulator, logger, ...): carried by its readers, so
  /// that a publisher can wait for the readers of a role (Transport::wait_for_readers). Each
  /// program sets its own.
  std::string role;
  /// A lockstep pair's private bus (set by lockstep_bus_config): loopback only, and under DDS
  /// Security not the governance's system domain.
  bool private_lockstep_bus = false;
};

/// Which transport to open and how.
struct TransportConfig {
  std::string lcm_url = kDefaultLcmUrl;
  /// LCM has no authentication: anyone on the multicast group can inject commands or weights.
  /// A URL whose traffic can leave the host (udpm with ttl > 0 or without ttl) is refused
  /// unless this is set explicitly; so are DDS peers that are not loopback addresses and a
  /// DDS configuration file.
  bool allow_off_host = false;
  TransportKind kind = TransportKind::kLcm;
  DdsSettings dds;
};

/// Raised when a transport cannot be opened or a configuration is refused.
class TransportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws TransportError if url would let traffic leave the host and allow_off_host is false.
void check_url_is_host_only(const std::string& url, bool allow_off_host);

/// A received message as bytes, valid only during the handler call.
struct RawMessage {
  const std::string& channel;
  const std::uint8_t* data;
  std::size_t size;
  std::int64_t recv_utime;  ///< receive time (for a log replay: the replayed time), us
};

using RawHandler = std::function<void(const RawMessage&)>;
using SubscriptionId = int;

/// Publish/subscribe over named channels. Not thread-safe: one thread handles a transport.
class Transport {
 public:
  virtual ~Transport() = default;

  /// Sends bytes on a channel; throws TransportError if the transport refuses them.
  virtual void publish(const std::string& channel, const void* data, std::size_t size) = 0;

  /// Calls handler for each message on channels matching channel_regex (a full-match POSIX
  /// regex, as LCM uses). queue_capacity bounds messages held between handle() calls; when
  /// full, LCM keeps the oldest and drops new ones, so consumers of self-superseding state
  /// must drain often (see Latest). Over DDS the channel's class decides (common/channels.hpp):
  /// state keeps only the newest per channel, queue channels make the writer wait, the others
  /// keep the newest queue_capacity per channel.
  virtual SubscriptionId subscribe(const std::string& channel_regex, RawHandler handler,
                                   int queue_capacity = 1000) = 0;
  virtual void unsubscribe(SubscriptionId id) = 0;

  /// Waits up to timeout_ms for one message and dispatches it. Returns true if one was
  /// handled, false on timeout; throws TransportError on a transport failure. A signal ends
  /// LCM's wait early (returning false); DDS waits out the timeout, so keep it short (<= 100 ms)
  /// where a stop request must be seen promptly.
  virtual bool handle_one(int timeout_ms) = 0;

  /// Waits until the publisher of `channel` has found, for each role of `roles`, a reader of
  /// that role that may receive it, or until timeout. Returns the roles still missing. Over DDS
  /// a message published before a remote reader is discovered never reaches it (volatile
  /// durability), so a process whose first messages matter (an actor's first episode) waits
  /// first; each DDS reader carries its participant's role (DdsSettings::role). LCM has no
  /// discovery: nothing to wait for (the default).
  virtual std::vector<std::string> wait_for_readers(const std::string& channel,
                                                    const std::vector<std::string>& roles,
                                                    std::chrono::milliseconds timeout);

  /// Dispatches everything already pending, without waiting. Returns how many.
  int drain();

  /// Waits up to timeout_ms for the first message, then drains the rest. Returns how many.
  int handle(int timeout_ms);
};

/// Opens the transport the configuration names; throws TransportError (refused or broken
/// configuration, transport that cannot start).
std::unique_ptr<Transport> make_transport(const TransportConfig& config);

/// Where the configuration sends the messages, for log lines ("udpm://..." or "dds domain 0,
/// peers 127.0.0.1").
std::string describe(const TransportConfig& config);

/// An in-process transport (LCM's memq://) for tests and single-process tools.
std::unique_ptr<Transport> make_in_process_transport();

/// Microseconds since the Unix epoch (what every message's utime carries).
std::int64_t now_utime();

/// Counts messages that could not be decoded, per reason, for heartbeats.
struct DecodeStats {
  std::int64_t decoded = 0;
  std::int64_t failed = 0;
};

/// Decodes an LCM-generated type from bytes; false if the bytes are not exactly one message of
/// that type (wrong fingerprint, truncated, trailing bytes, absurd array length).
template <class Msg>
bool decode_exact(const std::uint8_t* data, std::size_t size, Msg& out) {
  if (size > static_cast<std::size_t>(INT32_MAX)) return false;
  try {
    const int used = out.decode(data, 0, static_cast<int>(size));
    return used >= 0 && static_cast<std::size_t>(used) == size;
  } catch (const std::exception&) {
    // A negative or huge array length makes the generated code throw (length_error, bad_alloc).
    return false;
  }
}

/// Encodes and publishes an LCM-generated type.
template <class Msg>
void publish(Transport& transport, const std::string& channel, const Msg& msg) {
  const int size = msg.getEncodedSize();
  if (size < 0) throw TransportError("cannot encode a message for channel " + channel);
  // Reused per thread: publishing in a control loop should not allocate every message.
  thread_local std::vector<std::uint8_t> buffer;
  buffer.resize(static_cast<std::size_t>(size));
  if (msg.encode(buffer.data(), 0, size) != size) {
    throw TransportError("cannot encode a message for channel " + channel);
  }
  transport.publish(channel, buffer.data(), buffer.size());
}

/// Subscribes with decoding: handler(channel, msg) for each decodable message; messages that
/// do not decode as Msg are counted in stats (when given) and dropped.
template <class Msg>
SubscriptionId subscribe(Transport& transport, const std::string& channel_regex,
                         std::function<void(const std::string&, const Msg&)> handler,
                         DecodeStats* stats = nullptr, int queue_capacity = 1000) {
  return transport.subscribe(
      channel_regex,
      [handler = std::move(handler), stats](const RawMessage& raw) {
        Msg msg;
        if (!decode_exact(raw.data, raw.size, msg)) {
          if (stats) ++stats->failed;
          return;
        }
        if (stats) ++stats->decoded;
        handler(raw.channel, msg);
      },
      queue_capacity);
}

/// "Drain and keep newest" subscription for state that supersedes itself (policy weights,
/// schedules): every message overwrites the slot; take() hands out the newest once. Call
/// Transport::drain() (or handle()) before take() so nothing newer is still queued.
template <class Msg>
class Latest {
 public:
  Latest(Transport& transport, const std::string& channel_regex, int queue_capacity = 64)
      : transport_(transport) {
    id_ = subscribe<Msg>(
        transport, channel_regex,
        [this](const std::string& channel, const Msg& msg) {
          value_ = msg;
          channel_ = channel;
          ++received_;
        },
        &stats_, queue_capacity);
  }
  ~Latest() { transport_.unsubscribe(id_); }
  Latest(const Latest&) = delete;
  Latest& operator=(const Latest&) = delete;

  /// The newest message received since the last take(), if any.
  std::optional<Msg> take() {
    std::optional<Msg> out;
    out.swap(value_);
    return out;
  }
  bool has_value() const { return value_.has_value(); }
  const std::string& channel() const { return channel_; }
  std::int64_t received() const { return received_; }
  const DecodeStats& stats() const { return stats_; }

 private:
  Transport& transport_;
  SubscriptionId id_ = -1;
  std::optional<Msg> value_;
  std::string channel_;
  std::int64_t received_ = 0;
  DecodeStats stats_;
};

}  // namespace auvrl::transport
