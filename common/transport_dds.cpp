#include "common/transport_dds.hpp"

#include <dds/dds.h>
#include <regex.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <mutex>

#include "auvrl_message.h"
#include "common/dds_security.hpp"

namespace auvrl::transport {

namespace {

using channels::ChannelClass;

constexpr int kTopics = channels::kDdsTopicCount;

/// Depth of the writers' keep-last histories (what a reliable writer can resend).
constexpr int kLockstepWriterDepth = 8;
constexpr int kOtherWriterDepth = 16;
/// A state-class or other publish that cannot go out within this long fails.
constexpr std::chrono::milliseconds kDefaultMaxBlocking{1000};
/// How long closing a transport waits, at most, for readers to acknowledge its queue and state
/// messages.
constexpr std::chrono::milliseconds kAckWaitOnClose{3000};

std::string dds_error(dds_return_t rc) { return dds_strretcode(rc); }

bool is_loopback_peer(const std::string& peer) {
  return peer.rfind("127.", 0) == 0 || peer == "localhost" || peer == "::1" || peer == "[::1]" ||
         peer.rfind("localhost:", 0) == 0 || peer.rfind("[::1]:", 0) == 0;
}

/// Domains this process has created, shared by every transport in the same domain (Cyclone
/// allows one configuration per domain and process; deleting the domain ends its participants).
struct DomainEntry {
  dds_entity_t domain = 0;
  std::string config;
  int users = 0;
};
std::mutex g_domains_mutex;
std::map<int, DomainEntry> g_domains;

void acquire_domain(int domain_id, const std::string& config) {
  std::lock_guard<std::mutex> lock(g_domains_mutex);
  const auto it = g_domains.find(domain_id);
  if (it != g_domains.end()) {
    if (it->second.config != config) {
      throw TransportError("DDS domain " + std::to_string(domain_id) +
                           " is already open in this process with another configuration");
    }
    ++it->second.users;
    return;
  }
  const dds_entity_t domain =
      dds_create_domain(static_cast<dds_domainid_t>(domain_id), config.c_str());
  if (domain < 0) {
    throw TransportError("cannot create DDS domain " + std::to_string(domain_id) + " (" +
                         dds_error(domain) +
                         "); check the Cyclone configuration: " + config.substr(0, 300));
  }
  g_domains[domain_id] = {domain, config, 1};
}

void release_domain(int domain_id) {
  std::lock_guard<std::mutex> lock(g_domains_mutex);
  const auto it = g_domains.find(domain_id);
  if (it == g_domains.end()) return;
  if (--it->second.users == 0) {
    dds_delete(it->second.domain);
    g_domains.erase(it);
  }
}

/// A dds_qos_t that frees itself.
class Qos {
 public:
  Qos() : qos_(dds_create_qos()) {}
  ~Qos() { dds_delete_qos(qos_); }
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

dds_duration_t to_dds(std::chrono::milliseconds ms) { return DDS_MSECS(ms.count()); }

/// The QoS of a class's writers (reader_capacity < 0) or of a subscription's readers (its queue
/// capacity): the same reliability, history kind and durability on both sides, so they match.
void set_qos(const Qos& q, ChannelClass c, bool lockstep_reliable, int reader_capacity) {
  const bool reader = reader_capacity >= 0;
  const int depth = std::max(1, reader_capacity);
  switch (c) {
    case ChannelClass::kState:
      // Only the newest per channel: a reader that falls behind skips versions.
      dds_qset_reliability(q.get(), DDS_RELIABILITY_RELIABLE, to_dds(kDefaultMaxBlocking));
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, 1);
      dds_qset_durability(q.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
      break;
    case ChannelClass::kQueue:
      // A reader's full history rejects new samples; the reliable protocol then holds them at
      // the writer, which waits: back-pressure, not loss.
      dds_qset_reliability(q.get(), DDS_RELIABILITY_RELIABLE, to_dds(kDdsQueueMaxBlocking));
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_ALL, 0);
      if (reader) {
        dds_qset_resource_limits(q.get(), depth, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
      }
      break;
    case ChannelClass::kLockstep:
      dds_qset_reliability(
          q.get(), lockstep_reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
          to_dds(kDefaultMaxBlocking));
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, reader ? depth : kLockstepWriterDepth);
      break;
    case ChannelClass::kOther:
      dds_qset_reliability(q.get(), DDS_RELIABILITY_RELIABLE, to_dds(kDefaultMaxBlocking));
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, reader ? depth : kOtherWriterDepth);
      break;
  }
}

/// The Cyclone DDS implementation of Transport (one participant, one waitset, one thread).
class DdsTransport final : public Transport {
 public:
  DdsTransport(const DdsSettings& settings, const std::string& config)
      : domain_id_(settings.domain_id),
        lockstep_reliable_(settings.lockstep_reliable),
        reader_tag_(kRoleTag + settings.role) {
    acquire_domain(domain_id_, config);
    participant_ =
        dds_create_participant(static_cast<dds_domainid_t>(domain_id_), nullptr, nullptr);
    if (participant_ < 0) {
      release_domain(domain_id_);
      throw TransportError("cannot create a DDS participant in domain " +
                           std::to_string(domain_id_) + ": " + dds_error(participant_));
    }
    try {
      waitset_ = check(dds_create_waitset(participant_), "create a waitset");
      // Writers of every topic from the start: discovery then matches them with the readers
      // long before the first publish, so no first message goes to nobody. Under DDS Security
      // only the topics this participant's permissions let it publish get one.
      for (int t = 0; t < kTopics; ++t) {
        const dds_entity_t topic = create_topic(t);
        if (topic == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) continue;
        Qos qos;
        set_qos(qos, channels::kDdsTopics[t].channel_class, lockstep_reliable_, -1);
        const dds_entity_t writer =
            dds_create_writer(participant_, check(topic, "create a topic"), qos.get(), nullptr);
        if (writer == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) continue;
        writers_[t] = check(writer, "create a writer");
      }
    } catch (...) {
      dds_delete(participant_);
      release_domain(domain_id_);
      throw;
    }
  }

