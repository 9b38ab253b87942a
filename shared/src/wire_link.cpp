#include "fissure/shared/wire_link.hpp"

namespace fissure::transport {

// ---- LinkSender ------------------------------------------------------------------------

template <typename Message>
wire::EncodeStatus LinkSender::enqueue(Lane& lane, const Message& message) noexcept {
  ++stats_.messages_published;
  const bool in_flight = lane.next_frame > 0 && lane.next_frame < lane.current.count;
  const bool queued_unstarted = lane.next_frame == 0 && lane.current.count > 0;
  wire::EncodeStatus status = wire::EncodeStatus::kOk;
  if (in_flight) {
    // Finish the message on the wire (a half-sent one is worthless to the receiver); the
    // new one waits, replacing any older waiting one.
    status = wire::encode(message, lane.transfer_id, lane.waiting);
    if (status == wire::EncodeStatus::kOk) {
      if (lane.has_waiting) ++stats_.messages_skipped;
      lane.has_waiting = true;
    }
  } else if (queued_unstarted) {
    // Nothing of the queued one went out: replace it, reusing its transfer id.
    status = wire::encode(message, static_cast<std::uint8_t>(lane.transfer_id - 1u), lane.current);
    if (status == wire::EncodeStatus::kOk) ++stats_.messages_skipped;
  } else {
    status = wire::encode(message, lane.transfer_id, lane.current);
    if (status == wire::EncodeStatus::kOk) {
      lane.next_frame = 0;
      ++lane.transfer_id;
    }
  }
  if (status != wire::EncodeStatus::kOk) ++stats_.encode_errors;
  return status;
}

wire::EncodeStatus LinkSender::publish(const DeviceState& state) noexcept { return enqueue(lanes_[kDeviceStateLane], state); }
wire::EncodeStatus LinkSender::publish(const ContactProxy& proxy) noexcept { return enqueue(lanes_[kProxyLane], proxy); }
wire::EncodeStatus LinkSender::publish(const wire::Hello& hello) noexcept { return enqueue(lanes_[kHelloLane], hello); }

std::size_t LinkSender::service() noexcept {
  std::size_t sent = 0;
  for (Lane& lane : lanes_) {
    while (true) {
      if (lane.next_frame >= lane.current.count) {
        if (!lane.has_waiting) break;
        lane.current = lane.waiting;
        lane.has_waiting = false;
        lane.next_frame = 0;
        ++lane.transfer_id;
      }
      const CarrierStatus status = carrier_.try_send(lane.current.frames[lane.next_frame]);
      if (status == CarrierStatus::kBusy) {
        ++stats_.carrier_busy;
        return sent;
      }
      if (status != CarrierStatus::kOk) {
        // The receiver cannot complete this message any more: drop its remaining frames.
        ++stats_.messages_send_failed;
        lane.next_frame = lane.current.count;
        continue;
      }
      ++sent;
      ++stats_.frames_sent;
      if (++lane.next_frame == lane.current.count) ++stats_.messages_sent;
    }
  }
  return sent;
}

bool LinkSender::idle() const noexcept {
  for (const Lane& lane : lanes_) {
    if (lane.next_frame < lane.current.count || lane.has_waiting) return false;
  }
  return true;
}

// ---- LinkReceiver ----------------------------------------------------------------------

LinkPollResult LinkReceiver::poll() noexcept {
  LinkPollResult result;
  // Time out lost segments even when nothing arrives (a dead link still ages its assemblies).
  reassembler_.expire(clock_.now());
  for (std::size_t i = 0; i < config_.max_frames_per_poll; ++i) {
    ReceivedFrame received;
    const CarrierStatus status = carrier_.try_receive(received);
    if (status == CarrierStatus::kEmpty) break;
    if (status != CarrierStatus::kOk) {
      ++stats_.carrier_errors;
      break;
    }
    ++result.frames;
    const TimeNs now_ns = clock_.now();
    switch (reassembler_.push(received.frame, now_ns)) {
      case wire::MessageType::kHello:
        result.new_hello = true;
        if (handshake_ != nullptr) {
          last_hello_event_ = handshake_->on_hello(reassembler_.hello());
          // A restarted peer counts its sequence numbers from the start again.
          if (last_hello_event_.peer_restarted && last_hello_event_.established) reassembler_.reset_sequences();
        }
        break;
      case wire::MessageType::kDeviceState:
        if (!data_allowed()) {
          ++stats_.data_before_handshake;
          break;
        }
        latest_device_state_ = reassembler_.device_state();
        device_state_untaken_ = true;
        device_state_received_ns_ = now_ns;
        result.new_device_state = true;
        break;
      case wire::MessageType::kContactProxy:
        if (!data_allowed()) {
          ++stats_.data_before_handshake;
          break;
        }
        latest_proxy_ = reassembler_.contact_proxy();
        proxy_untaken_ = true;
        proxy_received_ns_ = now_ns;
        result.new_proxy = true;
        break;
      case wire::MessageType::kNone: break;
    }
  }
  return result;
}

bool LinkReceiver::try_take_proxy(ContactProxy& out) noexcept {
  if (!proxy_untaken_) return false;
  out = latest_proxy_;
  proxy_untaken_ = false;
  return true;
}

bool LinkReceiver::try_take_device_state(DeviceState& out) noexcept {
  if (!device_state_untaken_) return false;
  out = latest_device_state_;
  device_state_untaken_ = false;
  return true;
}

// ---- LinkEndpoint ----------------------------------------------------------------------

LinkEndpoint::LinkEndpoint(FrameCarrier& carrier, const Clock& clock, const LinkConfig& config) noexcept
    : clock_(clock),
      config_(config),
      handshake_(config.role, config.publish_rate_hz, config.session_id, config.identity),
      sender_(carrier),
      receiver_(carrier, clock, &handshake_, config.receiver) {}

void LinkEndpoint::close() noexcept {
  sender_.publish(handshake_.hello(true));
  sender_.service();
}

LinkPollResult LinkEndpoint::tick() noexcept {
  const LinkPollResult result = receiver_.poll();
  const TimeNs now_ns = clock_.now();
  const bool repeat_due = !hello_ever_sent_ || now_ns - last_hello_sent_ns_ >= config_.hello_period_ns;
  const bool still_introducing = !established() || !handshake_.peer_acknowledged();
  const bool reply_due = result.new_hello && receiver_.last_hello_event().reply_needed;
  if (reply_due || (still_introducing && repeat_due)) {
    sender_.publish(handshake_.hello());
    last_hello_sent_ns_ = now_ns;
    hello_ever_sent_ = true;
  }
  sender_.service();
  return result;
}

}  // namespace fissure::transport
