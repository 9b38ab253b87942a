#include "fissure/shared/socketcan_carrier.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>

#include "fissure/shared/wire_codec.hpp"

namespace fissure::transport {
namespace {

/// try_receive consumes at most this many error/foreign frames per call (bounded rt time).
constexpr int kMaxSkippedFramesPerReceive = 16;
/// Error classes we ask the kernel for. Not CAN_ERR_BUSERROR: it may flood on a noisy bus,
/// and the controller-state reports (CRTL) already say when errors accumulate.
constexpr can_err_mask_t kErrorMask =
    CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_ACK | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;

std::string errno_text(const char* call, int error) { return std::string(call) + ": " + std::strerror(error); }

TimeNs realtime_to_monotonic_ns(const timeval& stamp) noexcept {
  timespec realtime{};
  timespec monotonic{};
  clock_gettime(CLOCK_REALTIME, &realtime);
  clock_gettime(CLOCK_MONOTONIC, &monotonic);
  const TimeNs realtime_now_ns = static_cast<TimeNs>(realtime.tv_sec) * kNanosecondsPerSecond + realtime.tv_nsec;
  const TimeNs monotonic_now_ns = static_cast<TimeNs>(monotonic.tv_sec) * kNanosecondsPerSecond + monotonic.tv_nsec;
  const TimeNs stamp_ns = static_cast<TimeNs>(stamp.tv_sec) * kNanosecondsPerSecond + static_cast<TimeNs>(stamp.tv_usec) * 1000;
  return stamp_ns - (realtime_now_ns - monotonic_now_ns);
}

}  // namespace

bool socketcan_supported(std::string* reason) {
  const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    if (reason != nullptr) {
      *reason = (errno == EAFNOSUPPORT ? std::string("AF_CAN unsupported by this kernel (")
                                       : std::string("cannot open a CAN_RAW socket (")) +
                errno_text("socket", errno) + ")";
    }
    return false;
  }
  close(fd);
  return true;
}

CanErrorReport classify_can_error_frame(std::uint32_t can_id, const std::uint8_t* data, std::size_t length) noexcept {
  CanErrorReport report;
  if ((can_id & CAN_ERR_FLAG) == 0) return report;
  const std::uint32_t error_class = can_id & CAN_ERR_MASK;
  report.bus_off = (error_class & CAN_ERR_BUSOFF) != 0;
  report.tx_timeout = (error_class & CAN_ERR_TX_TIMEOUT) != 0;
  report.no_ack = (error_class & CAN_ERR_ACK) != 0;
  report.protocol_violation = (error_class & CAN_ERR_PROT) != 0;
  report.restarted = (error_class & CAN_ERR_RESTARTED) != 0;
  if ((error_class & CAN_ERR_CRTL) != 0) {
    // data[1] says what: back to error-active alone is good news, anything else a problem.
    const std::uint8_t status = length > 1 ? data[1] : 0;
    report.controller_problem = status != CAN_ERR_CRTL_ACTIVE;
  }
  return report;
}

SocketCanCarrier::SocketCanCarrier(const std::string& interface_name, const Clock& clock)
    : interface_name_(interface_name), clock_(clock) {
  fd_ = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) {
    const int error = errno;
    if (error == EAFNOSUPPORT) {
      throw TransportError(TransportError::Kind::kUnsupported,
                           "AF_CAN unsupported by this kernel (" + errno_text("socket", error) +
                               "); SocketCAN needs a kernel with CAN/CAN_RAW (and vcan for a virtual bus)");
    }
    throw TransportError(TransportError::Kind::kSystem, "CAN_RAW socket for '" + interface_name + "': " +
                                                            errno_text("socket", error));
  }
  auto fail = [&](TransportError::Kind kind, const std::string& what) {
    close(fd_);
    fd_ = -1;
    throw TransportError(kind, what);
  };
  if (interface_name.empty() || interface_name.size() >= IFNAMSIZ) {
    fail(TransportError::Kind::kConfiguration, "CAN interface name '" + interface_name + "' is empty or too long");
  }
  ifreq request{};
  std::strncpy(request.ifr_name, interface_name.c_str(), IFNAMSIZ - 1);
  if (ioctl(fd_, SIOCGIFINDEX, &request) != 0) {
    fail(TransportError::Kind::kNoSuchInterface,
         "no CAN interface '" + interface_name + "' (" + errno_text("SIOCGIFINDEX", errno) +
             "); for a virtual bus: ip link add dev " + interface_name + " type vcan; ip link set " + interface_name +
             " mtu 72 up");
  }
  const int interface_index = request.ifr_ifindex;
  if (ioctl(fd_, SIOCGIFMTU, &request) != 0) {
    fail(TransportError::Kind::kSystem, "CAN interface '" + interface_name + "': " + errno_text("SIOCGIFMTU", errno));
  }
  if (request.ifr_mtu != static_cast<int>(CANFD_MTU)) {
    fail(TransportError::Kind::kConfiguration,
         "CAN interface '" + interface_name + "' has MTU " + std::to_string(request.ifr_mtu) +
             (request.ifr_mtu == static_cast<int>(CAN_MTU) ? " (classic CAN)" : "") + "; CAN FD needs " +
             std::to_string(CANFD_MTU) + ": ip link set " + interface_name + " mtu 72");
  }
  const int enable = 1;
  if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &enable, sizeof enable) != 0) {
    fail(TransportError::Kind::kConfiguration,
         "CAN interface '" + interface_name + "': " + errno_text("CAN_RAW_FD_FRAMES", errno));
  }
  if (setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &enable, sizeof enable) != 0) {
    fail(TransportError::Kind::kSystem, "CAN interface '" + interface_name + "': " + errno_text("SO_TIMESTAMP", errno));
  }
  const can_err_mask_t error_mask = kErrorMask;
  if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof error_mask) != 0) {
    fail(TransportError::Kind::kSystem,
         "CAN interface '" + interface_name + "': " + errno_text("CAN_RAW_ERR_FILTER", errno));
  }
  // Only the codec's four standard identifiers kCanIdBase … kCanIdBase+3 (and error frames).
  can_filter filter{};
  filter.can_id = wire::kCanIdBase;
  filter.can_mask = (CAN_SFF_MASK & ~0x3u) | CAN_EFF_FLAG | CAN_RTR_FLAG;
  if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter) != 0) {
    fail(TransportError::Kind::kSystem, "CAN interface '" + interface_name + "': " + errno_text("CAN_RAW_FILTER", errno));
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = interface_index;
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    fail(TransportError::Kind::kSystem, "CAN interface '" + interface_name + "': " + errno_text("bind", errno));
  }
}