  ~DdsTransport() override {
    // A writer's history dies with it: messages that a reader has not acknowledged yet (still
    // being repaired on a lossy link) would be lost: experience and episode reports, and the
    // newest weights. Give them a bounded time to arrive (a dead reader that is still matched
    // holds this up at most that long).
    const dds_time_t deadline = dds_time() + to_dds(kAckWaitOnClose);
    for (int t = 0; t < kTopics; ++t) {
      const ChannelClass c = channels::kDdsTopics[t].channel_class;
      if ((c == ChannelClass::kQueue || c == ChannelClass::kState) && written_[t] > 0) {
        dds_wait_for_acks(writers_[t], std::max<dds_duration_t>(0, deadline - dds_time()));
      }
    }
    dds_delete(participant_);  // and every reader, writer, topic and the waitset in it
    subscriptions_.clear();
    release_domain(domain_id_);
  }

  void publish(const std::string& channel, const void* data, std::size_t size) override {
    if (size > UINT32_MAX) {
      throw TransportError("DDS publish refused on channel " + channel + ": " +
                           std::to_string(size) + " bytes is too large");
    }
    auvrl_dds_Message msg{};
    msg.channel = const_cast<char*>(channel.c_str());
    msg.data._buffer = static_cast<std::uint8_t*>(const_cast<void*>(data));
    msg.data._length = static_cast<std::uint32_t>(size);
    msg.data._maximum = static_cast<std::uint32_t>(size);
    msg.data._release = false;
    const int t = channels::dds_topic_of(channel);
    if (writers_[t] == 0) {
      throw TransportError("DDS publish refused on channel " + channel +
                           ": this participant's DDS Security permissions do not allow "
                           "publishing on topic " +
                           channels::kDdsTopics[t].name);
    }
    const dds_return_t rc = dds_write(writers_[t], &msg);
    ++written_[t];
    if (rc == DDS_RETCODE_TIMEOUT) {
      throw TransportError("DDS publish on channel " + channel + " (" + std::to_string(size) +
                           " bytes) timed out: a reader does not keep up (back-pressure)");
    }
    if (rc < 0) {
      throw TransportError("DDS publish failed on channel " + channel + " (" +
                           std::to_string(size) + " bytes): " + dds_error(rc));
    }
  }

