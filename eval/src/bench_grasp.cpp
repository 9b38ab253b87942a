// `fissure bench grasp` (bench_grasp.hpp). The bounds are issue 23's: the vessel's centre of mass
// rises with the jaws within 2 mm, no contact node slides more than 0.5 mm along a jaw during the
// 1 s hold, opened jaws carry 0 N within 5 ms of clearing the vessel, at μ = 0.05 the lift slips
// out, and the pull-out force grows with the grip force with slope 2μ within 10 %.
#include "fissure/eval/bench_grasp.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fissure/eval/grasp.hpp"
#include "fissure/eval/sim_report.hpp"

namespace fissure::eval {

namespace {

constexpr double kRiseBound_m = 2.0e-3;
constexpr double kSlideBound_m = 0.5e-3;
constexpr double kReleaseBound_s = 5.0e-3;
constexpr double kSlipperyRatio = 0.05;
// "Slips out": the vessel ends the hold having risen less than half as far as the jaws.
constexpr double kSlippedRiseShare = 0.5;
constexpr double kSlopeBound = 0.10;
// Settle times besides the scene's 0.5 s the lift runs again with (bench_grasp says why).
constexpr std::array<double, 4> kLiftSettleTimes_s{0.4, 0.45, 0.55, 0.6};
constexpr double kPullFrictionRatio = 0.3;
// Drag felt: rt_core's rendered tangential force is μ·F_n within 10 % (median over the slide).
constexpr double kDragBound = 0.10;
constexpr std::array<double, 2> kDragHostRates_hz{1000.0, 100.0};

double seconds_since(std::chrono::steady_clock::time_point t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }

nlohmann::json check(const std::string& name, double value, double bound, bool pass, const std::string& what) {
  std::printf("  %-52s %10.4g  bound %-9.4g %s\n", name.c_str(), value, bound, pass ? "pass" : "MISS");
  return {{"name", name}, {"value", value}, {"bound", bound}, {"pass", pass}, {"measures", what}};
}

nlohmann::json lift_json(const GraspLiftResult& r, double wall_s) {
  return {{"friction_static_ratio", r.friction_static_ratio}, {"friction_kinetic_ratio", r.friction_kinetic_ratio},
          {"vessel_mass_kg", r.vessel_mass_kg}, {"jaw_rise_m", r.jaw_rise_m}, {"centroid_rise_m", r.centroid_rise_m},
          {"rise_shortfall_max_m", r.rise_shortfall_max_m}, {"hold_slide_max_m", r.hold_slide_max_m}, {"hold_contact_nodes", r.hold_contact_nodes},
          {"hold_grip_n", r.hold_grip_n}, {"hold_friction_up_n", r.hold_friction_up_n}, {"release_delay_s", r.release_delay_s},
          {"force_at_clear_n", r.force_at_clear_n}, {"crossed_nodes_max", r.crossed_nodes_max},
          {"cut_triangles_max", r.cut_triangles_max}, {"finite", r.finite}, {"wall_s", wall_s}};
}

void print_lift(const char* label, const GraspLiftResult& r, double wall_s) {
  std::printf("  %s (mu %.2f / %.2f, vessel %.1f g): jaws rose %.2f mm, vessel %.2f mm (shortfall max %.2f mm); %d nodes on the jaws, max slide %.3f mm;\n"
              "    grip %.3f N per jaw, friction up %.3f N (weight %.3f N); 0 N %.1f ms after clearing (%.2g N then); crossed %d, cut %d; %.1f s\n",
              label, r.friction_static_ratio, r.friction_kinetic_ratio, r.vessel_mass_kg * 1e3, r.jaw_rise_m * 1e3, r.centroid_rise_m * 1e3,
              r.rise_shortfall_max_m * 1e3, r.hold_contact_nodes, r.hold_slide_max_m * 1e3, r.hold_grip_n, r.hold_friction_up_n, r.vessel_mass_kg * 9.81,
              r.release_delay_s * 1e3, r.force_at_clear_n, r.crossed_nodes_max, r.cut_triangles_max, wall_s);
}

}  // namespace

nlohmann::json run_bench_grasp(const BenchGraspOptions& options) {
  nlohmann::json out;
  out["machine"] = sim_machine_info();
  out["quick"] = options.quick;
  nlohmann::json checks = nlohmann::json::array();

  std::printf("grasp and lift (scenes/clamp-vessel-lift.toml: close to 22 mm, lift 20 mm, hold 1 s, lower, open):\n");
  GraspLiftOptions lift;
  lift.scene = grasp_lift_scene();
  auto t0 = std::chrono::steady_clock::now();
  const GraspLiftResult shipped = run_grasp_lift(lift);
  const double shipped_wall = seconds_since(t0);
  print_lift("shipped friction", shipped, shipped_wall);
  lift.friction_ratio_override = kSlipperyRatio;
  t0 = std::chrono::steady_clock::now();
  const GraspLiftResult slippery = run_grasp_lift(lift);
  const double slippery_wall = seconds_since(t0);
  print_lift("slippery", slippery, slippery_wall);
  out["lift"] = lift_json(shipped, shipped_wall);
  out["lift_slippery"] = lift_json(slippery, slippery_wall);
  // The take-up at the start of the lift depends on where the settled shell happens to lie when
  // the jaws close (docs/decisions.md, "Friction and grasp"): one settle time would report a lucky
  // or an unlucky grasp, so the target is checked on the worst of five.
  double shortfall_worst_m = shipped.rise_shortfall_max_m;
  double shortfall_best_m = shipped.rise_shortfall_max_m;
  bool rose = shipped.jaw_rise_m > 0.0;
  nlohmann::json settle_runs = nlohmann::json::array();
  settle_runs.push_back({{"settle_s", lift.settle_s}, {"rise_shortfall_max_m", shipped.rise_shortfall_max_m}});
  if (!options.quick) {
    GraspLiftOptions resettled = lift;
    resettled.friction_ratio_override = -1.0;
    for (const double settle_s : kLiftSettleTimes_s) {
      resettled.settle_s = settle_s;
      const GraspLiftResult r = run_grasp_lift(resettled);
      shortfall_worst_m = std::max(shortfall_worst_m, r.rise_shortfall_max_m);
      shortfall_best_m = std::min(shortfall_best_m, r.rise_shortfall_max_m);
      rose = rose && r.jaw_rise_m > 0.0;
      settle_runs.push_back({{"settle_s", settle_s}, {"rise_shortfall_max_m", r.rise_shortfall_max_m}});
    }
    std::printf("  shipped friction, settled %.2f–%.2f s before closing: shortfall %.2f … %.2f mm\n", kLiftSettleTimes_s.front(), kLiftSettleTimes_s.back(),
                shortfall_best_m * 1e3, shortfall_worst_m * 1e3);
  }
  out["lift_settle_times"] = settle_runs;
  checks.push_back(check("lift: vessel rise shortfall, max over the hold and settle times [m]", shortfall_worst_m, kRiseBound_m,
                         shortfall_worst_m <= kRiseBound_m && rose, "jaw rise − vessel rise since closing, worst of settle times 0.4–0.6 s"));
  checks.push_back(check("lift: node slide along a jaw during the hold [m]", shipped.hold_slide_max_m, kSlideBound_m,
                         shipped.hold_slide_max_m <= kSlideBound_m && shipped.hold_contact_nodes > 0, "max tangential slide of the nodes on the jaws at the hold's start"));
  checks.push_back(check("lift: 0 N after the jaws clear the vessel [s]", shipped.release_delay_s, kReleaseBound_s,
                         shipped.release_delay_s >= 0.0 && shipped.release_delay_s <= kReleaseBound_s, "time from clearing to 0 N for good"));
  checks.push_back(check("lift at mu 0.05: vessel rise / jaw rise", slippery.centroid_rise_m / std::max(1e-12, slippery.jaw_rise_m), kSlippedRiseShare,
                         slippery.centroid_rise_m < kSlippedRiseShare * slippery.jaw_rise_m, "slips out: rises less than half as far as the jaws"));
  checks.push_back(check("lift: crossed nodes (shipped, slippery)", shipped.crossed_nodes_max + slippery.crossed_nodes_max, 0,
                         shipped.crossed_nodes_max + slippery.crossed_nodes_max == 0, "paired guarantee"));
  checks.push_back(check("lift: cut triangles > 0.1 mm (shipped, slippery)", shipped.cut_triangles_max + slippery.cut_triangles_max, 0,
                         shipped.cut_triangles_max + slippery.cut_triangles_max == 0, "every 10th step checked"));

  std::printf("\npull-out (scenes/clamp-vessel-retract.toml: far end tied, gripped near the free end, pulled along the vessel; mu = %.2f static = kinetic):\n",
              kPullFrictionRatio);
  const std::vector<double> gaps = options.quick ? std::vector<double>{0.026, 0.022, 0.018} : std::vector<double>{0.026, 0.024, 0.022, 0.020, 0.018};
  nlohmann::json pulls = nlohmann::json::array();
  std::vector<double> grip, pull;
  GraspPullOptions pull_options;
  pull_options.scene = grasp_pull_scene();
  pull_options.friction_ratio = kPullFrictionRatio;
  if (options.quick) pull_options.pull_distance_m = 0.012;
  int crossed = 0;
  for (const double gap : gaps) {
    pull_options.jaw_gap_m = gap;
    t0 = std::chrono::steady_clock::now();
    const GraspPullResult r = run_grasp_pull(pull_options);
    const double wall = seconds_since(t0);
    std::printf("  jaw gap %.1f mm: grip %.3f N per jaw, pull-out %.3f N (peak %.3f N), 2*mu*grip %.3f N, slid %.2f mm of %.1f, crossed %d; %.1f s\n",
                gap * 1e3, r.grip_n, r.pull_out_n, r.pull_peak_n, 2.0 * kPullFrictionRatio * r.grip_n, r.slip_m * 1e3, pull_options.pull_distance_m * 1e3,
                r.crossed_nodes_max, wall);
    pulls.push_back({{"jaw_gap_m", gap}, {"grip_n", r.grip_n}, {"pull_out_n", r.pull_out_n}, {"pull_peak_n", r.pull_peak_n}, {"slip_m", r.slip_m},
                     {"crossed_nodes_max", r.crossed_nodes_max}, {"finite", r.finite}, {"wall_s", wall}});
    grip.push_back(r.grip_n);
    pull.push_back(r.pull_out_n);
    crossed += r.crossed_nodes_max;
  }
  // Least-squares line pull = a + slope·grip.
  const double n = static_cast<double>(grip.size());
  double gm = 0.0, pm = 0.0;
  for (std::size_t i = 0; i < grip.size(); ++i) {
    gm += grip[i] / n;
    pm += pull[i] / n;
  }
  double sgg = 0.0, sgp = 0.0;
  for (std::size_t i = 0; i < grip.size(); ++i) {
    sgg += (grip[i] - gm) * (grip[i] - gm);
    sgp += (grip[i] - gm) * (pull[i] - pm);
  }
  const double slope = sgg > 0.0 ? sgp / sgg : 0.0;
  const double intercept = pm - slope * gm;
  const double slope_error = slope / (2.0 * kPullFrictionRatio) - 1.0;
  std::printf("  fit: pull-out = %.4f N + %.4f x grip (2 mu = %.3f)\n", intercept, slope, 2.0 * kPullFrictionRatio);
  out["pull_out"] = {{"friction_ratio", kPullFrictionRatio}, {"runs", pulls}, {"slope", slope}, {"intercept_n", intercept}, {"slope_relative_error", slope_error}};
  checks.push_back(check("pull-out: slope against grip / (2 mu) - 1", slope_error, kSlopeBound, std::abs(slope_error) <= kSlopeBound && grip.size() >= 3,
                         "least-squares slope of the sliding pull-out force against the per-jaw grip force"));
  checks.push_back(check("pull-out: crossed nodes", crossed, 0, crossed == 0, "paired guarantee"));

  std::printf("\ndrag felt (scenes/spatula-ball-drag.toml: lockstep session, SimFalcon's hand presses the spatula onto the ball with ~2 N and\n"
              "slides it 20 mm at 5 cm/s; the commanded force split along rt_core's contact normal, over the ticks the tool slides):\n");
  nlohmann::json drags = nlohmann::json::array();
  GraspDragOptions drag_options;
  drag_options.scene = grasp_drag_scene();
  for (const double host_rate_hz : kDragHostRates_hz) {
    drag_options.host_rate_hz = host_rate_hz;
    t0 = std::chrono::steady_clock::now();
    const GraspDragResult r = run_grasp_drag(drag_options);
    const double wall = seconds_since(t0);
    const double host_ratio = r.host_normal_median_n > 0.0 ? r.host_friction_median_n / r.host_normal_median_n : 0.0;
    std::printf("  host %4.0f Hz: %d slide ticks at %.1f cm/s, normal %.3f N, tangential %.3f N: ratio median %.4f (p10 %.4f, p90 %.4f) vs mu_k %.2f;\n"
                "    cone sliding on %.0f %% of them; host's own friction %.3f N on %.3f N normal (%.3f); max |dF|/tick %.4f N, observer max %.4f J, crossed %d; %.1f s\n",
                host_rate_hz, r.slide_ticks, r.slide_speed_median_m_per_s * 1e2, r.normal_median_n, r.tangential_median_n, r.ratio_median, r.ratio_p10,
                r.ratio_p90, r.friction_kinetic_ratio, 100.0 * r.sliding_tick_share, r.host_friction_median_n, r.host_normal_median_n, host_ratio,
                r.max_force_step_n, r.energy_max_j, r.crossed_nodes_max, wall);
    drags.push_back({{"host_rate_hz", host_rate_hz}, {"friction_static_ratio", r.friction_static_ratio},
                     {"friction_kinetic_ratio", r.friction_kinetic_ratio}, {"slide_ticks", r.slide_ticks},
                     {"slide_speed_median_m_per_s", r.slide_speed_median_m_per_s}, {"normal_median_n", r.normal_median_n},
                     {"tangential_median_n", r.tangential_median_n}, {"ratio_median", r.ratio_median}, {"ratio_p10", r.ratio_p10},
                     {"ratio_p90", r.ratio_p90}, {"sliding_tick_share", r.sliding_tick_share}, {"host_friction_median_n", r.host_friction_median_n},
                     {"host_normal_median_n", r.host_normal_median_n}, {"max_force_step_n", r.max_force_step_n}, {"energy_max_j", r.energy_max_j},
                     {"crossed_nodes_max", r.crossed_nodes_max}, {"finite", r.finite}, {"wall_s", wall}});
    const double error = r.friction_kinetic_ratio > 0.0 ? r.ratio_median / r.friction_kinetic_ratio - 1.0 : 1.0;
    char name[96];
    std::snprintf(name, sizeof name, "drag at host %.0f Hz: rendered tangential / (mu_k F_n) - 1", host_rate_hz);
    checks.push_back(check(name, error, kDragBound, std::abs(error) <= kDragBound && r.slide_ticks > 0 && r.finite,
                           "median over the slide of the commanded force's tangential / normal part, against mu_k"));
  }
  out["drag"] = drags;
  out["checks"] = checks;
  return out;
}

}  // namespace fissure::eval
