#include "fissure/session/split_device.hpp"

#include <cstdio>

#include "fissure/session/session_error.hpp"

namespace fissure::session {

std::unique_ptr<SplitDevice> SplitDevice::open_sim(const std::optional<HandScript>& hand, const Clock& clock) {
  std::unique_ptr<SplitDevice> out(new SplitDevice());
  falcon::SimFalconConfig config;
  config.hand = hand;
  try {
    out->sim_ = std::make_unique<falcon::SimFalcon>(config, clock);
  } catch (const std::exception& e) {
    throw SessionError(std::string("--device sim: ") + e.what());
  }
  return out;
}

std::unique_ptr<SplitDevice> SplitDevice::open_usb(Clock& clock) {
  std::unique_ptr<SplitDevice> out(new SplitDevice());
  out->usb_ = UsbFalcon::open(clock);
  return out;
}

SplitDevice::~SplitDevice() = default;

falcon::HapticDevice& SplitDevice::device() noexcept {
  if (usb_) return usb_->device();
  return *sim_;
}

TimedDevice::TimedDevice(falcon::HapticDevice& inner, const Clock& clock, std::size_t capacity)
    : inner_(inner), clock_(clock), samples_ns_(capacity, 0) {}

falcon::IoStatus TimedDevice::try_exchange(const falcon::DeviceCommand& command, falcon::DeviceReading& reading) noexcept {
  const TimeNs start_ns = clock_.now();
  const falcon::IoStatus status = inner_.try_exchange(command, reading);
  const TimeNs took_ns = clock_.now() - start_ns;
  if (count_ < samples_ns_.size()) samples_ns_[count_] = took_ns;
  ++count_;
  return status;
}

std::string describe_transport(const transport::TransportSpec& spec) {
  switch (spec.kind) {
    case transport::TransportSpec::Kind::kInProcess: return "inproc";
    case transport::TransportSpec::Kind::kCan: return "can:" + spec.can_interface;
    case transport::TransportSpec::Kind::kUdp: return "udp:" + spec.udp_host + ":" + std::to_string(spec.udp_port);
  }
  return "?";
}

std::unique_ptr<transport::FrameCarrier> open_split_carrier(const std::string& text, wire::Role role, const Clock& clock,
                                                            const char* command) {
  transport::TransportSpec spec;
  try {
    spec = transport::parse_transport_spec(text);
  } catch (const transport::TransportError& e) {
    throw SessionError(std::string("--transport: ") + e.what(), true);
  }
  if (spec.kind == transport::TransportSpec::Kind::kInProcess) {
    throw SessionError(std::string("--transport inproc: '") + command +
                           "' is one end of a split deployment and needs can:IFACE or udp:HOST:PORT "
                           "(for rt_core and the host in one process run 'fissure run SCENE')",
                       2);
  }
  try {
    return transport::open_carrier(spec, role, clock);
  } catch (const transport::TransportError& e) {
    throw SessionError(std::string("--transport ") + describe_transport(spec) + ": " + e.what());
  }
}

}  // namespace fissure::session
