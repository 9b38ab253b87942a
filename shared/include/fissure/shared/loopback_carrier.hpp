#pragma once
// In-memory carrier pair for tests and lockstep sessions: what end A sends, end B receives
// in order, and vice versa. Each direction is a wait-free SPSC ring, so the two ends may
// live on different threads (one thread per end).
#include <cstddef>

#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"
#include "fissure/shared/spsc_ring.hpp"

namespace fissure::transport {

class LoopbackLink {
 public:
  /// Frames in flight per direction before try_send reports kBusy. 1024 ≈ 100 full proxies:
  /// tests may send a burst before receiving.
  static constexpr std::size_t kCapacityFrames = 1024;

  /// Receive timestamps come from `clock` (a LockstepClock in tests).
  explicit LoopbackLink(const Clock& clock) noexcept : a_(*this, 0), b_(*this, 1), clock_(clock) {}
  LoopbackLink(const LoopbackLink&) = delete;
  LoopbackLink& operator=(const LoopbackLink&) = delete;

  FrameCarrier& a() noexcept { return a_; }
  FrameCarrier& b() noexcept { return b_; }

 private:
  class End final : public FrameCarrier {
   public:
    End(LoopbackLink& link, int index) noexcept : link_(link), index_(index) {}
    CarrierStatus try_send(const CanFdFrame& frame) noexcept override;
    CarrierStatus try_receive(ReceivedFrame& out) noexcept override;
    const CarrierHealth& health() const noexcept override { return health_; }

   private:
    LoopbackLink& link_;
    int index_;
    CarrierHealth health_{};
  };

  SpscRing<CanFdFrame, kCapacityFrames>& ring_to(int end_index) noexcept { return end_index == 0 ? to_a_ : to_b_; }

  End a_;
  End b_;
  const Clock& clock_;
  SpscRing<CanFdFrame, kCapacityFrames> to_a_;
  SpscRing<CanFdFrame, kCapacityFrames> to_b_;
};

}  // namespace fissure::transport
