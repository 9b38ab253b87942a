#include "stress_row_json.hpp"

namespace fissure::app {

nlohmann::json stress_row_to_json(const StressRow& r) {
  return {{"name", r.name},
          {"group", r.group},
          {"seed", r.seed},
          {"passed", r.passed},
          {"known_failure", r.known_failure},
          {"failures", r.failures},
          {"ticks", r.ticks},
          {"host_steps", r.host_steps},
          {"force_max_n", r.force_max_n},
          {"force_limit_n", r.force_limit_n},
          {"energy_max_j", r.energy_max_j},
          {"energy_bound_j", r.energy_bound_j},
          {"crossed_nodes_max", r.crossed_nodes_max},
          {"host_penetration_max_mm", r.host_penetration_max_mm},
          {"faults_seen", fault_bits_text(r.fault_bits_seen)},
          {"faults_allowed", fault_bits_text(r.fault_bits_allowed)},
          // The masks themselves, so a row read back (parallel runs) prints the same text.
          {"fault_bits_seen", r.fault_bits_seen},
          {"fault_bits_allowed", r.fault_bits_allowed},
          {"fault_onsets", r.fault_onsets},
          {"proxies_rejected", r.proxies_rejected},
          {"injected_events", r.injected_events},
          {"recoveries_required", r.recoveries_required},
          {"recoveries_done", r.recoveries_done},
          {"recovery_max_s", r.recovery_max_s},
          {"contact_ticks", r.contact_ticks},
          {"contact_fraction", r.ticks > 0 ? static_cast<double>(r.contact_ticks) / static_cast<double>(r.ticks) : 0.0},
          {"min_contact_fraction", r.min_contact_fraction},
          {"wall_s", r.wall_s},
          {"note", r.note}};
}

StressRow stress_row_from_json(const nlohmann::json& j) {
  StressRow r;
  j.at("name").get_to(r.name);
  j.at("group").get_to(r.group);
  j.at("seed").get_to(r.seed);
  j.at("passed").get_to(r.passed);
  j.at("known_failure").get_to(r.known_failure);
  j.at("failures").get_to(r.failures);
  j.at("ticks").get_to(r.ticks);
  j.at("host_steps").get_to(r.host_steps);
  j.at("force_max_n").get_to(r.force_max_n);
  j.at("force_limit_n").get_to(r.force_limit_n);
  j.at("energy_max_j").get_to(r.energy_max_j);
  j.at("energy_bound_j").get_to(r.energy_bound_j);
  j.at("crossed_nodes_max").get_to(r.crossed_nodes_max);
  j.at("host_penetration_max_mm").get_to(r.host_penetration_max_mm);
  j.at("fault_bits_seen").get_to(r.fault_bits_seen);
  j.at("fault_bits_allowed").get_to(r.fault_bits_allowed);
  j.at("fault_onsets").get_to(r.fault_onsets);
  j.at("proxies_rejected").get_to(r.proxies_rejected);
  j.at("injected_events").get_to(r.injected_events);
  j.at("recoveries_required").get_to(r.recoveries_required);
  j.at("recoveries_done").get_to(r.recoveries_done);
  j.at("recovery_max_s").get_to(r.recovery_max_s);
  j.at("contact_ticks").get_to(r.contact_ticks);
  j.at("min_contact_fraction").get_to(r.min_contact_fraction);
  j.at("wall_s").get_to(r.wall_s);
  j.at("note").get_to(r.note);
  return r;
}

}  // namespace fissure::app
