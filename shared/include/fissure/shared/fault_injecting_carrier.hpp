#pragma once
// A carrier wrapper that damages the frames it receives, seeded and deterministic, to test
// the codec and the link against a bad bus: drop, duplicate, reorder, corrupt (bit flips in
// the data bytes), delay. Faults are applied on the receive path (try_receive), so one
// wrapper on the receiving end models a faulty link in that direction; try_send passes
// through unchanged. Fixed-size buffers, no allocation, noexcept.
#include <array>
#include <cstddef>
#include <cstdint>

#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"

namespace fissure::transport {

struct FaultConfig {
  double drop_probability = 0.0;       ///< frame vanishes
  double duplicate_probability = 0.0;  ///< frame is delivered twice (the copy right after)
  double reorder_probability = 0.0;    ///< frame is held back until 1…max_reorder_depth later frames went first
  double corrupt_probability = 0.0;    ///< 1…max_bit_flips random bits of its data bytes flip
  double delay_probability = 0.0;      ///< frame is held back until clock.now() ≥ arrival + U(0, max_delay_ns]
  int max_reorder_depth = 3;
  int max_bit_flips = 3;
  TimeNs max_delay_ns = 2'000'000;
  std::uint64_t seed = 1;
};

/// What the injector did (ground truth for the tests' bookkeeping).
struct FaultCounts {
  std::uint64_t frames_in = 0;        ///< taken from the inner carrier
  std::uint64_t frames_delivered = 0; ///< handed to the caller (duplicates included)
  std::uint64_t dropped = 0;
  std::uint64_t duplicated = 0;
  std::uint64_t reordered = 0;
  std::uint64_t corrupted = 0;
  std::uint64_t delayed = 0;
  std::uint64_t hold_overflow = 0;    ///< a hold was wanted but the buffer was full: delivered now
};

class FaultInjectingCarrier final : public FrameCarrier {
 public:
  /// Frames that can be held back (reordered, delayed, duplicate copies) at once.
  static constexpr std::size_t kHoldCapacity = 64;

  FaultInjectingCarrier(FrameCarrier& inner, const Clock& clock, const FaultConfig& config) noexcept;

  CarrierStatus try_send(const CanFdFrame& frame) noexcept override { return inner_.try_send(frame); }
  CarrierStatus try_receive(ReceivedFrame& out) noexcept override;
  const CarrierHealth& health() const noexcept override { return inner_.health(); }

  [[nodiscard]] const FaultCounts& counts() const noexcept { return counts_; }
  /// Frames still held back (a reordered frame waits for later traffic).
  [[nodiscard]] std::size_t held_frames() const noexcept;
  /// Releases every held frame regardless of its condition (end of a test run).
  void release_all() noexcept;

 private:
  struct Held {
    bool in_use = false;
    ReceivedFrame frame{};
    TimeNs release_time_ns = 0;      ///< delay: not before this
    std::uint64_t release_after = 0; ///< reorder: not before frames_delivered reaches this
    std::uint64_t order = 0;         ///< FIFO among releasable frames
  };

  double uniform() noexcept;                  // [0, 1)
  std::uint64_t next_random() noexcept;       // splitmix64
  bool hold(const ReceivedFrame& frame, TimeNs release_time_ns, std::uint64_t release_after) noexcept;
  bool take_releasable(ReceivedFrame& out, bool ignore_conditions) noexcept;
  void corrupt(CanFdFrame& frame) noexcept;

  FrameCarrier& inner_;
  const Clock& clock_;
  FaultConfig config_;
  std::uint64_t random_state_;
  std::array<Held, kHoldCapacity> held_{};
  std::uint64_t next_order_ = 0;
  bool releasing_all_ = false;
  FaultCounts counts_{};
};

}  // namespace fissure::transport
