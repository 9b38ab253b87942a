#include "fissure/shared/transport_spec.hpp"

#include <charconv>

#include "fissure/shared/socketcan_carrier.hpp"
#include "fissure/shared/udp_carrier.hpp"

namespace fissure::transport {
namespace {

[[noreturn]] void bad_spec(std::string_view text, const std::string& why) {
  throw TransportError(TransportError::Kind::kConfiguration,
                       "transport '" + std::string(text) + "': " + why + " (expected inproc, can:IFACE or udp:HOST:PORT)");
}

}  // namespace

TransportSpec parse_transport_spec(std::string_view text) {
  TransportSpec spec;
  if (text == "inproc") return spec;
  if (text.starts_with("can:")) {
    spec.kind = TransportSpec::Kind::kCan;
    spec.can_interface = std::string(text.substr(4));
    if (spec.can_interface.empty()) bad_spec(text, "no CAN interface named");
    return spec;
  }
  if (text.starts_with("udp:")) {
    const std::string_view rest = text.substr(4);
    const std::size_t colon = rest.rfind(':');
    if (colon == std::string_view::npos || colon == 0) bad_spec(text, "missing HOST or PORT");
    const std::string_view port_text = rest.substr(colon + 1);
    unsigned port = 0;
    const auto [end, error] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
    if (error != std::errc{} || end != port_text.data() + port_text.size() || port == 0 || port > 65535) {
      bad_spec(text, "port '" + std::string(port_text) + "' is not 1…65535");
    }
    spec.kind = TransportSpec::Kind::kUdp;
    spec.udp_host = std::string(rest.substr(0, colon));
    spec.udp_port = static_cast<std::uint16_t>(port);
    return spec;
  }
  bad_spec(text, "unknown transport");
}

std::unique_ptr<FrameCarrier> open_carrier(const TransportSpec& spec, wire::Role role, const Clock& clock) {
  switch (spec.kind) {
    case TransportSpec::Kind::kCan: return std::make_unique<SocketCanCarrier>(spec.can_interface, clock);
    case TransportSpec::Kind::kUdp: {
      UdpCarrierConfig config;
      if (role == wire::Role::kRt) {
        config.local_address = spec.udp_host;
        config.local_port = spec.udp_port;
      } else {
        config.local_address = "0.0.0.0";
        config.local_port = 0;
        config.remote_address = spec.udp_host;
        config.remote_port = spec.udp_port;
      }
      return std::make_unique<UdpCarrier>(config, clock);
    }
    case TransportSpec::Kind::kInProcess: break;
  }
  throw TransportError(TransportError::Kind::kConfiguration,
                       "transport 'inproc' has no carrier: both halves share the in-process exchange");
}

}  // namespace fissure::transport
