#pragma once
// Link-level helpers both ends use over any FrameCarrier:
//   LinkSender   — publish the newest DeviceState / ContactProxy; frames go out as the
//                  carrier accepts them (a message in flight is finished, anything older
//                  than the newest waiting one is skipped: newest wins).
//   LinkReceiver — drains the carrier through the Reassembler and keeps the newest whole
//                  message of each type (ready for LatestValueExchange::publish) and the age
//                  of the last good one: the rt side fades a stale proxy, the host notices
//                  rt_core death.
//   LinkEndpoint — sender + receiver + Handshake: Hellos until the peer acknowledged,
//                  data accepted only from a peer of the same protocol version.
// Everything is non-blocking, noexcept and allocation-free; time comes from fissure::Clock.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"
#include "fissure/shared/wire_codec.hpp"
#include "fissure/shared/wire_handshake.hpp"
#include "fissure/shared/wire_reassembler.hpp"

namespace fissure::transport {

/// Age reported before any message of that type arrived.
inline constexpr TimeNs kNeverReceived = std::numeric_limits<TimeNs>::max();

struct LinkSenderStats {
  std::uint64_t messages_published = 0;
  std::uint64_t messages_sent = 0;        ///< every frame accepted by the carrier
  std::uint64_t messages_skipped = 0;     ///< replaced by a newer one before their first frame went out
  std::uint64_t messages_send_failed = 0; ///< carrier error mid-message: the rest was dropped
  std::uint64_t frames_sent = 0;
  std::uint64_t carrier_busy = 0;         ///< service() stopped because the carrier was full
  std::uint64_t encode_errors = 0;
};

class LinkSender {
 public:
  explicit LinkSender(FrameCarrier& carrier) noexcept : carrier_(carrier) {}

  /// Queues the message as the newest of its type (replacing a queued one not yet started).
  /// Nothing is sent until service().
  wire::EncodeStatus publish(const DeviceState& state) noexcept;
  wire::EncodeStatus publish(const ContactProxy& proxy) noexcept;
  wire::EncodeStatus publish(const wire::Hello& hello) noexcept;

  /// Sends queued frames (Hello, then DeviceState, then ContactProxy: the CAN id priority)
  /// until the carrier reports kBusy or nothing is left. Returns the frames sent.
  std::size_t service() noexcept;
  [[nodiscard]] bool idle() const noexcept;
  [[nodiscard]] const LinkSenderStats& stats() const noexcept { return stats_; }

 private:
  struct Lane {
    wire::FrameBatch current{};
    std::size_t next_frame = 0;  ///< == current.count when nothing is in flight
    wire::FrameBatch waiting{};
    bool has_waiting = false;
    std::uint8_t transfer_id = 0;  ///< id the next message put in flight gets
  };
  enum LaneIndex : std::size_t { kHelloLane = 0, kDeviceStateLane = 1, kProxyLane = 2 };

  template <typename Message>
  wire::EncodeStatus enqueue(Lane& lane, const Message& message) noexcept;

  FrameCarrier& carrier_;
  std::array<Lane, 3> lanes_{};
  LinkSenderStats stats_{};
};

struct LinkReceiverConfig {
  /// Frames taken per poll(): bounds the time poll() spends on the rt tick. 64 frames are
  /// six full proxies, far more than a 1/5 Mbit/s bus delivers in one 1 ms tick (~7 frames).
  std::size_t max_frames_per_poll = 64;
  wire::ReassemblerConfig reassembler{};
};

struct LinkPollResult {
  std::size_t frames = 0;
  bool new_device_state = false;
  bool new_proxy = false;
  bool new_hello = false;
};

struct LinkReceiverStats {
  std::uint64_t data_before_handshake = 0;  ///< whole messages ignored: no compatible Hello yet
  std::uint64_t carrier_errors = 0;         ///< try_receive returned kError / kBusOff
};

class LinkReceiver {
 public:
  /// With a `handshake`, Hellos are judged as they arrive (a restarted peer resets the
  /// sequence tracking before its next data frame is read) and data is accepted only while
  /// it is established. Without one, every good message is accepted.
  LinkReceiver(FrameCarrier& carrier, const Clock& clock, wire::Handshake* handshake = nullptr,
               LinkReceiverConfig config = {}) noexcept
      : carrier_(carrier), clock_(clock), handshake_(handshake), config_(config), reassembler_(config.reassembler) {}

  LinkPollResult poll() noexcept;