  SubscriptionId subscribe(const std::string& channel_regex, RawHandler handler,
                           int queue_capacity) override {
    auto sub = std::make_unique<Subscription>();
    sub->handler = std::move(handler);
    const std::string anchored = "^(" + channel_regex + ")$";
    if (regcomp(&sub->regex, anchored.c_str(), REG_EXTENDED | REG_NOSUB) != 0) {
      throw TransportError("DDS cannot subscribe to '" + channel_regex +
                           "': not a POSIX extended regular expression");
    }
    sub->regex_ok = true;
    const SubscriptionId id = next_id_++;
    std::vector<std::string> denied;
    try {
      for (int t : topics_possibly_matching(channel_regex)) {
        // A topic entity of its own, so that the filter (this subscription's regex) applies
        // to this reader only.
        const dds_entity_t topic = create_topic(t);
        if (topic == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) {
          denied.push_back(channels::kDdsTopics[t].name);
          continue;
        }
        sub->entities.push_back(check(topic, "create a topic"));
        check(dds_set_topic_filter_and_arg(topic, &Subscription::accept, sub.get()),
              "set a topic filter");
        Qos qos;
        set_qos(qos, channels::kDdsTopics[t].channel_class, lockstep_reliable_,
                std::max(1, queue_capacity));
        dds_qset_userdata(qos.get(), reader_tag_.data(), reader_tag_.size());
        const dds_entity_t reader = dds_create_reader(participant_, topic, qos.get(), nullptr);
        if (reader == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) {
          denied.push_back(channels::kDdsTopics[t].name);
          continue;
        }
        sub->entities.push_back(check(reader, "create a reader"));
        const dds_entity_t condition =
            check(dds_create_readcondition(reader, DDS_ANY_STATE), "create a read condition");
        check(dds_waitset_attach(waitset_, condition, static_cast<dds_attach_t>(reader)),
              "attach a read condition");
        sub->readers.push_back(reader);
      }
      // A regex over several topics reads those it may; one that may read none is refused.
      if (sub->readers.empty() && !denied.empty()) {
        std::string names;
        for (const std::string& n : denied) names += (names.empty() ? "" : ", ") + n;
        throw TransportError("DDS cannot subscribe to '" + channel_regex +
                             "': this participant's DDS Security permissions do not allow "
                             "subscribing to topic " +
                             names);
      }
    } catch (...) {
      delete_entities(sub->entities);
      throw;
    }
    subscriptions_.emplace(id, std::move(sub));
    rebuild_reader_list();
    return id;
  }

  std::vector<std::string> wait_for_readers(const std::string& channel,
                                            const std::vector<std::string>& roles,
                                            std::chrono::milliseconds timeout) override {
    const dds_entity_t writer = writers_[channels::dds_topic_of(channel)];
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (true) {
      std::vector<std::string> missing;
      const std::vector<std::string> present = matched_reader_roles(writer);
      for (const std::string& role : roles) {
        if (std::find(present.begin(), present.end(), role) == present.end()) {
          missing.push_back(role);
        }
      }
      if (missing.empty() || writer == 0 || std::chrono::steady_clock::now() >= deadline) {
        return missing;
      }
      dds_sleepfor(DDS_MSECS(20));
    }
  }

  void unsubscribe(SubscriptionId id) override {
    const auto it = subscriptions_.find(id);
    if (it == subscriptions_.end()) return;
    if (dispatching_) {
      // The handler running now may hold a loan from one of these readers: end it after.
      it->second->removed = true;
      pending_removal_.push_back(id);
      return;
    }
    remove(it);
  }

