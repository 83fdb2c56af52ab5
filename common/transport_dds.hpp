// The Cyclone DDS implementation of the common Transport: the same LCM-encoded bytes on the same
// channel names, carried as auvrl_dds::Message {channel (key), data} samples (see
// common/dds/auvrl_message.idl) on one DDS topic per channel class (common/channels.hpp), each
// with the QoS its class needs:
//   auvrl_state     policy weights and summary: reliable, keep-last-1 per channel,
//                   transient-local (a late joiner gets the newest at once, without asking)
//   auvrl_queue     experience, episodes, weights requests: reliable, keep-all with bounded
//                   reader history, so a reader that falls behind makes the writer wait
//                   (back-pressure up to kDdsQueueMaxBlocking) instead of losing
//   auvrl_lockstep  simulator commands and states: reliable (or best effort), keep-last
//   auvrl_other     heartbeats, statistics: reliable, keep-last
// A subscription gets one reader per class its regex may match; the full-match POSIX regex is
// applied as a reader-side filter (non-matching samples never enter its history, so
// queue_capacity counts only its own channels). Everything runs on the caller's thread except
// Cyclone's own receive threads; as for LCM, one thread handles a transport.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "common/channels.hpp"
#include "common/transport.hpp"

namespace auvrl::transport {

/// How long a queue-class publish may wait for a slow reader before it fails (back-pressure).
/// Longer than Cyclone's participant lease (10 s): a reader whose process was killed holds the
/// writer until its lease expires and it is dropped; the publish then goes on instead of
/// failing.
inline constexpr std::chrono::milliseconds kDdsQueueMaxBlocking{15000};

/// Opens a Cyclone DDS transport (one participant in settings.domain_id). Throws
/// TransportError for a refused or broken configuration or when DDS cannot start.
std::unique_ptr<Transport> make_dds_transport(const DdsSettings& settings, bool allow_off_host);

/// Throws TransportError if the settings could send traffic off this host (a peer that is not
/// a loopback address, or a configuration file) and allow_off_host is false; also for settings
/// that cannot be used (domain id out of range, no peers, a peer name with XML characters).
void check_dds_settings(const DdsSettings& settings, bool allow_off_host);

/// The Cyclone configuration generated for settings without a config_path (XML, for
/// dds_create_domain): interface lo when every peer is loopback, multicast off, the peers,
/// participant index auto up to settings.max_auto_participant_index.
std::string dds_default_config_xml(const DdsSettings& settings);

/// The topics (indices into channels::kDdsTopics) that a channel matching the full-match regex
/// may be carried on: a superset, decided from the regex's literal prefix (".*" gives all,
/// "SIM_CMD_[0-9]+" only auvrl_sim_command). A subscription reads only these topics.
std::vector<int> topics_possibly_matching(const std::string& channel_regex);

}  // namespace auvrl::transport