SocketCanCarrier::~SocketCanCarrier() {
  if (fd_ >= 0) close(fd_);
}

CarrierStatus SocketCanCarrier::try_send(const CanFdFrame& frame) noexcept {
  canfd_frame raw{};
  raw.can_id = frame.can_id & CAN_SFF_MASK;
  raw.len = static_cast<std::uint8_t>(std::min<std::size_t>(frame.length, CANFD_MAX_DLEN));
  raw.flags = static_cast<std::uint8_t>(frame.flags & (CANFD_BRS | CANFD_ESI));
  std::memcpy(raw.data, frame.data.data(), raw.len);
  const ssize_t written = write(fd_, &raw, CANFD_MTU);
  if (written == static_cast<ssize_t>(CANFD_MTU)) {
    ++health_.frames_sent;
    return CarrierStatus::kOk;
  }
  const int error = written < 0 ? errno : EIO;
  if (error == EAGAIN || error == EWOULDBLOCK || error == ENOBUFS) {
    ++health_.send_busy;
    return CarrierStatus::kBusy;
  }
  ++health_.send_errors;
  health_.last_errno = error;
  // A bus-off controller takes the interface down: writes fail with ENETDOWN.
  return health_.bus_off || error == ENETDOWN ? CarrierStatus::kBusOff : CarrierStatus::kError;
}

void SocketCanCarrier::apply(const CanErrorReport& report) noexcept {
  ++health_.error_frames;
  if (report.bus_off) {
    ++health_.bus_off_events;
    health_.bus_off = true;
  }
  if (report.tx_timeout) ++health_.tx_timeouts;
  if (report.controller_problem || report.no_ack || report.protocol_violation) ++health_.controller_problems;
  if (report.restarted) {
    ++health_.restarts;
    health_.bus_off = false;
  }
}

CarrierStatus SocketCanCarrier::try_receive(ReceivedFrame& out) noexcept {
  for (int attempt = 0; attempt < kMaxSkippedFramesPerReceive; ++attempt) {
    canfd_frame raw{};
    iovec io{&raw, sizeof raw};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval))];
    msghdr message{};
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    const ssize_t size = recvmsg(fd_, &message, MSG_DONTWAIT);
    if (size < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return CarrierStatus::kEmpty;
      if (errno == EINTR) continue;
      ++health_.receive_errors;
      health_.last_errno = errno;
      return health_.bus_off ? CarrierStatus::kBusOff : CarrierStatus::kError;
    }
    // With CAN_RAW_FD_FRAMES the socket delivers classic frames (CAN_MTU) and FD frames (CANFD_MTU).
    if (size != static_cast<ssize_t>(CANFD_MTU) && size != static_cast<ssize_t>(CAN_MTU)) {
      ++health_.malformed_received;
      continue;
    }
    const std::size_t max_length = size == static_cast<ssize_t>(CANFD_MTU) ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
    const std::size_t length = std::min<std::size_t>(raw.len, max_length);
    if ((raw.can_id & CAN_ERR_FLAG) != 0) {
      apply(classify_can_error_frame(raw.can_id, raw.data, length));
      continue;
    }
    if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) != 0) {
      ++health_.malformed_received;  // the filter should have kept these out
      continue;
    }
    out.frame.can_id = raw.can_id & CAN_SFF_MASK;
    out.frame.length = static_cast<std::uint8_t>(length);
    out.frame.flags = static_cast<std::uint8_t>(raw.flags & (CANFD_BRS | CANFD_ESI));
    out.frame.data.fill(0);
    std::memcpy(out.frame.data.data(), raw.data, length);
    out.receive_time_ns = clock_.now();
    for (cmsghdr* header = CMSG_FIRSTHDR(&message); header != nullptr; header = CMSG_NXTHDR(&message, header)) {
      if (header->cmsg_level == SOL_SOCKET && header->cmsg_type == SCM_TIMESTAMP) {
        timeval stamp{};
        std::memcpy(&stamp, CMSG_DATA(header), sizeof stamp);
        out.receive_time_ns = realtime_to_monotonic_ns(stamp);
      }
    }
    ++health_.frames_received;
    return CarrierStatus::kOk;
  }
  return CarrierStatus::kEmpty;
}

}  // namespace fissure::transport