  bool handle_one(int timeout_ms) override {
    if (take_one()) return true;
    if (timeout_ms == 0) return false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (true) {
      const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(
          deadline - std::chrono::steady_clock::now());
      if (timeout_ms > 0 && left.count() <= 0) return false;
      const dds_return_t rc =
          dds_waitset_wait(waitset_, nullptr, 0, timeout_ms < 0 ? DDS_INFINITY : left.count());
      if (rc < 0) throw TransportError("DDS wait failed: " + dds_error(rc));
      if (take_one()) return true;
      if (rc == 0 && timeout_ms > 0) return false;
    }
  }

 private:
  struct Subscription {
    regex_t regex{};
    bool regex_ok = false;
    bool removed = false;
    RawHandler handler;
    std::vector<dds_entity_t> readers;
    std::vector<dds_entity_t> entities;  ///< topic entities and their readers, in creation order
    ~Subscription() {
      if (regex_ok) regfree(&regex);
    }
    /// Reader-side filter, called on Cyclone's receive threads (regexec is thread-safe).
    static bool accept(const void* sample, void* arg) {
      const auto* msg = static_cast<const auvrl_dds_Message*>(sample);
      const auto* self = static_cast<const Subscription*>(arg);
      return msg->channel != nullptr && regexec(&self->regex, msg->channel, 0, nullptr, 0) == 0;
    }
  };

  dds_entity_t check(dds_entity_t rc, const char* what) const {
    if (rc < 0) {
      throw TransportError(std::string("DDS cannot ") + what + " in domain " +
                           std::to_string(domain_id_) + ": " + dds_error(rc));
    }
    return rc;
  }

  /// Deletes a subscription's entities, newest first: each reader before the topic entity it
  /// reads.
  static void delete_entities(const std::vector<dds_entity_t>& entities) {
    for (auto e = entities.rbegin(); e != entities.rend(); ++e) dds_delete(*e);
  }

  /// The roles of the readers a writer has matched (their user data, see reader_tag_).
  static std::vector<std::string> matched_reader_roles(dds_entity_t writer) {
    std::vector<std::string> roles;
    if (writer == 0) return roles;
    std::vector<dds_instance_handle_t> handles(64);
    dds_return_t n = dds_get_matched_subscriptions(writer, handles.data(), handles.size());
    if (n > static_cast<dds_return_t>(handles.size())) {
      handles.resize(static_cast<std::size_t>(n));
      n = dds_get_matched_subscriptions(writer, handles.data(), handles.size());
    }
    for (dds_return_t i = 0; i < std::min<dds_return_t>(n, handles.size()); ++i) {
      dds_builtintopic_endpoint_t* reader = dds_get_matched_subscription_data(writer, handles[i]);
      if (reader == nullptr) continue;
      void* data = nullptr;
      std::size_t size = 0;
      if (reader->qos != nullptr && dds_qget_userdata(reader->qos, &data, &size) && data) {
        const std::string tag(static_cast<const char*>(data), size);
        if (tag.rfind(kRoleTag, 0) == 0) roles.push_back(tag.substr(std::strlen(kRoleTag)));
        dds_free(data);
      }
      dds_builtintopic_free_endpoint(reader);
    }
    return roles;
  }

  /// Topic t of kDdsTopics, or DDS_RETCODE_NOT_ALLOWED_BY_SECURITY when this participant may
  /// neither publish nor subscribe to it.
  dds_entity_t create_topic(int t) {
    const dds_entity_t topic = dds_create_topic(participant_, &auvrl_dds_Message_desc,
                                                channels::kDdsTopics[t].name, nullptr, nullptr);
    return topic == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY ? topic : check(topic, "create a topic");
  }

  void remove(std::map<SubscriptionId, std::unique_ptr<Subscription>>::iterator it) {
    delete_entities(it->second->entities);
    subscriptions_.erase(it);
    rebuild_reader_list();
  }

