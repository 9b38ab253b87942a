#pragma once
// The stress harness (`fissure stress`): lockstep sessions (SimFalcon + RtLoop +
// SessionHost, optionally through the wire layer) driven by random and adversarial input,
// extreme parameters, awkward geometry and faulty transports, each checked tick by tick
// against the BRIEF §9 stability measures:
//   * everything finite (position, velocity, forces, energy) on every tick;
//   * |F| within the rt safety limit (SafetyConfig::max_force_n);
//   * 0 crossed soft nodes after every host step;
//   * passivity observer energy ≤ kStressEnergyBound_j;
//   * no rt fault bit the case did not inject (StressSetup::allowed_faults);
//   * recovery after each injected fault: within kStressRecoveryBound_s of the fault clearing
//     the loop is fault-free, fully ramped in and renders a fresh proxy again.
// Everything is deterministic from the case's seed (LockstepClock, seeded hand scripts and
// fault streams), so a failing row is reproduced by `fissure stress --case NAME --seed S`.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/host_sim/scene_description.hpp"
#include "fissure/shared/fault_injecting_carrier.hpp"

namespace fissure::eval {

enum class StressProfile : std::uint8_t { kCi, kFull };

/// Energy the passivity observer may report as put into the hand [J]. The controller's job is
/// E ≤ 0; its prediction uses the filtered velocity (≈ 3 ms lag, passivity.hpp), so allow the
/// work of the Falcon's full 8 N over that lag at a brisk 1 m/s hand motion: 8·1·0.003 ≈ 0.025 J.
inline constexpr double kStressEnergyBound_j = 0.025;
/// Longest time from a fault clearing to the loop being healthy again [s]: the fault recovery
/// ticks (a few ms), the safety stage's fault ramp-in (0.25 s, safety.hpp) and the proxy fade-in
/// (0.05 s, staleness.hpp), with margin for the host's next proxy at the slowest 20 ms step.
inline constexpr double kStressRecoveryBound_s = 0.5;
/// Simulated seconds per case in the ci profile (20 000 rt ticks at 1 kHz): the whole profile
/// (43 cases) then runs in about 1–2 minutes on the loaded 2-core VM (measured, see the report).
inline constexpr double kCiCaseDuration_s = 20.0;
/// rt ticks per case in the full profile: ≥ 10⁶ rt ticks with the host in the loop.
inline constexpr double kFullCaseTicks = 1.0e6;
/// Stress cases tie the ball's bottom cap to the ground ([[soft_body.anchor]]): every node whose
/// rest position lies within this height above the ball's lowest node (the 128-face ball: 6 of
/// its 66 nodes, ~10 % of the surface). Why: a free ball is knocked off the 1 m ground by the
/// random hand within ~20 s of a 1000 s case and the clamp squeezes the frictionless ball out
/// sideways — the full profile would test free motion. Tissue lies attached to its bed; 1 cm keeps the cap
/// well below anything the tool reaches (the spatula's lowest face stays above y = 0.06 m, the
/// clamp jaws above 0.04 m), so the anchors never fight the tool, and leaves the ball free to
/// dent, lean and bulge everywhere the tool goes.
inline constexpr double kAnchorCapHeight_m = 0.01;
/// After an injected rt stall (StressSetup::rt_stalls), the commanded force must be back within
/// kStressStallForceTolerance of the environment rt_core renders — the contact force the proxy
/// gives plus the workspace soft wall (stall_force_check.hpp) — within this time [s] (issue 26)…
inline constexpr double kStressStallRecovery_s = 0.2;
/// …and stay there for this long [s] (the hand keeps resting; the check window).
inline constexpr double kStressStallCheck_s = 0.2;
/// Largest |F_commanded − F_env| / |F_env| in the check window (issue 26: 5 %; F_env = contact +
/// soft wall), both forces averaged over kStressStallMeanWindow_s.
inline constexpr double kStressStallForceTolerance = 0.05;
/// The window those means are taken over [s]: 20 ms, one period of 50 Hz. A resting hand on the
/// spatula-sphere contact buzzes at ~60 Hz by ±15 mm/s, and the passivity damper β·v_f (≤ 5 N·s/m)
/// ripples the command by ±0.075 N about the contact force with it — zero on average, and not the
/// held-back force this check is about (issue 26: 1.1 N commanded against 1.35 N, with a
/// 20–25 Hz sawtooth, which a 20 ms mean passes at ≥ 60 % of its amplitude).
inline constexpr double kStressStallMeanWindow_s = 0.02;
/// Contact forces, and F_env, below this [N] are not checked against the relative tolerance: there
/// 5 % is below the wall's own step per encoder count.
inline constexpr double kStressStallMinForce_n = 0.2;
/// A case's contact floor as a fraction of the share of its session the hand SCRIPT puts the
/// tool through the rest ball's surface (script_contact_share). Half: the
/// device follows the script through the hand's 300 N/m grip (SimFalcon), so fast legs (flicks,
/// teleports, 1 m/s jerks) overshoot and bounce, injected faults blank the proxy for 0.1 s of
/// every second plus the ramp-in, and the ball sags ~1–2 mm under gravity below its rest shape —
/// each loses a part of the geometric share, none loses half of it. The failure this catches is
/// a ball no longer under the tool: ≈ 0.4 % against shares of ~15–40 %.
inline constexpr double kContactFloorOfScriptShare = 0.5;

/// A span of session time [s].
struct TimeWindow {
  double start_s = 0.0;
  double end_s = 0.0;
  [[nodiscard]] bool contains(double t_s) const noexcept { return t_s >= start_s && t_s < end_s; }
};

/// Which proxy field the harness overwrites (with NaN or inf) on its way from the host to rt_core.
enum class ProxyField : std::uint8_t {
  kPlanePoint,
  kNormal,
  kStiffness,
  kDamping,
  kExponent,
  kReferencePosition,
  kReferenceOrientation,
  kHostTime,
};
const char* to_string(ProxyField field) noexcept;

struct ProxyCorruption {
  TimeWindow window;
  ProxyField field = ProxyField::kPlanePoint;
  double value = 0.0;  ///< NaN, +inf or −inf
};

/// What a case sets up; the runner builds the session from it.
struct StressSetup {
  host::SceneDescription scene;
  falcon::SimFalconConfig device;     ///< hand script and SimFalcon faults (exchange windows)
  double rt_rate_hz = 1000.0;
  double duration_s = 0.0;
  std::vector<ProxyCorruption> proxy_corruptions;
  std::vector<TimeWindow> device_state_corruptions;  ///< NaN position/velocity handed to the host
  /// Transport: both directions through FaultInjectingCarrier over a LoopbackLink and the
  /// LinkBridge pair; the faults stop at transport_clean_after_s (recovery is checked then).
  std::optional<transport::FaultConfig> transport;
  double transport_clean_after_s = 0.0;
  std::uint32_t allowed_faults = 0;        ///< RtFaultBits the injected faults may cause
  std::vector<TimeWindow> fault_windows;   ///< injected faults (recovery is checked after each)
  /// rt stalls: at each window's start the lockstep clock jumps by the window's length before
  /// the next rt tick (the rt thread descheduled; the host, paced by rt ticks in lockstep, waits
  /// with it, SimFalcon integrates the gap as a real device would). From kStressStallRecovery_s
  /// after each stall, for kStressStallCheck_s, the commanded force must be within
  /// kStressStallForceTolerance of the contact + soft-wall force (stall_force_check.hpp).
  std::vector<TimeWindow> rt_stalls;
  std::uint64_t injected_events = 0;       ///< how many faults were injected (report)
  /// The set-up must be refused with a clear error (e.g. a degenerate tool mesh): the case
  /// passes when constructing the session throws, and fails if it runs.
  bool expect_rejection = false;
  /// Fraction of rt ticks the tool must render contact in: a case about a contact (the clamp
  /// squeezing the sphere flat) proves nothing once the body has slipped away from the tool.
  double min_contact_fraction = 0.0;
  /// Derive min_contact_fraction from the hand script (run_stress_case, after configure):
  /// kContactFloorOfScriptShare × the share of the session the script's target holds the tool
  /// below the rest ball's surface. Off for cases that set their own floor (the clamp) or are
  /// not about a contact (a refused set-up).
  bool contact_floor_from_hand_script = true;
  std::string note;
};

struct StressCase {
  StressCase(std::string case_name, std::string case_group, std::string scene_name, double rate_hz,
             std::function<void(StressSetup&, std::uint64_t seed)> configure_setup)
      : name(std::move(case_name)), group(std::move(case_group)), scene(std::move(scene_name)), rt_rate_hz(rate_hz),
        configure(std::move(configure_setup)) {}

