#pragma once
// The host half of a `fissure run` session (BRIEF §2): each step takes the newest DeviceState
// rt_core published, maps it to the tool pose (and a clamp's jaw gap) with rt_core's own
// device → world mapping, steps the HostSimulation there, turns the contact set into a
// ContactProxy (host_sim's ProxyBuilder) and publishes it. Runs on the host thread in real
// time, or interleaved with the rt ticks in lockstep.
#include <array>
#include <cstdint>
#include <vector>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/proxy_builder.hpp"
#include "fissure/host_sim/scene_description.hpp"
#include "fissure/rt_core/proxy_intake.hpp"
#include "fissure/rt_core/tick.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::session {

/// What the host reports after each step (trivially copyable: crosses threads through a
/// LatestValueExchange in real time).
struct HostStatus {
  std::uint64_t steps = 0;
  TimeNs host_time_ns = 0;            ///< simulation time at the end of the step
  int crossed_nodes = 0;              ///< soft nodes on the wrong side of / inside the tool now
  int contacts = 0;                   ///< contacted soft triangles
  int patches = 0;                    ///< proxy patches published
  double max_penetration_m = 0.0;     ///< deepest soft node inside the tool volume
  double force_n = 0.0;               ///< |host force on the tool| [N]
  double step_cpu_s = 0.0;            ///< wall time of the step (simulation + proxy)
  double jaw_gap_m = 0.0;             ///< clamp: gap the host applied
  /// Per jaw (clamp: A, B; other tools: the tool in [0]): |normal (Hunt-Crossley) part| and
  /// |friction part| of the force on it [N] (friction: in_solver with [tool] friction).
  std::array<double, 2> part_normal_n{0.0, 0.0};
  std::array<double, 2> part_friction_n{0.0, 0.0};
  std::uint64_t proxy_sequence = 0;
  std::uint64_t rejected_device_states = 0;  ///< non-finite samples dropped before the scene
  std::uint64_t tool_reseats = 0;     ///< device position epoch changes: tool re-seated, not swept
  /// Soft body's signed enclosed volume / its volume when settled (1 at rest; < 0: more of its
  /// surface faces inwards than outwards — turned inside out; meaningful for a closed surface only);
  /// with several bodies, the lowest of theirs.
  double soft_volume_ratio = 1.0;
  bool soft_everted = false;          ///< soft_volume_ratio < 0 after some step so far (latched)
};

class SessionHost {
 public:
  /// `scene` must outlive the host. Builds the simulation (throws what HostSimulation throws).
  explicit SessionHost(const host::SceneDescription& scene);

  /// Lets the soft body settle with the tool at the scene's start pose (before any step).
  void settle(double seconds);

  /// One host step towards the newest device state (the previous one if nothing new came).
  const HostStatus& step(DeviceStateExchange& state_in, ProxyExchange& proxy_out);

  [[nodiscard]] const HostStatus& status() const noexcept { return status_; }
  [[nodiscard]] const host::HostSimulation& simulation() const noexcept { return sim_; }
  /// The view builds its picture's model from the settled simulation (before the session runs).
  [[nodiscard]] host::HostSimulation& simulation() noexcept { return sim_; }
  [[nodiscard]] const ContactProxy& last_proxy() const noexcept { return proxy_; }
  [[nodiscard]] double time_step_s() const noexcept { return scene_.simulation.time_step_s; }

 private:
  void take_settled_volumes();
  /// The lowest of the bodies' volume / settled volume (NaN when a settled volume is 0).
  [[nodiscard]] double lowest_volume_ratio() const noexcept;
  const host::SceneDescription& scene_;
  host::HostSimulation sim_;
  host::ProxyBuilder builder_;
  host::ToolPose pose_;
  DeviceState device_{};
  bool have_device_ = false;
  /// The device position epoch the tool pose follows (messages.hpp; 0: none yet — the tool
  /// stays at the scene's start pose until rt_core has accepted a sample).
  std::uint8_t applied_epoch_ = 0;
  std::vector<double> settled_volume_m3_;  ///< each soft body's enclosed volume at construction / after settle()
  ContactProxy proxy_{};
  HostStatus status_{};
  /// Per rt tool part: the low-passed velocity of the tissue under it (session_host.cpp,
  /// add_friction_inputs), zero while the part holds no tissue.
  std::array<Eigen::Vector3d, 3> surface_velocity_world_m_per_s_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                                 Eigen::Vector3d::Zero()};
};

}  // namespace fissure::session
