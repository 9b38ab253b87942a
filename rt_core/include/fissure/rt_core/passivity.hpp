#pragma once
// Pipeline stage: time-domain passivity observer / controller (Hannaford & Ryu 2002).
//
// Observer: the energy the rendered force has put into the operator's hand since start,
//     E = Σ F_in_effect · Δp_device       [J]   (= Σ f·v·T with v = Δp/T)
// where F_in_effect is the force command that was acting while the device moved by Δp. On
// the Falcon's ping-pong a command computed in tick k goes out with exchange k+1 and acts
// until exchange k+2, so the motion seen in tick k+2 (p_{k+2} − p_{k+1}) is paired with the
// force computed two ticks earlier. E ≤ 0 means the virtual environment is passive (it
// has absorbed at least as much energy as it returned); E > 0 means it created energy —
// the precursor of the buzzing/instability Colgate & Schenkel's bound b > K·T/2 predicts.
//
// Controller: before a force goes out, predict the energy at the end of the interval it will
// act in, E' = E + (F_sent + F)·v·T (F_sent: the command already on its way, acting until
// the next exchange; F: this one, acting the interval after). If E' > 0, take away the
// part of F along the motion that makes E' positive: first the component of F pushing
// along v (the environment returning energy), then, if that is not enough, a damping force
// of at most max_damping_n_s_per_m·|v|. This is Hannaford & Ryu's PC with the added damper
// bounded: a virtual damper delayed by the ping-pong and the velocity filter is itself
// subject to the sampled-data limit b > K·T/2 + |B| (Colgate & Schenkel 1997), so B must
// stay below the device's own damping; removing a push along v is always safe. Telemetry
// reports the equivalent damping removed/|v|. v is whichever of the filtered and the raw
// velocity predicts more energy out (the filter lags ~3 ms; the raw difference does not).
#include <Eigen/Core>

namespace fissure::rt {

struct PassivityConfig {
  bool enabled = true;
  /// Largest damping the controller may add beyond cancelling the force along v [N·s/m].
  /// Below SimFalcon's nominal mechanism damping (3 N·s/m) so that, by Colgate–Schenkel,
  /// the added damper cannot itself become active. (CHAI3D's 20 N·s/m Falcon limit is for a
  /// damper rendered with the hand's own damping added; the controller cannot count on it.)
  double max_damping_n_s_per_m = 2.0;
  /// Below this speed the controller does nothing [m/s]: the direction of v is noise there
  /// (one encoder count per tick at 1 kHz reads ≈ 50 mm/s raw, ≲ 1 mm/s after the filter)
  /// and a force at standstill does no work anyway.
  double min_speed_m_per_s = 1e-3;
};

struct PassivityState {
  double energy_j = 0.0;  ///< observer: Σ F·Δp since start (positive = active)
  double dissipated_by_controller_j = 0.0;   ///< Σ removed·|v|·T the controller asked for
  Eigen::Vector3d force_sent_last_device_n = Eigen::Vector3d::Zero();   ///< computed tick k−1
  Eigen::Vector3d force_acting_device_n = Eigen::Vector3d::Zero();      ///< computed tick k−2 (acting now)
  Eigen::Vector3d p_prev_device_m = Eigen::Vector3d::Zero();
  bool primed = false;
  double damping_n_s_per_m = 0.0;  ///< equivalent damping removed/|v| in the last tick
};

/// Observer: account the work done since the previous sample. Call once per good sample.
void observe_energy(PassivityState& state, const Eigen::Vector3d& p_device_m) noexcept;

/// Controller: returns the force with passivity damping added (unchanged when disabled
/// or when the prediction stays ≤ 0).
Eigen::Vector3d passivity_control(const PassivityConfig& config, PassivityState& state,
                                  const Eigen::Vector3d& force_device_n, const Eigen::Vector3d& v_filtered_m_per_s,
                                  const Eigen::Vector3d& v_raw_m_per_s, double period_s) noexcept;

/// Records the force that actually went out this tick (after safety) for the observer.
void record_sent_force(PassivityState& state, const Eigen::Vector3d& force_device_n) noexcept;

/// After a fault the device position history is not trustworthy: restart the Δp chain
/// (the energy total is kept).
void restart_observer(PassivityState& state) noexcept;

}  // namespace fissure::rt
