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
  /// μ_s, μ_k: measured tool–tissue coefficients span 0.11–0.83 (Heijnsdijk 2004, docs/scenes.md);
  /// 2 is the scene loader's own bound ([tool] friction_static_ratio).
  static constexpr double kMaxFrictionRatio = 2.0;
  /// |host friction force| [N]: 100× the Falcon's 8 N rating, in world units at force_scale 0.01;
  /// only rejects garbage.
  static constexpr double kMaxFrictionForce_n = 800.0;
  /// Tissue surface speed per axis [m/s]: the tunnelling benchmark's fastest tool is 50 m/s.
  static constexpr double kMaxSurfaceSpeed_m_per_s = 100.0;
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
  kFrictionOutOfRange,  ///< a present part's friction: μ_s or μ_k outside [0, 2], μ_k > μ_s, force, position or surface speed out of range
};

/// Human-readable name of an error (static string, no allocation).
const char* to_string(ProxyError error) noexcept;

/// First problem found in `proxy`, or kNone. `bad_patch` receives the offending patch index
/// (for kFrictionOutOfRange and a non-finite friction: −1).
ProxyError validate(const ContactProxy& proxy, int* bad_patch = nullptr) noexcept;

/// True when every number in the sample is finite.
bool is_finite(const DeviceState& state) noexcept;

}  // namespace fissure
