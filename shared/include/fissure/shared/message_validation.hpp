#pragma once
// Range and sanity checks for messages crossing a trust boundary (a transport, another
// thread's output). Pure, noexcept, allocation-free: callable from the RT tick.
#include <cstdint>

#include "fissure/shared/messages.hpp"

namespace fissure {

/// Accepted ranges. They are deliberately generous physical bounds, not tuning: anything
/// outside them is a bug or corruption upstream, never a real contact.
struct ProxyLimits {
  /// |plane point|, |reference position|: 10 m is far beyond any scene (tool workspace ≈ 0.1 m).
  static constexpr double kMaxCoordinate_m = 10.0;
  /// |normal| must be 1 within this (host normalises in double precision; wire uses float32).
  static constexpr double kUnitNormalTolerance = 1e-3;
  /// k: soft tissue patches are 10¹–10⁴ N/m (n = 1); 10⁹ leaves room for n = 2 units.
  static constexpr double kMaxStiffness = 1e9;
  /// λ: Hunt-Crossley λ/k is a few s/m for tissue; 10⁹ only rejects garbage.
  static constexpr double kMaxDamping = 1e9;
  /// n: 1 (flat punch) to 2; Hertz is 1.5 (BRIEF §4). 3 tolerates exotic fits.
  static constexpr double kMinExponent = 0.5;
  static constexpr double kMaxExponent = 3.0;
};

enum class ProxyError : std::uint8_t {
  kNone = 0,
  kWrongVersion,
  kTooManyPatches,
  kNonFinite,
  kCoordinateOutOfRange,
  kNormalNotUnit,
  kStiffnessOutOfRange,
  kDampingOutOfRange,
  kExponentOutOfRange,
  kBadToolPart,
};

/// Human-readable name of an error (static string, no allocation).
const char* to_string(ProxyError error) noexcept;

/// First problem found in `proxy`, or kNone. `bad_patch` receives the offending index.
ProxyError validate(const ContactProxy& proxy, int* bad_patch = nullptr) noexcept;

/// True when every number in the sample is finite.
bool is_finite(const DeviceState& state) noexcept;

}  // namespace fissure
