#include "fissure/shared/fault_injecting_carrier.hpp"

#include <algorithm>

namespace fissure::transport {

FaultInjectingCarrier::FaultInjectingCarrier(FrameCarrier& inner, const Clock& clock, const FaultConfig& config) noexcept
    : inner_(inner), clock_(clock), config_(config), random_state_(config.seed) {}

std::uint64_t FaultInjectingCarrier::next_random() noexcept {
  // splitmix64: tiny, seedable with any value, identical on every platform (unlike the
  // standard distributions), which is what makes a seeded run reproducible everywhere.
  std::uint64_t z = (random_state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double FaultInjectingCarrier::uniform() noexcept {
  return static_cast<double>(next_random() >> 11) * 0x1.0p-53;
}

bool FaultInjectingCarrier::hold(const ReceivedFrame& frame, TimeNs release_time_ns, std::uint64_t release_after) noexcept {
  for (Held& slot : held_) {
    if (slot.in_use) continue;
    slot.in_use = true;
    slot.frame = frame;
    slot.release_time_ns = release_time_ns;
    slot.release_after = release_after;
    slot.order = next_order_++;
    return true;
  }
  ++counts_.hold_overflow;
  return false;
}

bool FaultInjectingCarrier::take_releasable(ReceivedFrame& out, bool ignore_conditions) noexcept {
  const TimeNs now_ns = clock_.now();
  Held* oldest = nullptr;
  for (Held& slot : held_) {
    if (!slot.in_use) continue;
    const bool due = ignore_conditions ||
                     (now_ns >= slot.release_time_ns && counts_.frames_delivered >= slot.release_after);
    if (due && (oldest == nullptr || slot.order < oldest->order)) oldest = &slot;
  }
  if (oldest == nullptr) return false;
  out = oldest->frame;
  oldest->in_use = false;
  return true;
}

void FaultInjectingCarrier::corrupt(CanFdFrame& frame) noexcept {
  if (frame.length == 0) return;
  const int flips = 1 + static_cast<int>(next_random() % static_cast<std::uint64_t>(std::max(1, config_.max_bit_flips)));
  for (int i = 0; i < flips; ++i) {
    const std::uint64_t bit = next_random() % (static_cast<std::uint64_t>(frame.length) * 8u);
    frame.data[bit / 8] = static_cast<std::uint8_t>(frame.data[bit / 8] ^ (1u << (bit % 8)));
  }
}

CarrierStatus FaultInjectingCarrier::try_receive(ReceivedFrame& out) noexcept {
  // Held frames whose time has come go first: they were received earlier.
  if (take_releasable(out, releasing_all_)) {
    ++counts_.frames_delivered;
    return CarrierStatus::kOk;
  }
  // Bounded: each pass takes one frame from the inner carrier.
  for (std::size_t pass = 0; pass < kHoldCapacity; ++pass) {
    ReceivedFrame incoming;
    const CarrierStatus status = inner_.try_receive(incoming);
    if (status != CarrierStatus::kOk) return status;
    ++counts_.frames_in;
    // Every decision draws the same number of random values, so a run is reproducible
    // whatever the probabilities are.
    const double drop_draw = uniform();
    const double duplicate_draw = uniform();
    const double reorder_draw = uniform();
    const double corrupt_draw = uniform();
    const double delay_draw = uniform();
    const std::uint64_t depth_draw = next_random();
    const double delay_fraction = uniform();
    if (drop_draw < config_.drop_probability) {
      ++counts_.dropped;
      continue;
    }
    if (corrupt_draw < config_.corrupt_probability) {
      corrupt(incoming.frame);
      ++counts_.corrupted;
    }
    if (duplicate_draw < config_.duplicate_probability && hold(incoming, 0, 0)) ++counts_.duplicated;
    if (reorder_draw < config_.reorder_probability) {
      const int depth = 1 + static_cast<int>(depth_draw % static_cast<std::uint64_t>(std::max(1, config_.max_reorder_depth)));
      if (hold(incoming, 0, counts_.frames_delivered + static_cast<std::uint64_t>(depth))) {
        ++counts_.reordered;
        continue;
      }
    } else if (delay_draw < config_.delay_probability) {
      const auto delay_ns = static_cast<TimeNs>(delay_fraction * static_cast<double>(config_.max_delay_ns)) + 1;
      if (hold(incoming, incoming.receive_time_ns + delay_ns, 0)) {
        ++counts_.delayed;
        continue;
      }
    }
    out = incoming;
    ++counts_.frames_delivered;
    return CarrierStatus::kOk;
  }
  return CarrierStatus::kEmpty;
}

std::size_t FaultInjectingCarrier::held_frames() const noexcept {
  return static_cast<std::size_t>(std::count_if(held_.begin(), held_.end(), [](const Held& h) { return h.in_use; }));
}

void FaultInjectingCarrier::release_all() noexcept { releasing_all_ = true; }

}  // namespace fissure::transport
