#pragma once
// A payload that checks its own integrity: a torn read (half old value, half new) fails
// verify(). Big enough (≈ 1 KiB, like a ContactProxy) that a torn copy is likely to show.
#include <array>
#include <cstdint>

namespace fissure::test {

struct ChecksummedPayload {
  std::uint64_t sequence = 0;
  std::array<std::uint64_t, 126> words{};
  std::uint64_t checksum = 0;

  static ChecksummedPayload make(std::uint64_t sequence) {
    ChecksummedPayload p;
    p.sequence = sequence;
    std::uint64_t x = sequence * 0x9E3779B97F4A7C15ull + 1;
    for (auto& w : p.words) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      w = x;
    }
    p.checksum = p.compute();
    return p;
  }
  [[nodiscard]] std::uint64_t compute() const {
    std::uint64_t h = 1469598103934665603ull ^ sequence;
    for (auto w : words) h = (h ^ w) * 1099511628211ull;
    return h;
  }
  [[nodiscard]] bool verify() const { return checksum == compute(); }
};

}  // namespace fissure::test
