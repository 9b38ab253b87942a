#include "fissure/session/link_bridge.hpp"

#include <cstdio>
#include <random>

namespace fissure::session {

LinkBridge::LinkBridge(transport::FrameCarrier& carrier, const Clock& clock, const transport::LinkConfig& config,
                       TimeNs peer_silent_after_ns) noexcept
    : clock_(clock),
      role_(config.role),
      peer_silent_after_ns_(peer_silent_after_ns),
      hello_period_ns_(config.hello_period_ns),
      endpoint_(carrier, clock, config),
      announcer_(carrier) {}

void LinkBridge::announce_while_silent() noexcept {
  if (!endpoint_.established() || !peer_silent()) return;
  const TimeNs now_ns = clock_.now();
  if (announcements_ != 0 && now_ns - last_announce_ns_ < hello_period_ns_) return;
  // Hellos are one frame and not tracked by transfer id, so a second sender on the carrier
  // cannot confuse the peer's reassembly of the endpoint's messages.
  announcer_.publish(endpoint_.handshake().hello());
  announcer_.service();
  last_announce_ns_ = now_ns;
  ++announcements_;
}

void LinkBridge::note_restart() noexcept {
  if (!endpoint_.established()) return;
  const std::uint32_t session = endpoint_.handshake().peer().session_id;
  if (have_peer_session_ && session != last_peer_session_) ++peer_restarts_;
  last_peer_session_ = session;
  have_peer_session_ = true;
}

void LinkBridge::pump_rt(DeviceStateExchange& from_rt, ProxyExchange& to_rt) noexcept {
  // Receive first, so a proxy that arrived is handed to rt_core before we spend time sending.
  endpoint_.tick();
  note_restart();
  if (endpoint_.receiver().try_take_proxy(proxy_scratch_)) {
    const std::uint64_t host_sequence = proxy_scratch_.sequence;
    // Within one host session the reassembler only lets newer sequences through, so a
    // sequence that is not newer means the host restarted and counts from 1 again.
    if (last_forwarded_sequence_ != 0 && host_sequence <= last_host_sequence_) {
      sequence_offset_ = static_cast<std::int64_t>(last_forwarded_sequence_) + 1 - static_cast<std::int64_t>(host_sequence);
    }
    last_host_sequence_ = host_sequence;
    proxy_scratch_.sequence = static_cast<std::uint64_t>(static_cast<std::int64_t>(host_sequence) + sequence_offset_);
    last_forwarded_sequence_ = proxy_scratch_.sequence;
    to_rt.publish(proxy_scratch_);
    ++messages_in_;
  }
  if (from_rt.try_fetch(state_scratch_) && endpoint_.established()) {
    if (endpoint_.publish(state_scratch_) == wire::EncodeStatus::kOk) ++messages_out_;
  }
  // Send in the same pump what was just queued (tick() sent before the publish).
  endpoint_.tick();
  announce_while_silent();
}

void LinkBridge::pump_host(DeviceStateExchange& to_host, ProxyExchange& from_host) noexcept {
  endpoint_.tick();
  note_restart();
  if (endpoint_.receiver().try_take_device_state(state_scratch_)) {
    to_host.publish(state_scratch_);
    ++messages_in_;
  }
  if (from_host.try_fetch(proxy_scratch_) && endpoint_.established()) {
    if (endpoint_.publish(proxy_scratch_) == wire::EncodeStatus::kOk) ++messages_out_;
  }
  endpoint_.tick();
  announce_while_silent();
}

void LinkBridge::close() noexcept {
  for (int i = 0; i < kGoodbyeRepeats; ++i) endpoint_.close();
}

TimeNs LinkBridge::peer_data_age_ns() const noexcept {
  const transport::LinkReceiver& receiver = endpoint_.receiver();
  return role_ == wire::Role::kHost ? receiver.device_state_age_ns() : receiver.proxy_age_ns();
}

bool LinkBridge::peer_silent() const noexcept { return peer_data_age_ns() > peer_silent_after_ns_; }

BridgeStatus LinkBridge::status() const noexcept {
  BridgeStatus out;
  out.established = endpoint_.established();
  out.failed = failed();
  out.error = endpoint_.handshake().error_message();
  out.peer_data_age_ns = peer_data_age_ns();
  out.peer_silent = peer_silent();
  out.peer_closed = endpoint_.handshake().peer_closed();
  out.messages_in = messages_in_;
  out.messages_out = messages_out_;
  const wire::WireStats& wire_stats = endpoint_.receiver().wire_stats();
  out.frames_discarded = wire_stats.frames_discarded();
  out.messages_discarded = wire_stats.messages_discarded() + endpoint_.receiver().stats().data_before_handshake;
  out.peer_restarts = peer_restarts_;
  out.carrier_errors = endpoint_.receiver().stats().carrier_errors + endpoint_.sender().stats().messages_send_failed;
  out.announcements = announcements_;
  return out;
}

std::string format_bridge_status(const BridgeStatus& status, wire::Role role) {
  const char* age_name = role == wire::Role::kHost ? "device-state age" : "proxy age";
  char age[48];
  if (status.peer_data_age_ns == transport::kNeverReceived) {
    std::snprintf(age, sizeof age, "none yet");
  } else {
    std::snprintf(age, sizeof age, "%.1f ms", to_seconds(status.peer_data_age_ns) * 1e3);
  }
  // A handshake once done is not a live link: a silent peer (dead, or cut off) is "link lost".
  const char* link = status.failed                               ? "link REFUSED"
                     : !status.established                       ? "link waiting"
                     : status.peer_closed                        ? "link closed by the peer"
                     : status.peer_silent                        ? "link LOST"
                                                                 : "link up";
  char line[256];
  std::snprintf(line, sizeof line, "%s | %s %s%s | in %llu out %llu | discards %llu frames / %llu msgs | restarts %llu",
                link, age_name, age, status.established && status.peer_silent && !status.peer_closed ? " (peer silent)" : "",
                static_cast<unsigned long long>(status.messages_in), static_cast<unsigned long long>(status.messages_out),
                static_cast<unsigned long long>(status.frames_discarded),
                static_cast<unsigned long long>(status.messages_discarded),
                static_cast<unsigned long long>(status.peer_restarts));
  return line;
}

std::uint32_t fresh_session_id() {
  std::random_device device;
  std::uint32_t id = 0;
  while (id == 0) id = device();
  return id;
}

}  // namespace fissure::session
