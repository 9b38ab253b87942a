#include "fissure/eval/stress_row_json.hpp"

namespace fissure::eval {

// Every stored field under its member's name (nlohmann's macro writes both directions, and
// from_json throws naming a missing key).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(StressRow, name, group, seed, passed, known_failure, failures, ticks, host_steps, force_max_n,
                                   force_limit_n, energy_max_j, energy_bound_j, crossed_nodes_max, host_penetration_max_mm,
                                   fault_bits_seen, fault_bits_allowed, fault_onsets, proxies_rejected, injected_events,
                                   recoveries_required, recoveries_done, recovery_max_s, contact_ticks, min_contact_fraction,
                                   soft_volume_ratio_min,                                   wall_s, note)

nlohmann::json stress_row_to_json(const StressRow& r) {
  nlohmann::json j = r;
  // Derived, for readers of the report (not read back).
  j["faults_seen"] = fault_bits_text(r.fault_bits_seen);
  j["faults_allowed"] = fault_bits_text(r.fault_bits_allowed);
  j["contact_fraction"] = r.ticks > 0 ? static_cast<double>(r.contact_ticks) / static_cast<double>(r.ticks) : 0.0;
  return j;
}

StressRow stress_row_from_json(const nlohmann::json& json) { return json.get<StressRow>(); }

}  // namespace fissure::eval
