#pragma once
// Wait-free bounded single-producer / single-consumer ring (telemetry out of the rt tick).
// The producer never waits: when the ring is full, try_push() fails and the caller counts
// the drop. Head and tail live on separate cache lines, and each side caches the other's
// index so the common case touches only its own line.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace fissure {

template <typename T, std::size_t Capacity>
  requires(std::is_trivially_copyable_v<T> && Capacity >= 2 && (Capacity & (Capacity - 1)) == 0)
class SpscRing {
 public:
  SpscRing() noexcept = default;
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  static constexpr std::size_t capacity() noexcept { return Capacity; }

  /// Producer only. False (and nothing written) when full.
  bool try_push(const T& value) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - cached_tail_ >= Capacity) {
      cached_tail_ = tail_.load(std::memory_order_acquire);
      if (head - cached_tail_ >= Capacity) return false;
    }
    buffer_[head & kMask] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only. False when empty.
  bool try_pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == cached_head_) {
      cached_head_ = head_.load(std::memory_order_acquire);
      if (tail == cached_head_) return false;
    }
    out = buffer_[tail & kMask];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Approximate fill level (exact when called by either side while the other is idle).
  [[nodiscard]] std::size_t size() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire));
  }

 private:
  static constexpr std::uint64_t kMask = Capacity - 1;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // written by the producer
  std::uint64_t cached_tail_ = 0;                   // producer's view of tail_
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // written by the consumer
  std::uint64_t cached_head_ = 0;                   // consumer's view of head_
  alignas(64) std::array<T, Capacity> buffer_{};
};

}  // namespace fissure
