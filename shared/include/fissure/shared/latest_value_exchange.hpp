#pragma once
// Wait-free single-producer / single-consumer "latest value" exchange (a triple buffer).
//
// The producer always has a private slot to write into, the consumer a private slot to
// read from, and the third slot sits in the middle holding the newest complete value.
// Publishing swaps the producer's slot with the middle one; fetching swaps the middle
// with the consumer's slot, but only if the middle holds something new. Each side does
// one atomic exchange and a memcpy: no locks, no retries, bounded time — usable from the
// rt tick on either side. A value is never torn: a slot is only ever touched by the side
// that currently owns it. (SOFA's LCPForceFeedback does the same with plain ints; this one
// has the acquire/release ordering that makes it correct.)
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace fissure {

template <typename T>
  requires std::is_trivially_copyable_v<T>
class LatestValueExchange {
 public:
  LatestValueExchange() noexcept = default;
  LatestValueExchange(const LatestValueExchange&) = delete;
  LatestValueExchange& operator=(const LatestValueExchange&) = delete;

  /// Producer only. Publishes `value` as the newest one; never blocks.
  void publish(const T& value) noexcept {
    slots_[producer_slot_].value = value;
    const std::uint8_t previous_middle =
        middle_.exchange(static_cast<std::uint8_t>(producer_slot_ | kFreshBit), std::memory_order_acq_rel);
    producer_slot_ = previous_middle & kSlotMask;
  }

  /// Consumer only. If a value newer than the last fetched one exists, copies it to `out`
  /// and returns true; otherwise leaves `out` untouched and returns false.
  bool try_fetch(T& out) noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFreshBit) == 0) return false;
    const std::uint8_t previous_middle =
        middle_.exchange(static_cast<std::uint8_t>(consumer_slot_), std::memory_order_acq_rel);
    consumer_slot_ = previous_middle & kSlotMask;
    out = slots_[consumer_slot_].value;
    return true;
  }

 private:
  static constexpr std::uint8_t kSlotMask = 0x3;
  static constexpr std::uint8_t kFreshBit = 0x4;

  struct alignas(64) Slot {
    T value{};
  };
  Slot slots_[3];
  alignas(64) std::atomic<std::uint8_t> middle_{1};
  alignas(64) std::uint8_t producer_slot_ = 0;
  alignas(64) std::uint8_t consumer_slot_ = 2;
};

}  // namespace fissure
