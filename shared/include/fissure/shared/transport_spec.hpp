#pragma once
// The `--transport` option both commands take: `inproc`, `can:IFACE`,
// `udp:HOST:PORT`. One convention for UDP on both ends: HOST:PORT is the rt box's address.
// The rt end binds it and answers whoever talks to it; the host end binds an ephemeral port
// and sends to it. Setup-time code: may allocate and throws TransportError.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"
#include "fissure/shared/wire_codec.hpp"

namespace fissure::transport {

struct TransportSpec {
  enum class Kind : std::uint8_t { kInProcess, kCan, kUdp };
  Kind kind = Kind::kInProcess;
  std::string can_interface;  ///< kCan
  std::string udp_host;       ///< kUdp: the rt box's address
  std::uint16_t udp_port = 0; ///< kUdp
};

/// Parses `inproc`, `can:IFACE` or `udp:HOST:PORT`; throws TransportError (kConfiguration)
/// quoting the text and the expected forms.
TransportSpec parse_transport_spec(std::string_view text);

/// Opens the carrier a split deployment's `role` end uses for `spec` (kCan or kUdp; kInProcess
/// has no carrier and throws). Errors are TransportError naming the interface / address.
std::unique_ptr<FrameCarrier> open_carrier(const TransportSpec& spec, wire::Role role, const Clock& clock);

}  // namespace fissure::transport