  std::string name;
  std::string group;    ///< device input, parameters, geometry, transport
  std::string scene;    ///< scene file name (scenes/NAME.toml)
  double rt_rate_hz = 1000.0;
  /// Fills in the setup (scene already loaded, duration and device defaults set).
  std::function<void(StressSetup&, std::uint64_t seed)> configure;
  /// Non-empty: a failure of this case is a known bug in another module (the text says which);
  /// the ci profile reports it as KNOWN and does not fail on it. The full profile always fails.
  std::string known_failure_ci;
};

struct StressRow {
  std::string name;
  std::string group;
  std::uint64_t seed = 0;
  std::uint64_t ticks = 0;
  std::uint64_t host_steps = 0;
  bool passed = false;
  bool known_failure = false;          ///< failed, but listed as a known bug (ci profile only)
  std::vector<std::string> failures;   ///< first occurrence of each failed assertion
  double force_max_n = 0.0;
  double force_limit_n = 0.0;
  double energy_max_j = 0.0;
  double energy_bound_j = kStressEnergyBound_j;
  int crossed_nodes_max = 0;
  double host_penetration_max_mm = 0.0;
  std::uint32_t fault_bits_seen = 0;
  std::uint32_t fault_bits_allowed = 0;
  std::uint64_t fault_onsets = 0;       ///< ticks where a fault bit appeared (was clear before)
  std::uint64_t proxies_rejected = 0;
  std::uint64_t injected_events = 0;
  std::uint64_t recoveries_required = 0;
  std::uint64_t recoveries_done = 0;
  double recovery_max_s = 0.0;
  std::uint64_t contact_ticks = 0;      ///< rt ticks that rendered at least one contact patch
  double min_contact_fraction = 0.0;    ///< what the case requires of contact_ticks / ticks
  /// Lowest enclosed volume of the soft body over the run, as a fraction of its settled volume
  /// (Bullet's signed volume, so < 0 means the surface is turned inside out: the one-sided paired
  /// collision then meets no triangle from outside — a failure the crossed-node count cannot see).
  double soft_volume_ratio_min = 1.0;
  /// After rt stalls: largest |F_commanded − F_env| / |F_env| in the check windows (20 ms means;
  /// F_env = contact + soft wall), and how many ticks were checked.
  double stall_force_error_max = 0.0;
  std::uint64_t stall_checked_ticks = 0;
  double wall_s = 0.0;
  std::string note;
};

/// Every case of the harness, in report order.
std::vector<StressCase> stress_cases();

/// Per-case seed from the run's base seed and the case name (so one case can be rerun alone).
std::uint64_t stress_case_seed(std::uint64_t base_seed, const std::string& case_name) noexcept;

/// Simulated duration of one case [s] in a profile at an rt rate.
double stress_case_duration_s(StressProfile profile, double rt_rate_hz) noexcept;

/// Share of [0, duration_s] in which the hand script's target (sampled every 1 ms, legs and
/// holds as SimFalcon plays them) puts the tool's axis-aligned box across the REST sphere's
/// surface (its nearest point inside the sphere, its farthest corner outside): the time the
/// script asks for contact — pressed in from above, or poking out from inside. Spatula-type
/// scenes (box or convex mesh tool, not clamp mode; identity axis mapping and tool orientation)
/// with a sphere soft body; throws std::invalid_argument otherwise.
double script_contact_share(const StressSetup& setup);

/// Runs one case (loads its scene, configures, runs lockstep, checks every tick).
StressRow run_stress_case(const StressCase& stress_case, StressProfile profile, std::uint64_t seed);

/// Names of the set bits of an RtFaultBits mask ("device_io|proxy_stale"), "none" for 0.
std::string fault_bits_text(std::uint32_t bits);

}  // namespace fissure::eval
