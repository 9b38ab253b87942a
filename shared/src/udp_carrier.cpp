#include "fissure/shared/udp_carrier.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

namespace fissure::transport {
namespace {

/// Largest datagram we accept plus one byte, so an oversized datagram shows up as too long.
constexpr std::size_t kDatagramBufferBytes = kUdpFrameHeaderBytes + wire::kCanFdMaxDataBytes + 1;
/// try_receive skips at most this many malformed datagrams per call: bounded time on the rt tick.
constexpr int kMaxSkippedDatagramsPerReceive = 16;

std::string describe(const std::string& address, std::uint16_t port) {
  return address + ":" + std::to_string(port);
}

sockaddr_in resolve(const std::string& address, std::uint16_t port, const char* what) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* result = nullptr;
  const int rc = getaddrinfo(address.c_str(), nullptr, &hints, &result);
  if (rc != 0 || result == nullptr) {
    throw TransportError(TransportError::Kind::kConfiguration,
                         std::string("UDP ") + what + " address '" + address + "' does not resolve: " + gai_strerror(rc));
  }
  sockaddr_in resolved{};
  std::memcpy(&resolved, result->ai_addr, sizeof resolved);
  freeaddrinfo(result);
  resolved.sin_port = htons(port);
  return resolved;
}

}  // namespace

std::size_t pack_udp_frame(const CanFdFrame& frame, std::uint8_t* out) noexcept {
  const std::size_t length = std::min<std::size_t>(frame.length, wire::kCanFdMaxDataBytes);
  for (int i = 0; i < 4; ++i) out[i] = static_cast<std::uint8_t>(frame.can_id >> (8 * i));
  out[4] = static_cast<std::uint8_t>(length);
  out[5] = frame.flags;
  out[6] = 0;
  out[7] = 0;
  std::memcpy(out + kUdpFrameHeaderBytes, frame.data.data(), length);
  return kUdpFrameHeaderBytes + length;
}

bool unpack_udp_frame(const std::uint8_t* datagram, std::size_t size, CanFdFrame& out) noexcept {
  if (size < kUdpFrameHeaderBytes) return false;
  const std::size_t length = datagram[4];
  if (length > wire::kCanFdMaxDataBytes || size != kUdpFrameHeaderBytes + length) return false;
  out.can_id = 0;
  for (int i = 0; i < 4; ++i) out.can_id |= static_cast<std::uint32_t>(datagram[i]) << (8 * i);
  out.length = static_cast<std::uint8_t>(length);
  out.flags = datagram[5];
  out.data.fill(0);
  std::memcpy(out.data.data(), datagram + kUdpFrameHeaderBytes, length);
  return true;
}

UdpCarrier::UdpCarrier(const UdpCarrierConfig& config, const Clock& clock) : clock_(clock) {
  const sockaddr_in local = resolve(config.local_address, config.local_port, "local");
  if (!config.remote_address.empty()) {
    remote_ = resolve(config.remote_address, config.remote_port, "remote");
    has_remote_ = true;
  } else {
    learn_remote_ = true;
  }
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    throw TransportError(TransportError::Kind::kSystem, std::string("UDP socket: ") + std::strerror(errno));
  }
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0) {
    const int error = errno;
    close(fd_);
    throw TransportError(TransportError::Kind::kConfiguration,
                         "UDP bind to " + describe(config.local_address, config.local_port) + ": " + std::strerror(error));
  }
  sockaddr_in bound{};
  socklen_t bound_size = sizeof bound;
  getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &bound_size);
  local_port_ = ntohs(bound.sin_port);
}

UdpCarrier::~UdpCarrier() {
  if (fd_ >= 0) close(fd_);
}

CarrierStatus UdpCarrier::try_send(const CanFdFrame& frame) noexcept {
  if (!has_remote_) {
    ++health_.send_errors;
    health_.last_errno = ENOTCONN;
    return CarrierStatus::kError;
  }
  std::array<std::uint8_t, kDatagramBufferBytes> datagram{};
  const std::size_t size = pack_udp_frame(frame, datagram.data());
  const ssize_t sent =
      sendto(fd_, datagram.data(), size, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&remote_), sizeof remote_);
  if (sent == static_cast<ssize_t>(size)) {
    ++health_.frames_sent;
    return CarrierStatus::kOk;
  }
  if (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
    ++health_.send_busy;
    return CarrierStatus::kBusy;
  }
  // ECONNREFUSED etc.: the peer is not (yet) listening; the frame is lost like on a bus.
  ++health_.send_errors;
  health_.last_errno = sent < 0 ? errno : EMSGSIZE;
  return CarrierStatus::kError;
}

CarrierStatus UdpCarrier::try_receive(ReceivedFrame& out) noexcept {
  for (int attempt = 0; attempt < kMaxSkippedDatagramsPerReceive; ++attempt) {
    std::array<std::uint8_t, kDatagramBufferBytes> datagram{};
    sockaddr_in sender{};
    socklen_t sender_size = sizeof sender;
    const ssize_t size = recvfrom(fd_, datagram.data(), datagram.size(), MSG_DONTWAIT,
                                  reinterpret_cast<sockaddr*>(&sender), &sender_size);
    if (size < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return CarrierStatus::kEmpty;
      if (errno == ECONNREFUSED || errno == EINTR) continue;  // ICMP from an earlier send; not a receive failure
      ++health_.receive_errors;
      health_.last_errno = errno;
      return CarrierStatus::kError;
    }
    if (!unpack_udp_frame(datagram.data(), static_cast<std::size_t>(size), out.frame)) {
      ++health_.malformed_received;
      continue;
    }
    if (learn_remote_) {
      remote_ = sender;
      has_remote_ = true;
    }
    out.receive_time_ns = clock_.now();
    ++health_.frames_received;
    return CarrierStatus::kOk;
  }
  return CarrierStatus::kEmpty;
}

}  // namespace fissure::transport
