#include "fissure/rt_core/passivity.hpp"

#include <algorithm>

namespace fissure::rt {

void observe_energy(PassivityState& state, const Eigen::Vector3d& p_device_m) noexcept {
  if (state.primed) state.energy_j += state.force_acting_device_n.dot(p_device_m - state.p_prev_device_m);
  state.p_prev_device_m = p_device_m;
  state.primed = true;
  // From this exchange on, the force computed last tick is the one acting.
  state.force_acting_device_n = state.force_sent_last_device_n;
}

Eigen::Vector3d passivity_control(const PassivityConfig& config, PassivityState& state,
                                  const Eigen::Vector3d& force_device_n, const Eigen::Vector3d& v_filtered_m_per_s,
                                  const Eigen::Vector3d& v_raw_m_per_s, double period_s) noexcept {
  state.damping_n_s_per_m = 0.0;
  if (!config.enabled) return force_device_n;
  // Of the two velocity estimates take the one that predicts more energy out of the
  // environment: the filtered one lags by ~3 ms, the raw difference is current but noisy.
  const Eigen::Vector3d& committed = state.force_sent_last_device_n;
  const Eigen::Vector3d total = committed + force_device_n;
  const Eigen::Vector3d& v = total.dot(v_raw_m_per_s) > total.dot(v_filtered_m_per_s) ? v_raw_m_per_s
                                                                                        : v_filtered_m_per_s;
  const double speed = v.norm();
  if (speed < config.min_speed_m_per_s) return force_device_n;
  // Energy by the end of the interval this force acts in: what is observed, plus the
  // command already sent (acting now), plus this one.
  const double predicted_j = state.energy_j + total.dot(v) * period_s;
  if (predicted_j <= 0.0) return force_device_n;
  const Eigen::Vector3d direction = v / speed;
  const double along_n = std::max(0.0, force_device_n.dot(direction));
  const double removable_n = along_n + config.max_damping_n_s_per_m * speed;
  const double removed_n = std::min(removable_n, predicted_j / (period_s * speed));
  state.damping_n_s_per_m = removed_n / speed;
  state.dissipated_by_controller_j += removed_n * speed * period_s;
  return force_device_n - removed_n * direction;
}

void record_sent_force(PassivityState& state, const Eigen::Vector3d& force_device_n) noexcept {
  state.force_sent_last_device_n = force_device_n;
}

void restart_observer(PassivityState& state) noexcept {
  state.primed = false;
  state.force_sent_last_device_n.setZero();
  state.force_acting_device_n.setZero();
}

}  // namespace fissure::rt