  void rebuild_reader_list() {
    readers_.clear();
    for (const auto& [id, sub] : subscriptions_) {
      if (sub->removed) continue;
      for (dds_entity_t r : sub->readers) readers_.push_back({id, r});
    }
    if (next_reader_ >= readers_.size()) next_reader_ = 0;
  }

  /// Takes one valid sample from the readers (round robin, so a busy channel cannot starve
  /// the others) and dispatches it. False if none had one.
  bool take_one() {
    const std::size_t n = readers_.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = (next_reader_ + k) % n;
      const auto [id, reader] = readers_[i];
      while (true) {
        void* sample = nullptr;
        dds_sample_info_t info;
        const dds_return_t got = dds_take(reader, &sample, &info, 1, 1);
        if (got < 0) throw TransportError("DDS take failed: " + dds_error(got));
        if (got == 0) break;
        if (!info.valid_data) {  // a writer went away or disposed: no message
          dds_return_loan(reader, &sample, got);
          continue;
        }
        next_reader_ = (i + 1) % n;
        dispatch(id, reader, sample);
        return true;
      }
    }
    return false;
  }

  void dispatch(SubscriptionId id, dds_entity_t reader, void* sample) {
    struct Loan {
      dds_entity_t reader;
      void* sample;
      ~Loan() { dds_return_loan(reader, &sample, 1); }
    } loan{reader, sample};
    const auto* msg = static_cast<const auvrl_dds_Message*>(sample);
    const auto it = subscriptions_.find(id);
    if (it == subscriptions_.end() || it->second->removed) return;
    const std::string channel(msg->channel != nullptr ? msg->channel : "");
    const RawMessage raw{channel, msg->data._buffer, msg->data._length, now_utime()};
    dispatching_ = true;
    struct Done {
      DdsTransport& self;
      ~Done() {
        self.dispatching_ = false;
        auto pending = std::move(self.pending_removal_);
        self.pending_removal_.clear();
        for (SubscriptionId removed : pending) {
          const auto found = self.subscriptions_.find(removed);
          if (found != self.subscriptions_.end()) self.remove(found);
        }
      }
    };
    {
      Done done{*this};
      it->second->handler(raw);
    }
  }

  /// The user data of this transport's readers: "auvrl-role=" and its participant's role.
  static constexpr const char* kRoleTag = "auvrl-role=";

  int domain_id_;
  bool lockstep_reliable_;
  std::string reader_tag_;
  dds_entity_t participant_ = 0;
  dds_entity_t waitset_ = 0;
  std::array<dds_entity_t, kTopics> writers_{};  ///< per topic; 0 where not permitted
  std::array<std::int64_t, kTopics> written_{};  ///< samples written per topic (acks at close)
  std::map<SubscriptionId, std::unique_ptr<Subscription>> subscriptions_;
  std::vector<std::pair<SubscriptionId, dds_entity_t>> readers_;
  std::size_t next_reader_ = 0;
  SubscriptionId next_id_ = 0;
  bool dispatching_ = false;
  std::vector<SubscriptionId> pending_removal_;
};

}  // namespace