  /// Newest whole proxy not yet taken. False (out untouched) when none arrived since.
  bool try_take_proxy(ContactProxy& out) noexcept;
  bool try_take_device_state(DeviceState& out) noexcept;
  [[nodiscard]] bool has_proxy() const noexcept { return proxy_received_ns_ != kNeverReceived; }
  [[nodiscard]] const ContactProxy& latest_proxy() const noexcept { return latest_proxy_; }
  [[nodiscard]] const DeviceState& latest_device_state() const noexcept { return latest_device_state_; }

  /// clock.now() − when the last good message of that type was received; kNeverReceived if none.
  [[nodiscard]] TimeNs proxy_age_ns() const noexcept { return age_since(proxy_received_ns_); }
  [[nodiscard]] TimeNs device_state_age_ns() const noexcept { return age_since(device_state_received_ns_); }
  /// True while the last good message of that type is at most `bound_ns` old.
  [[nodiscard]] bool proxy_fresh(TimeNs bound_ns) const noexcept { return proxy_age_ns() <= bound_ns; }
  [[nodiscard]] bool device_state_fresh(TimeNs bound_ns) const noexcept { return device_state_age_ns() <= bound_ns; }

  [[nodiscard]] const wire::Reassembler& reassembler() const noexcept { return reassembler_; }
  [[nodiscard]] const wire::WireStats& wire_stats() const noexcept { return reassembler_.stats(); }
  [[nodiscard]] const LinkReceiverStats& stats() const noexcept { return stats_; }
  /// The last Hello event (for LinkEndpoint: whether a reply is due).
  [[nodiscard]] const wire::HandshakeEvent& last_hello_event() const noexcept { return last_hello_event_; }

 private:
  [[nodiscard]] TimeNs age_since(TimeNs received_ns) const noexcept {
    return received_ns == kNeverReceived ? kNeverReceived : clock_.now() - received_ns;
  }
  bool data_allowed() const noexcept {
    return handshake_ == nullptr || handshake_->state() == wire::HandshakeState::kEstablished;
  }

  FrameCarrier& carrier_;
  const Clock& clock_;
  wire::Handshake* handshake_;
  LinkReceiverConfig config_;
  wire::Reassembler reassembler_;
  LinkReceiverStats stats_{};
  wire::HandshakeEvent last_hello_event_{};
  ContactProxy latest_proxy_{};
  DeviceState latest_device_state_{};
  bool proxy_untaken_ = false;
  bool device_state_untaken_ = false;
  TimeNs proxy_received_ns_ = kNeverReceived;
  TimeNs device_state_received_ns_ = kNeverReceived;
};

struct LinkConfig {
  wire::Role role = wire::Role::kRt;
  float publish_rate_hz = 1000.0f;  ///< announced in the Hello (informative)
  std::uint32_t session_id = 1;     ///< pick a fresh random value per process start
  /// Hello repeat period until the peer acknowledged. 100 ms: a restart is noticed within a
  /// tenth of a second; ten 20-byte Hello frames a second use < 0.1 % of a 1/5 Mbit/s bus.
  TimeNs hello_period_ns = 100'000'000;
  LinkReceiverConfig receiver{};
  /// What this end runs (wire::session_identity); the handshake refuses a peer running another.
  wire::SessionIdentity identity{};
};

class LinkEndpoint {
 public:
  LinkEndpoint(FrameCarrier& carrier, const Clock& clock, const LinkConfig& config) noexcept;
  LinkEndpoint(const LinkEndpoint&) = delete;
  LinkEndpoint& operator=(const LinkEndpoint&) = delete;

  /// One non-blocking step: receive (bounded), repeat or answer Hellos, send queued frames.
  LinkPollResult tick() noexcept;

  wire::EncodeStatus publish(const DeviceState& state) noexcept { return sender_.publish(state); }
  wire::EncodeStatus publish(const ContactProxy& proxy) noexcept { return sender_.publish(proxy); }

  /// Says goodbye: a Hello with kHelloClosing, sent now (call it when stopping cleanly, so the
  /// peer reports "closed by the peer" instead of a lost link). Best effort, like every frame.
  void close() noexcept;

  [[nodiscard]] bool established() const noexcept { return handshake_.state() == wire::HandshakeState::kEstablished; }
  [[nodiscard]] const wire::Handshake& handshake() const noexcept { return handshake_; }
  LinkReceiver& receiver() noexcept { return receiver_; }
  [[nodiscard]] const LinkReceiver& receiver() const noexcept { return receiver_; }
  [[nodiscard]] const LinkSender& sender() const noexcept { return sender_; }

 private:
  const Clock& clock_;
  LinkConfig config_;
  wire::Handshake handshake_;
  LinkSender sender_;
  LinkReceiver receiver_;
  TimeNs last_hello_sent_ns_ = 0;
  bool hello_ever_sent_ = false;
};

}  // namespace fissure::transport
