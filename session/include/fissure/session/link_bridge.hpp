#pragma once
// The link bridge of a split deployment (docs/deployment.md): it pumps between the
// in-process exchanges rt_core and the host already use (DeviceStateExchange,
// ProxyExchange) and a wire LinkEndpoint (shared/wire_link.hpp). It runs on a non-RT
// service thread (or the host's own loop), so the rt tick never touches a socket and neither
// rt_core nor SessionHost can tell a split deployment from the in-process one.
//   rt end:   DeviceState  rt_core → exchange → bridge → wire;  ContactProxy wire → bridge → exchange → rt_core
//   host end: DeviceState  wire → bridge → exchange → SessionHost;  ContactProxy SessionHost → exchange → bridge → wire
// Peer death: the rt end needs nothing from the bridge — no proxy is forwarded, rt_core's
// staleness stage fades the force to zero (ProxyConfig: stale 0.1 s + fade 0.05 s). The host
// end asks peer_silent() before each step and pauses the scene while rt_core is silent.
// While the peer is silent the bridge keeps announcing itself (a Hello every hello period):
// the LinkEndpoint stops sending Hellos once acknowledged, and a paused host sends no data,
// so without this a restarted rt end (UDP: it binds and answers whoever talks to it) would
// never learn the host's address and the link would not come back.
// pump_*() are noexcept and allocation-free (the LinkEndpoint is), so a bridge could share a
// thread with anything.
#include <cstdint>
#include <string>

#include "fissure/rt_core/proxy_intake.hpp"
#include "fissure/rt_core/tick.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"
#include "fissure/shared/wire_link.hpp"

namespace fissure::session {

/// The host declares rt_core silent after this long without a DeviceState [ns]. rt_core
/// publishes one per tick (≥ 500 Hz), so 50 ms is ≥ 25 lost samples in a row — a dropped
/// datagram never trips it — and it is half the rt side's 100 ms proxy stale bound, so the
/// host pauses before rt_core would fade a proxy the host is still computing.
inline constexpr TimeNs kRtSilentAfter_ns = 50'000'000;
/// The rt end reports the host silent after this long without a proxy [ns]: rt_core's own
/// stale bound (rt::ProxyConfig::stale_after_s = 0.1 s), which is when the fade starts.
inline constexpr TimeNs kHostSilentAfter_ns = 100'000'000;

/// A bridge's view of its link (what the status lines print; docs/deployment.md explains each).
struct BridgeStatus {
  bool established = false;        ///< handshake done with a peer of the same protocol version
  bool failed = false;             ///< handshake refused the peer (version mismatch, role conflict)
  const char* error = "";          ///< the handshake's one-line error when failed
  TimeNs peer_data_age_ns = transport::kNeverReceived;  ///< host end: DeviceState age; rt end: proxy age
  bool peer_silent = true;         ///< no peer data within the silence bound (or never any)
  bool peer_closed = false;        ///< the peer said goodbye: it stopped cleanly (not a crash or a cut link)
  std::uint64_t messages_in = 0;   ///< whole data messages received and forwarded
  std::uint64_t messages_out = 0;  ///< data messages published to the wire
  std::uint64_t frames_discarded = 0;    ///< reassembler frame-level discards
  std::uint64_t messages_discarded = 0;  ///< reassembler message-level discards + data before handshake
  std::uint64_t peer_restarts = 0;       ///< the peer came back with a new session id
  std::uint64_t carrier_errors = 0;      ///< send + receive failures the carrier reported
  std::uint64_t announcements = 0;       ///< Hellos sent while the established peer was silent
};

class LinkBridge {
 public:
  /// `carrier` and `clock` must outlive the bridge. `peer_silent_after_ns`: kRtSilentAfter_ns
  /// on the host end, kHostSilentAfter_ns on the rt end.
  LinkBridge(transport::FrameCarrier& carrier, const Clock& clock, const transport::LinkConfig& config,
             TimeNs peer_silent_after_ns) noexcept;
  LinkBridge(const LinkBridge&) = delete;
  LinkBridge& operator=(const LinkBridge&) = delete;

  /// rt end, one pump: the newest DeviceState rt_core published goes to the wire; the newest
  /// whole proxy from the wire goes to rt_core, renumbered so that its sequence keeps
  /// increasing across a host restart (rt_core ignores a proxy not newer than the one it has).
  void pump_rt(DeviceStateExchange& from_rt, ProxyExchange& to_rt) noexcept;
  /// host end, one pump: the newest DeviceState from the wire goes to the host; the newest
  /// proxy the host published goes to the wire.
  void pump_host(DeviceStateExchange& to_host, ProxyExchange& from_host) noexcept;

  /// Says goodbye to the peer (a closing Hello, kGoodbyeRepeats times): call it when this end
  /// stops cleanly, on the thread that pumps the bridge (or after it has stopped).
  void close() noexcept;
  /// A lost datagram must not turn a clean exit into a "lost link" report at the peer.
  static constexpr int kGoodbyeRepeats = 3;

  [[nodiscard]] BridgeStatus status() const noexcept;
  [[nodiscard]] bool established() const noexcept { return endpoint_.established(); }
  [[nodiscard]] bool failed() const noexcept { return endpoint_.handshake().state() == wire::HandshakeState::kFailed; }
  /// True when the peer's data is older than the silence bound (or never came).
  [[nodiscard]] bool peer_silent() const noexcept;
  [[nodiscard]] TimeNs peer_data_age_ns() const noexcept;
  /// rt end: rt_core's proxy sequence − the host's, for the current host session (0 until a
  /// host restart; the HIL benchmark maps rt_core's telemetry back to host steps with it).
  [[nodiscard]] std::int64_t sequence_offset() const noexcept { return sequence_offset_; }
  [[nodiscard]] const transport::LinkEndpoint& endpoint() const noexcept { return endpoint_; }

 private:
  void note_restart() noexcept;
  void announce_while_silent() noexcept;

  const Clock& clock_;
  wire::Role role_;
  TimeNs peer_silent_after_ns_;
  TimeNs hello_period_ns_;
  transport::LinkEndpoint endpoint_;
  transport::LinkSender announcer_;  ///< Hellos while the peer is silent (the endpoint has stopped)
  TimeNs last_announce_ns_ = 0;
  std::uint64_t announcements_ = 0;
  std::uint64_t messages_in_ = 0;
  std::uint64_t messages_out_ = 0;
  std::uint64_t peer_restarts_ = 0;
  std::uint32_t last_peer_session_ = 0;
  bool have_peer_session_ = false;
  // rt end: forwarded sequence = host sequence + offset; the offset grows when a restarted
  // host starts counting from 1 again, so rt_core always sees increasing sequences.
  std::int64_t sequence_offset_ = 0;
  std::uint64_t last_forwarded_sequence_ = 0;
  std::uint64_t last_host_sequence_ = 0;
  DeviceState state_scratch_{};
  ContactProxy proxy_scratch_{};
};

/// One status-line fragment, e.g. "link up | device-state age 1.2 ms | in 950 out 80 | discards 0/0".
std::string format_bridge_status(const BridgeStatus& status, wire::Role role);

/// A session id for this process start (the handshake's restart detection): random, non-zero.
std::uint32_t fresh_session_id();

}  // namespace fissure::session