namespace {

/// The top-level alternatives of a regex ("A|(B|C)" -> "A", "(B|C)"), with one pair of
/// parentheses around the whole regex removed first; escapes and bracket expressions are
/// skipped over.
std::vector<std::string> top_level_alternatives(std::string regex) {
  const auto split = [](const std::string& r, bool* wrapped) {
    std::vector<std::string> parts;
    int depth = 0;
    bool in_bracket = false;
    std::size_t start = 0;
    *wrapped = r.size() >= 2 && r.front() == '(' && r.back() == ')';
    for (std::size_t i = 0; i < r.size(); ++i) {
      const char c = r[i];
      if (in_bracket) {
        // "[]...]" and "[^]...]": a ']' first in the bracket is literal.
        if (c == ']' && i > 0 && r[i - 1] != '[' && !(r[i - 1] == '^' && r[i - 2] == '[')) {
          in_bracket = false;
        }
        continue;
      }
      if (c == '\\') {
        ++i;
      } else if (c == '[') {
        in_bracket = true;
      } else if (c == '(') {
        ++depth;
      } else if (c == ')') {
        // The opening parenthesis closes before the end: not one group around everything.
        if (--depth == 0 && i + 1 < r.size()) *wrapped = false;
      } else if (c == '|' && depth == 0) {
        parts.push_back(r.substr(start, i - start));
        start = i + 1;
      }
    }
    parts.push_back(r.substr(start));
    return parts;
  };
  bool wrapped = false;
  auto parts = split(regex, &wrapped);
  while (parts.size() == 1 && wrapped) {
    regex = regex.substr(1, regex.size() - 2);
    parts = split(regex, &wrapped);
  }
  return parts;
}

/// The topics one alternative (no top-level '|') may match, from its literal prefix.
void add_topics_of_branch(const std::string& branch, std::vector<bool>& possible) {
  // The literal prefix every match must start with: the characters before the first one
  // that is special in an extended regex.
  const std::string special = ".[]()*+?{}|^$\\";
  std::size_t end = 0;
  while (end < branch.size() && special.find(branch[end]) == std::string::npos) ++end;
  std::string prefix = branch.substr(0, end);
  // "AB*" or "AB?" or "AB{0,1}": the B is optional.
  if (end < branch.size() && !prefix.empty() &&
      std::string("*?{").find(branch[end]) != std::string::npos) {
    prefix.pop_back();
  }
  // In the families' order (first match wins): a family whose prefix begins with this prefix
  // is possible; the first whose prefix this prefix begins with decides, and ends the search.
  for (const channels::ChannelFamily& f : channels::kChannelFamilies) {
    const std::string family_prefix = f.prefix;
    if (prefix.rfind(family_prefix, 0) == 0) {
      possible[static_cast<std::size_t>(f.dds_topic)] = true;
      return;
    }
    if (family_prefix.rfind(prefix, 0) == 0) possible[static_cast<std::size_t>(f.dds_topic)] = true;
  }
  // Channels of no family go to the last topic.
  possible[static_cast<std::size_t>(channels::kOtherDdsTopic)] = true;
}

/// Marks the topics a regex may match in possible (alternatives analysed one by one).
void add_topics(const std::string& regex, std::vector<bool>& possible) {
  const std::vector<std::string> parts = top_level_alternatives(regex);
  if (parts.size() > 1) {
    for (const std::string& part : parts) add_topics(part, possible);
  } else if (parts[0].find('|') != std::string::npos) {
    // A nested alternation ("A(B|C)"): not analysed, every topic is possible.
    std::fill(possible.begin(), possible.end(), true);
  } else {
    add_topics_of_branch(parts[0], possible);
  }
}

}  // namespace

std::vector<int> topics_possibly_matching(const std::string& channel_regex) {
  std::vector<bool> possible(static_cast<std::size_t>(kTopics), false);
  add_topics(channel_regex, possible);
  std::vector<int> out;
  for (int t = 0; t < kTopics; ++t) {
    if (possible[static_cast<std::size_t>(t)]) out.push_back(t);
  }
  return out;
}

void check_dds_settings(const DdsSettings& s, bool allow_off_host) {
  const bool secured = !s.security_dir.empty();
  const int max_domain = secured ? kSecuredMaxDomainId : 232;
  if (s.domain_id < 0 || s.domain_id > max_domain) {
    throw TransportError("DDS domain id " + std::to_string(s.domain_id) + " is out of range (0.." +
                         std::to_string(max_domain) + (secured ? " with DDS Security)" : ")"));
  }
  if (s.max_auto_participant_index < 1) {
    throw TransportError("DDS max_auto_participant_index must be >= 1");
  }
  if (!s.config_path.empty()) {
    if (secured) {
      throw TransportError("DDS Security (--dds-security) and a Cyclone configuration file ('" +
                           s.config_path +
                           "') do not go together: put the <Security> section in the file");
    }
    if (access(s.config_path.c_str(), R_OK) != 0) {
      throw TransportError("DDS configuration file '" + s.config_path + "' cannot be read");
    }
    if (!allow_off_host) {
      throw TransportError("refusing DDS configuration file '" + s.config_path +
                           "': it may bind interfaces that leave this host, and DDS here has "
                           "no authentication; pass --allow-off-host to accept it");
    }
    return;
  }
  if (s.peers.empty()) throw TransportError("DDS needs at least one peer (e.g. 127.0.0.1)");
  for (const std::string& peer : s.peers) {
    if (peer.empty() || peer.find_first_of("<>&\"' \t\n") != std::string::npos) {
      throw TransportError("DDS peer '" + peer + "' is not a host name or address");
    }
    if (!is_loopback_peer(peer) && !allow_off_host && !secured) {
      throw TransportError("refusing DDS peer '" + peer +
                           "': traffic to it leaves this host, and DDS here has no "
                           "authentication; pass --allow-off-host to accept it, or secure the "
                           "bus with --dds-security");
    }
  }
}

namespace {

/// The generated configuration, with security_xml (a <Security> element, or "") in its domain.
std::string generated_config_xml(const DdsSettings& s, const std::string& security_xml) {
  bool all_loopback = true;
  for (const std::string& peer : s.peers) all_loopback = all_loopback && is_loopback_peer(peer);
  std::string xml = R"(<CycloneDDS><Domain id="any"><General>)";
  // Off-host peers: Cyclone picks the interface that reaches them.
  if (all_loopback) xml += R"(<Interfaces><NetworkInterface name="lo"/></Interfaces>)";
  xml += "<AllowMulticast>false</AllowMulticast></General><Discovery><Peers>";
  for (const std::string& peer : s.peers) xml += R"(<Peer address=")" + peer + R"("/>)";
  xml += "</Peers><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>" +
         std::to_string(s.max_auto_participant_index) + "</MaxAutoParticipantIndex></Discovery>";
  return xml + security_xml + "</Domain></CycloneDDS>";
}

/// The participant's security files, checked, and its system bus in the governance's domain.
DdsSecurityFiles checked_security_files(const DdsSettings& settings) {
  const DdsSecurityFiles files =
      resolve_dds_security(settings.security_dir, settings.security_identity);
  check_dds_security_files(files);
  // The governance encrypts everything in its system domain only: a system bus in another
  // domain would carry the simulator topics in clear.
  const int system_domain = dds_governance_system_domain(files.governance);
  if (!settings.private_lockstep_bus && settings.domain_id != system_domain) {
    throw TransportError("DDS Security: " + files.governance + " was made for system domain " +
                         std::to_string(system_domain) + ", but this bus is domain " +
                         std::to_string(settings.domain_id) +
                         " (make the PKI with scripts/pki.sh --domain " +
                         std::to_string(settings.domain_id) + ")");
  }
  return files;
}

}  // namespace

std::string dds_default_config_xml(const DdsSettings& s) {
  return generated_config_xml(
      s, s.security_dir.empty()
             ? ""
             : dds_security_config_xml(resolve_dds_security(s.security_dir, s.security_identity)));
}

std::unique_ptr<Transport> make_dds_transport(const DdsSettings& settings, bool allow_off_host) {
  check_dds_settings(settings, allow_off_host);
  // The security files are read and checked once; the configuration names them.
  const std::string security_xml = settings.security_dir.empty()
                                       ? ""
                                       : dds_security_config_xml(checked_security_files(settings));
  const std::string config = settings.config_path.empty()
                                 ? generated_config_xml(settings, security_xml)
                                 : "file://" + settings.config_path;
  return std::make_unique<DdsTransport>(settings, config);
}

}  // namespace auvrl::transport
