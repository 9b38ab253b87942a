// `fissure bench collision --json FILE [--quick | --full]`: the benchmark of the thin-body
// collision methods. Five parts, every one a table over a knob:
//   1. tunnelling sweep: speed × tool × method → crossed nodes, max penetration, force jitter
//      (detrended), std/mean, step noise and drift over a 0.5 s hold, cut triangles, median step
//      time; the paired cells again on a 1280-face icosphere;
//   1c/d. (part "cells") levering: the blade inserted edge-first and turned 30° about its edge;
//      clamp release: clamp-sphere's close–hold–open script after four settling times;
//   2. quasi-static force–indentation: plate into a flat slab (fitted exponent vs n) and
//      into the sphere (fitted vs the rigid-cap prediction n + 1);
//   3. mesh convergence: the sphere's force at a fixed depth per mesh size;
//   4. cost vs mesh size: out of contact, at the same press (4 mm: the contact set grows with the
//      mesh) and at the same contact (~24 contacted triangles on every mesh), with the collision's
//      stage split and the cost per contacted triangle; the scaling targets computed.
// The default run has every required cell; --full only takes more timing samples per part-4 row.
// All runs are lockstep (simulated time); only the step times are wall clock.
#include "fissure/eval/bench_collision.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fissure/eval/eval_error.hpp"
#include "fissure/host_sim/contact_cells.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/plunge_hold.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/eval/sim_report.hpp"

namespace fissure::eval {

namespace {

using host::HostSimulation;
using host::SceneCollisionMethod;
using host::SceneDescription;

// Settling time of the indentation / convergence specimens under gravity [s] (the sweep's own,
// host::kPlungeSettle_s).
constexpr double kSettleS = host::kPlungeSettle_s;
// Pose-matching coefficient (Bullet kMT) of the indentation / convergence specimens: the sweep
// ball's (host/plunge_hold.hpp says why a springy ball).
constexpr double kShapeMatchingRatio = host::kPlungeShapeMatchingRatio;
// Issue 22's second sweep mesh: an icosphere ten times finer than the paper's 128-face shell.
constexpr int kFineSweepFaces = 1280;
// Depth at which the mesh convergence compares the sphere's force [m].
constexpr double kConvergenceDepthM = 0.004;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// /proc/loadavg's 1-minute figure (0 when unreadable).
double load_average() {
  std::ifstream in("/proc/loadavg");
  double one_minute = 0.0;
  in >> one_minute;
  return one_minute;
}

SceneDescription base_scene() { return host::load_scene(host::resolve_scene_path("spatula-sphere")); }

// `scene` with the bench's contact response (BenchCollisionOptions::contact_response).
SceneDescription with_response(SceneDescription scene, host::ContactResponse response) {
  scene.simulation.contact_response = response;
  return scene;
}

// Least-squares slope of log F against log d (points with F > 0).
double fitted_exponent(const std::vector<std::pair<double, double>>& curve) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& [d, f] : curve) {
    if (d <= 0.0 || f <= 0.0) continue;
    const double x = std::log(d), y = std::log(f);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++n;
  }
  if (n < 2) return 0.0;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// Quasi-static indentation: step the tool down in increments, hold each depth so the
// damping term decays, read the force at the end of each hold.
std::vector<std::pair<double, double>> indentation_curve(const SceneDescription& scene, const std::vector<double>& depths_m, double hold_s,
                                                          double* top_out = nullptr) {
  HostSimulation sim(scene, SceneCollisionMethod::kPaired);
  const double dt = scene.simulation.time_step_s;
  host::ToolPose pose = host::to_tool_pose(scene.trajectory.start);
  pose.position_world_m.y() = 0.3;
  (void)sim.step(pose);
  sim.settle(kSettleS);
  const double top_m = sim.soft_bounds_world_m().max().y();
  if (top_out != nullptr) *top_out = top_m;
  const double half_thickness_m = 0.5 * scene.tool.box_size_m[1];
  constexpr double kApproachSpeedMS = 0.01;  // quasi-static
  pose.position_world_m.y() = top_m + 0.002 + half_thickness_m;
  std::vector<std::pair<double, double>> curve;
  for (double depth : depths_m) {
    const double target_y = top_m - depth + half_thickness_m;
    while (pose.position_world_m.y() > target_y) {
      pose.position_world_m.y() = std::max(target_y, pose.position_world_m.y() - kApproachSpeedMS * dt);
      (void)sim.step(pose);
    }
    const long hold_steps = std::lround(hold_s / dt);
    double force = 0.0;
    for (long i = 0; i < hold_steps; ++i) force = sim.step(pose).force_on_tool_world_n.norm();
    curve.emplace_back(depth, force);
  }
  return curve;
}

SceneDescription sphere_scene(int faces, bool icosphere, host::ContactResponse response) {
  SceneDescription s = with_response(base_scene(), response);
  host::SoftSphere sphere = std::get<host::SoftSphere>(s.soft_bodies.front().shape);
  sphere.faces_count = faces;
  sphere.tessellation = icosphere ? host::SphereTessellation::kIcosphere : host::SphereTessellation::kBulletEllipsoid;
  s.soft_bodies.front().shape = sphere;
  // The indentation is about the contact law, not the ball sagging: no gravity, the ball
  // just touches the ground. A plate wider than any contact patch.
  s.simulation.gravity_world_m_per_s2 = {0.0, 0.0, 0.0};
  // The Hunt-Crossley force at a fixed depth depends on the contacted area, so the ball must
  // push back on the plate: an edge-link shell without pressure has no restoring force, its
  // cap falls away from a held plate (a fine mesh loses more than half its contacts within
  // seconds) and the contact patch becomes a property of the mesh. Pose matching (Bullet kMT)
  // is the mesh-independent restoring force (each node pulled towards its rest place).
  s.soft_bodies.front().shape_matching_ratio = kShapeMatchingRatio;
  s.tool.box_size_m = {0.1, 0.002, 0.1};
  s.tool.node_spacing_m = 0.002;
  return s;
}

// A sweep or levering cell's scene: the shell cell (plunge_cell_scene) or its volumetric ball.
SceneDescription cell_scene(const host::PlungeTool& tool, int icosphere_faces, const BenchCollisionOptions& o) {
  if (o.soft_model == host::SoftBodyModel::kFem)
    return host::volumetric_plunge_scene(host::plunge_scene(tool, icosphere_faces), icosphere_faces, o.contact_response, o.in_solver_tool_friction);
  return host::plunge_cell_scene(tool, icosphere_faces, o.contact_response, o.in_solver_tool_friction);
}

// The methods a cell runs: Bullet's (and the ray method, with_ray) act on the classic soft body only.
std::vector<SceneCollisionMethod> cell_methods(const BenchCollisionOptions& o, bool with_ray) {
  if (o.soft_model == host::SoftBodyModel::kFem) return {SceneCollisionMethod::kPaired};
  if (with_ray) return {SceneCollisionMethod::kBullet, SceneCollisionMethod::kRay, SceneCollisionMethod::kPaired};
  return {SceneCollisionMethod::kBullet, SceneCollisionMethod::kPaired};
}

// What the sweep's JSON says of its ball: the shell's pose matching, or the volumetric ball's material.
nlohmann::json sweep_body_json(const BenchCollisionOptions& o, double hold_s) {
  nlohmann::json body = {{"plunge_depth_m", host::kPlungeDepth_m}, {"hold_s", hold_s}, {"hold_settle_s", host::kHoldSettle_s}};
  if (o.soft_model == host::SoftBodyModel::kFem) {
    body["model"] = "fem";
    body["youngs_modulus_pa"] = host::kPlungeFemYoungsModulus_pa;
  } else {
    body["model"] = "shell";
    body["shape_matching_ratio"] = kShapeMatchingRatio;
  }
  return body;
}

// ---- 1. Tunnelling sweep: speed × tool × method, on the 128-face ball and (paired) on a 1280-face icosphere.
void print_sweep_legend(double hold_s) {
  std::printf("(hold: |F| every step for %.1f s after a %.0f ms settling window, fitted by a line; in %% of the mean force:\n"
              " jitter = residual std about the line, std = plain std, step = std of the step-to-step change / sqrt 2,\n"
              " drift = the line's change over the hold (the soft body relaxing); 'lost' = no contact left in the hold;\n"
              " 'NONFINITE' = the soft body went non-finite, the cell stopped there with every node counted crossed)\n", hold_s, host::kHoldSettle_s * 1e3);
  std::printf(" cut = soft triangles reaching > %.1f mm into the tool during the hold, most on a step / steps with any (nodes may all be outside))\n",
              host::kInsideToleranceM * 1e3);
  std::printf("%-17s %-7s %7s | %7s %7s %7s | %9s %8s %8s %8s %8s %9s %9s %9s\n", "tool", "method", "v m/s", "crossed", "wrong", "inside", "pen mm",
              "jitter%", "std%", "step%", "drift%", "F_hold N", "med us", "cut");
}

// One sweep table: every tool × method × speed on the ball of `icosphere_faces` (0: the paper's 128-face shell).
nlohmann::json sweep_cells(const std::vector<double>& speeds, const std::vector<SceneCollisionMethod>& methods, int icosphere_faces, double hold_s,
                           const BenchCollisionOptions& o, const char* progress_name) {
  const auto& tools = host::plunge_tools();
  nlohmann::json sweep = nlohmann::json::array();
  SimProgress progress(progress_name, static_cast<long>(speeds.size() * tools.size() * methods.size()));
  long done = 0;
  for (const host::PlungeTool& tool : tools) {
    const SceneDescription scene = cell_scene(tool, icosphere_faces, o);
    const std::string tool_name(tool.name);
    for (SceneCollisionMethod method : methods) {
      for (double v : speeds) {
        const host::PlungeHoldResult c = host::run_plunge_hold(scene, method, v, tool.leading_half_m, hold_s, /*count_cut_triangles=*/true);
        const host::HoldForceStats& h = c.hold;
        const double median_us = sim_quantile(c.step_s, 0.5) * 1e6;
        const double p99_us = sim_quantile(c.step_s, 0.99) * 1e6;
        progress.update(++done, tool_name + " " + host::to_string(method));
        const char* no_hold = c.non_finite ? "NONFINITE" : "lost";
        char jitter[16], drift[16], std_over_mean[16], step_noise[16];
        for (char* field : {jitter, drift, std_over_mean, step_noise}) std::snprintf(field, 16, "%s", no_hold);
        if (h.in_contact) {
          std::snprintf(jitter, sizeof jitter, "%.3f", 100.0 * h.jitter);
          std::snprintf(std_over_mean, sizeof std_over_mean, "%.3f", 100.0 * h.std_over_mean);
          std::snprintf(step_noise, sizeof step_noise, "%.3f", 100.0 * h.step_noise);
          std::snprintf(drift, sizeof drift, "%+.2f", 100.0 * h.drift);
        }
        std::printf("\r%-17s %-7s %7.1f | %7d %7d %7d | %9.3f %8s %8s %8s %8s %9.3f %9.1f %4d/%-4d\033[K\n", tool_name.c_str(),
                    host::to_string(method), v, c.crossed_nodes, c.wrong_side_nodes, c.inside_nodes, c.max_penetration_m * 1e3, jitter, std_over_mean,
                    step_noise, drift, h.mean_n, median_us, c.hold_max_cut_triangles, c.hold_steps_with_cut_triangles);
        const auto if_contact = [&](double x) { return h.in_contact ? nlohmann::json(x) : nlohmann::json(nullptr); };
        sweep.push_back({{"method", host::to_string(method)}, {"tool", tool_name}, {"speed_m_s", v}, {"crossed_nodes", c.crossed_nodes},
                         {"wrong_side_nodes", c.wrong_side_nodes}, {"inside_nodes", c.inside_nodes}, {"max_penetration_m", c.max_penetration_m},
                         {"force_jitter", if_contact(h.jitter)}, {"force_std_over_mean", if_contact(h.std_over_mean)},
                         {"force_step_noise", if_contact(h.step_noise)}, {"force_drift", if_contact(h.drift)}, {"hold_in_contact", h.in_contact},
                         {"hold_settle_s", host::kHoldSettle_s}, {"hold_force_n", h.mean_n}, {"step_median_us", median_us}, {"step_p99_us", p99_us},
                         {"hold_steps", c.hold_force_n.size()}, {"hold_max_cut_triangles", c.hold_max_cut_triangles},
                         {"hold_steps_with_cut_triangles", c.hold_steps_with_cut_triangles}, {"non_finite", c.non_finite}});
      }
    }
  }
  progress.finish("");
  return sweep;
}

void run_sweep(const BenchCollisionOptions& o, nlohmann::json& out) {
  const std::vector<double> speeds = o.quick ? std::vector<double>{0.1, 10.0, 50.0} : std::vector<double>{0.1, 0.5, 1, 2, 5, 10, 20, 50};
  const double hold_s = o.quick ? 0.1 : 0.5;
  const bool fem = o.soft_model == host::SoftBodyModel::kFem;
  if (fem) {
    std::printf("\n1. Tunnelling sweep on the volumetric ball (the 128-face surface filled with tetrahedra, FEM E %.0f kPa, on its bed, %s;"
                " 1 kHz, plunge %.0f mm, hold %.1f s)\n", host::kPlungeFemYoungsModulus_pa * 1e-3, host::to_string(o.contact_response),
                host::kPlungeDepth_m * 1e3, hold_s);
  } else {
    std::printf("\n1. Tunnelling sweep (sphere 128 faces with pose matching kMT %.2f, 1 kHz, plunge %.0f mm, hold %.1f s)\n", kShapeMatchingRatio,
                host::kPlungeDepth_m * 1e3, hold_s);
  }
  out["sweep_body"] = sweep_body_json(o, hold_s);
  out["sweep_body"]["faces"] = 128;
  print_sweep_legend(hold_s);
  out["sweep"] = sweep_cells(speeds, cell_methods(o, /*with_ray=*/true), 0, hold_s, o, "bench collision: sweep");
  std::printf("\n1b. The same paired cells on a %d-face icosphere (issue 22's second mesh)\n", kFineSweepFaces);
  out["sweep_fine_body"] = sweep_body_json(o, hold_s);
  out["sweep_fine_body"]["faces"] = kFineSweepFaces;
  out["sweep_fine_body"]["tessellation"] = "icosphere";
  print_sweep_legend(hold_s);
  out["sweep_fine"] =
      sweep_cells(speeds, {SceneCollisionMethod::kPaired}, kFineSweepFaces, hold_s, o, "bench collision: sweep, 1280 faces");
}

// ---- 1c. Levering and clamp-release cells (issue 22) -------------------------------------------
void run_motion_cells(const BenchCollisionOptions& o, nlohmann::json& out) {
  const double hold_s = o.quick ? 0.1 : 0.5;
  std::printf("\n1c. Levering: the 1 mm blade inserted edge-first %.0f mm at %.1f m/s, turned %.0f deg about its edge at %.1f rad/s, held %.1f s\n",
              host::kPlungeDepth_m * 1e3, host::kLeverInsertSpeed_m_s, host::kLeverAngle_rad * 180.0 / 3.141592653589793, host::kLeverRate_rad_s,
              hold_s);
  std::printf("%-8s %-7s | %7s %7s %9s | %9s %8s %8s %9s | %9s %9s\n", "mesh", "method", "crossed", "inside", "pen mm", "cut max", "cut stp", "steps",
              "F_hold N", "jitter%", "step%");
  nlohmann::json lever = nlohmann::json::array();
  for (const int faces : {0, kFineSweepFaces}) {
    const SceneDescription scene = cell_scene(host::plunge_tools()[2], faces, o);
    for (SceneCollisionMethod method : cell_methods(o, /*with_ray=*/false)) {
      const host::LeverResult r = host::run_lever_hold(scene, method, hold_s);
      const int mesh = faces == 0 ? 128 : faces;
      std::printf("%-8d %-7s | %7d %7d %9.3f | %9d %8d %8d %9.3f | %9.3f %9.3f\n", mesh, host::to_string(method), r.crossed_nodes, r.inside_nodes,
                  r.max_penetration_m * 1e3, r.max_cut_triangles, r.steps_with_cut_triangles, r.steps, r.hold.mean_n, 100.0 * r.hold.jitter,
                  100.0 * r.hold.step_noise);
      const auto if_contact = [&](double x) { return r.hold.in_contact ? nlohmann::json(x) : nlohmann::json(nullptr); };
      lever.push_back({{"faces", mesh}, {"method", host::to_string(method)}, {"crossed_nodes", r.crossed_nodes}, {"inside_nodes", r.inside_nodes},
                       {"max_penetration_m", r.max_penetration_m}, {"max_cut_triangles", r.max_cut_triangles},
                       {"steps_with_cut_triangles", r.steps_with_cut_triangles}, {"steps", r.steps}, {"hold_force_n", r.hold.mean_n},
                       {"force_jitter", if_contact(r.hold.jitter)}, {"force_step_noise", if_contact(r.hold.step_noise)},
                       {"step_median_us", sim_quantile(r.step_s, 0.5) * 1e6}});
    }
  }
  out["lever"] = lever;
  if (o.soft_model == host::SoftBodyModel::kFem) {
    std::printf("\n1d. Clamp release: not run on the volumetric ball (the clamp cell's ball is clamp-sphere's shell)\n");
    return;
  }

  const SceneDescription clamp = host::clamp_cell_scene(o.contact_response, o.in_solver_tool_friction);
  std::printf("\n1d. Clamp release: clamp-sphere's script (close, hold, open fully) after settling; the larger jaw's |F| from the %dth fully open step\n",
              host::kClampOpenGraceSteps + 1);
  std::printf("%-8s %-7s | %9s %9s %9s | %7s %9s %9s\n", "settle s", "method", "F_max N", "open N", "open stp", "crossed", "cut max", "cut stp");
  nlohmann::json release = nlohmann::json::array();
  for (const double settle_s : {0.1, 0.2, 0.3, 0.5}) {
    for (SceneCollisionMethod method : {SceneCollisionMethod::kBullet, SceneCollisionMethod::kPaired}) {
      const host::ClampReleaseResult r = host::run_clamp_release(clamp, method, settle_s);
      std::printf("%-8.2f %-7s | %9.3f %9.4f %9d | %7d %9d %9d\n", settle_s, host::to_string(method), r.script_max_force_n, r.open_force_max_n,
                  r.open_steps, r.crossed_nodes, r.max_cut_triangles, r.steps_with_cut_triangles);
      release.push_back({{"settle_s", settle_s}, {"method", host::to_string(method)}, {"script_max_force_n", r.script_max_force_n},
                         {"open_force_max_n", r.open_force_max_n}, {"open_steps", r.open_steps}, {"open_grace_steps", host::kClampOpenGraceSteps},
                         {"crossed_nodes", r.crossed_nodes}, {"max_penetration_m", r.max_penetration_m}, {"max_cut_triangles", r.max_cut_triangles},
                         {"steps_with_cut_triangles", r.steps_with_cut_triangles}, {"step_median_us", sim_quantile(r.step_s, 0.5) * 1e6}});
    }
  }
  out["clamp_release"] = release;
}

// ---- 2. Quasi-static force-indentation: a flat slab and the finest sphere. --------------------
// Returns the finest sphere's force at kConvergenceDepthM: its curve includes that depth, so the
// convergence table reads its point off the curve (one 20 480-face run instead of two — the
// finest mesh is most of the bench's time).
double run_indentation(const SceneDescription& base, const std::vector<int>& mesh_faces, double indent_hold_s, nlohmann::json& out) {
  const double n_configured = base.hunt_crossley.n;
  std::printf("\n2. Quasi-static force-indentation (paired, Hunt-Crossley n = %.2f, %s)\n", n_configured,
              base.hunt_crossley.per_unit_area ? "per unit area" : "per triangle");
  double finest_force_at_depth_n = 0.0;
  SceneDescription slab = base;
  host::SoftSlab shape;
  shape.center_world_m = {0.0, 0.0125, 0.0};
  shape.size_m = {0.08, 0.02, 0.08};
  shape.top_cells_count = {16, 16};
  slab.soft_bodies.front().shape = shape;
  slab.simulation.gravity_world_m_per_s2 = {0.0, 0.0, 0.0};
  slab.soft_bodies.front().shape_matching_ratio = kShapeMatchingRatio;  // see sphere_scene()
  slab.tool.box_size_m = {0.04, 0.002, 0.04};  // smaller than the slab: the contact set is fixed
  slab.tool.node_spacing_m = 0.002;
  const std::vector<double> depths = {0.0005, 0.001, 0.0015, 0.002, 0.003, 0.004};
  const auto slab_curve = indentation_curve(slab, depths, indent_hold_s);
  const double slab_n = fitted_exponent(slab_curve);
  const SceneDescription sphere = sphere_scene(mesh_faces.back(), true, base.simulation.contact_response);
  const std::vector<double> sphere_depths = {0.001, 0.002, 0.003, kConvergenceDepthM, 0.005, 0.006};
  const auto sphere_curve = indentation_curve(sphere, sphere_depths, indent_hold_s);
  finest_force_at_depth_n = sphere_curve[3].second;
  const double sphere_n = fitted_exponent(sphere_curve);
  std::printf("%-30s %10s %10s\n", "specimen", "fitted n", "expected");
  std::printf("%-30s %10.4f %10.4f\n", "flat slab (fixed contact set)", slab_n, n_configured);
  std::printf("%-30s %10.4f %10.4f (rigid cap n+1)\n", ("sphere " + std::to_string(mesh_faces.back()) + " faces").c_str(), sphere_n, n_configured + 1.0);
  auto curve_json = [](const std::vector<std::pair<double, double>>& c) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& [d, f] : c) a.push_back({{"depth_m", d}, {"force_n", f}});
    return a;
  };
  out["indentation"] = {{"configured_n", n_configured}, {"slab_fitted_n", slab_n}, {"sphere_fitted_n", sphere_n},
                        {"sphere_predicted_n", n_configured + 1.0}, {"sphere_faces", mesh_faces.back()},
                        {"slab_curve", curve_json(slab_curve)}, {"sphere_curve", curve_json(sphere_curve)},
                        {"hold_s", indent_hold_s}};
  return finest_force_at_depth_n;
}

// ---- 3. Mesh convergence: the sphere's force at a fixed depth per mesh size. ------------------
void run_convergence(const std::vector<int>& mesh_faces, double indent_hold_s, double finest_force_at_depth_n, host::ContactResponse response,
                     nlohmann::json& out) {
  std::printf("\n3. Mesh convergence: sphere force at %.0f mm (paired)\n%8s %12s\n", kConvergenceDepthM * 1e3, "faces", "F N");
  nlohmann::json rows = nlohmann::json::array();
  for (int faces : mesh_faces) {
    const bool finest = faces == mesh_faces.back();
    const double force = finest ? finest_force_at_depth_n : indentation_curve(sphere_scene(faces, true, response), {kConvergenceDepthM}, indent_hold_s)[0].second;
    std::printf("%8d %12.5f%s\n", faces, force, finest ? "  (from the indentation curve)" : "");
    rows.push_back({{"faces", faces}, {"depth_m", kConvergenceDepthM}, {"force_at_depth_n", force},
                    {"from_indentation_curve", finest}});
  }
  out["convergence"] = rows;
}

// ---- 4. Cost vs mesh size. -------------------------------------------------------------------
// One simulation per mesh: out of contact (2 cm above), then pressed quasi-statically and held
// at (b) the depth where the contact set first reaches kSameContactTriangles contacted
// triangles ("the same contact" on every mesh) and (a) 4 mm ("the same press": the contact
// set grows with the mesh density). Collision cost is the method's own time per step
// (HostStepTimes::collision_s) with its stages (CollisionStepResult::seconds_*).
constexpr int kSameContactTriangles = 24;
constexpr double kSamePressDepthM = 0.004;
constexpr double kMaxSearchDepthM = 0.025;       // the paper's 128-face ball needs ~1 cm for 24
constexpr double kScalingApproachSpeedMS = 0.02;  // quasi-static: a jump would launch the ball
constexpr long kScalingSettleSteps = 50;          // after reaching a depth, before sampling

// One mesh and method: the out, same-press and same-contact rows, appended to `rows`.
void measure_scaling_case(SceneCollisionMethod method, const SceneDescription& scene, long samples, nlohmann::json& rows) {
  const bool ours = method != SceneCollisionMethod::kBullet;
  HostSimulation sim(scene, method);
  const double dt = scene.simulation.time_step_s;
  const double half_thickness_m = 0.5 * scene.tool.box_size_m[1];
  host::ToolPose pose = host::to_tool_pose(scene.trajectory.start);
  pose.position_world_m.y() = 0.3;
  (void)sim.step(pose);
  sim.settle(0.05);
  const double top = sim.soft_bounds_world_m().max().y();
  auto measure = [&](const char* label, double depth_m) {
    for (long i = 0; i < kScalingSettleSteps; ++i) (void)sim.step(pose);
    std::vector<double> total, collision, broad, narrow, response, force, triangles;
    for (long i = 0; i < samples; ++i) {
      const host::HostStepResult& r = sim.step(pose);
      total.push_back(r.times.total_s);
      collision.push_back(r.times.collision_s);
      const host::CollisionStepResult& p = r.part_results[0];
      broad.push_back(p.seconds_broad);
      narrow.push_back(p.seconds_narrow);
      response.push_back(p.seconds_response);
      force.push_back(p.seconds_force);
      triangles.push_back(ours ? static_cast<double>(p.contacted_triangles) : static_cast<double>(r.contact_count));
    }
    const double tri = sim_quantile(triangles, 0.5);
    const double col_us = sim_quantile(collision, 0.5) * 1e6;
    const double per_tri_us = tri > 0.0 ? col_us / tri : 0.0;
    const bool in_contact = depth_m > 0.0;
    char per_tri[16] = "-";
    if (tri > 0.0) std::snprintf(per_tri, sizeof per_tri, "%.3f", per_tri_us);
    std::printf("%-7s %6d %-13s %7.2f %5.0f | %9.1f %9.2f %8s | %7.2f %7.2f %7.2f %7.2f\n", host::to_string(method), sim.soft_face_count(),
                label, depth_m * 1e3, tri, sim_quantile(total, 0.5) * 1e6, col_us, per_tri, sim_quantile(broad, 0.5) * 1e6,
                sim_quantile(narrow, 0.5) * 1e6, sim_quantile(response, 0.5) * 1e6, sim_quantile(force, 0.5) * 1e6);
    rows.push_back({{"method", host::to_string(method)}, {"faces", sim.soft_face_count()}, {"case", label}, {"in_contact", in_contact},
                    {"depth_m", depth_m}, {"contacted_triangles", tri}, {"step_median_us", sim_quantile(total, 0.5) * 1e6},
                    {"step_p99_us", sim_quantile(total, 0.99) * 1e6}, {"collision_median_us", col_us},
                    {"collision_p99_us", sim_quantile(collision, 0.99) * 1e6},
                    {"collision_us_per_contacted_triangle", tri > 0.0 ? nlohmann::json(per_tri_us) : nlohmann::json(nullptr)},
                    {"broad_median_us", sim_quantile(broad, 0.5) * 1e6}, {"narrow_median_us", sim_quantile(narrow, 0.5) * 1e6},
                    {"response_median_us", sim_quantile(response, 0.5) * 1e6}, {"force_median_us", sim_quantile(force, 0.5) * 1e6},
                    {"contacts", sim.last().contact_count}, {"samples", samples}});
  };
  // The plate's bottom face at `depth` below the settled top (negative: above it).
  auto plate_y = [&](double depth_m) { return top - depth_m + half_thickness_m; };
  pose.position_world_m.y() = plate_y(-0.02);
  (void)sim.step(pose);
  measure("out", -0.02);
  pose.position_world_m.y() = plate_y(-0.002);
  (void)sim.step(pose);
  // Press: (b) as soon as the contact set reaches the count (paired only: bullet reports no
  // contacted triangles of the same kind), (a) at 4 mm; in whichever order they come.
  bool same_contact_done = !ours;
  bool same_press_done = false;
  while (!(same_contact_done && same_press_done)) {
    const double depth = top + half_thickness_m - pose.position_world_m.y();
    if (!same_press_done && depth >= kSamePressDepthM - 1e-12) {
      measure("same_press", depth);
      same_press_done = true;
      continue;
    }
    if (!same_contact_done && sim.last().part_results[0].contacted_triangles >= kSameContactTriangles) {
      measure("same_contact", depth);
      same_contact_done = true;
      continue;
    }
    if (depth >= kMaxSearchDepthM) {
      std::printf("%-7s %6d %-13s never reached %d contacted triangles by %.0f mm\n", host::to_string(method), sim.soft_face_count(),
                  "same_contact", kSameContactTriangles, kMaxSearchDepthM * 1e3);
      break;
    }
    const double next = same_press_done ? plate_y(kMaxSearchDepthM) : plate_y(kSamePressDepthM);
    pose.position_world_m.y() = std::max(next, pose.position_world_m.y() - kScalingApproachSpeedMS * dt);
    (void)sim.step(pose);
  }
}

// The targets, computed from the scaling rows: out-of-contact collision ≤ 5 % of in contact on
// every mesh; at the same contact, collision cost ≤ 2× from the coarsest to the finest mesh; at
// the same press, cost per contacted triangle ≤ 2× likewise.
nlohmann::json scaling_summary(const nlohmann::json& rows, const std::vector<int>& mesh_faces) {
  auto row_of = [&](int faces, const std::string& label) -> const nlohmann::json* {
    for (const auto& r : rows)
      if (r["method"] == "paired" && r["faces"] == faces && r["case"] == label) return &r;
    return nullptr;
  };
  nlohmann::json summary;
  const int coarse = 128, fine = mesh_faces.back();
  double worst_out_ratio = 0.0;
  for (int faces : std::vector<int>{128, 320, 1280, 5120, 20480}) {
    const auto* r_out = row_of(faces, "out");
    const auto* r_in = row_of(faces, "same_contact");
    if (r_out == nullptr || r_in == nullptr) continue;
    worst_out_ratio = std::max(worst_out_ratio, (*r_out)["collision_median_us"].get<double>() / (*r_in)["collision_median_us"].get<double>());
  }
  summary["out_over_in_collision_worst"] = worst_out_ratio;
  const auto* c_b = row_of(coarse, "same_contact");
  const auto* f_b = row_of(fine, "same_contact");
  if (c_b != nullptr && f_b != nullptr)
    summary["same_contact_collision_ratio_fine_over_coarse"] =
        (*f_b)["collision_median_us"].get<double>() / (*c_b)["collision_median_us"].get<double>();
  const auto* c_a = row_of(coarse, "same_press");
  const auto* f_a = row_of(fine, "same_press");
  if (c_a != nullptr && f_a != nullptr && !(*c_a)["collision_us_per_contacted_triangle"].is_null() &&
      !(*f_a)["collision_us_per_contacted_triangle"].is_null())
    summary["same_press_per_triangle_ratio_fine_over_coarse"] = (*f_a)["collision_us_per_contacted_triangle"].get<double>() /
                                                                 (*c_a)["collision_us_per_contacted_triangle"].get<double>();
  summary["coarse_faces"] = coarse;
  summary["fine_faces"] = fine;
  return summary;
}

// What the node bounds cost where they are taken, inside Bullet's solve (NodeBoundsSolver, not
// in the collision times above): the finest ball out of contact, solved by the fused solve and
// by Bullet's stock one (the same simulation, bit for bit), steps interleaved and the order
// alternated so that neither always runs on the other's cache.
nlohmann::json solver_bounds_ab(const std::vector<int>& mesh_faces, long samples) {
  const SceneDescription scene = sphere_scene(mesh_faces.back(), true, host::ContactResponse::kAfterStep);
  HostSimulation fused(scene, SceneCollisionMethod::kPaired, host::HostSimulationOptions{true});
  HostSimulation stock(scene, SceneCollisionMethod::kPaired, host::HostSimulationOptions{false});
  host::ToolPose pose = host::to_tool_pose(scene.trajectory.start);
  pose.position_world_m.y() = 0.3;
  for (HostSimulation* sim : {&fused, &stock}) {
    (void)sim->step(pose);
    sim->settle(0.05);
  }
  std::vector<double> fused_s, stock_s;
  for (long i = 0; i < 2 * samples; ++i) {
    HostSimulation& first = i % 2 == 0 ? fused : stock;
    HostSimulation& second = i % 2 == 0 ? stock : fused;
    const double first_s = first.step(pose).times.bullet_s;
    const double second_s = second.step(pose).times.bullet_s;
    fused_s.push_back(i % 2 == 0 ? first_s : second_s);
    stock_s.push_back(i % 2 == 0 ? second_s : first_s);
  }
  // The ratio of each adjacent pair of steps, then its median: the VM's load drifts on a
  // scale of many steps, and a pair sees the same load.
  std::vector<double> pair_ratio;
  for (std::size_t i = 0; i < fused_s.size(); ++i) pair_ratio.push_back(fused_s[i] / stock_s[i]);
  const double fused_us = sim_quantile(fused_s, 0.5) * 1e6, stock_us = sim_quantile(stock_s, 0.5) * 1e6;
  const double ratio = sim_quantile(pair_ratio, 0.5);
  std::printf("node bounds inside Bullet's solve (%d faces, out of contact, %ld interleaved steps each): Bullet step median %.1f us fused vs "
              "%.1f us stock; median pair ratio %.3f (quartiles %.3f-%.3f)\n",
              fused.soft_face_count(), 2 * samples, fused_us, stock_us, ratio, sim_quantile(pair_ratio, 0.25), sim_quantile(pair_ratio, 0.75));
  return {{"faces", fused.soft_face_count()}, {"samples", 2 * samples}, {"bullet_step_median_us_fused", fused_us},
                             {"bullet_step_median_us_stock", stock_us}, {"ratio", ratio},
                             {"ratio_quartiles", {sim_quantile(pair_ratio, 0.25), sim_quantile(pair_ratio, 0.75)}}};
}

void run_scaling(const BenchCollisionOptions& o, const std::vector<int>& mesh_faces, nlohmann::json& out) {
  const long samples = o.quick ? 60 : (o.full ? 300 : 100);
  std::printf("\n4. Cost vs mesh size (plate 100 x 2 x 100 mm; out = 2 cm above; same press = %.0f mm deep;\n"
              "   same contact = first depth with >= %d contacted triangles; medians of %ld steps; us)\n",
              kSamePressDepthM * 1e3, kSameContactTriangles, samples);
  std::printf("%-7s %6s %-13s %7s %5s | %9s %9s %8s | %7s %7s %7s %7s\n", "method", "faces", "case", "depth mm", "tri", "step", "collision",
              "per tri", "broad", "narrow", "resp", "force");
  nlohmann::json rows = nlohmann::json::array();
  std::vector<std::pair<SceneCollisionMethod, SceneDescription>> cases;
  SceneDescription paper = sphere_scene(128, false, o.contact_response);
  cases.emplace_back(SceneCollisionMethod::kBullet, paper);
  cases.emplace_back(SceneCollisionMethod::kPaired, paper);
  for (int faces : mesh_faces) cases.emplace_back(SceneCollisionMethod::kPaired, sphere_scene(faces, true, o.contact_response));
  for (const auto& [method, scene] : cases) measure_scaling_case(method, scene, samples, rows);
  out["scaling"] = rows;
  const nlohmann::json summary = scaling_summary(rows, mesh_faces);
  out["scaling_summary"] = summary;
  out["solver_bounds_ab"] = solver_bounds_ab(mesh_faces, samples);
  std::printf("targets: out/in collision (worst mesh) %.3f (<= 0.05); same contact %d->%d faces %.2fx (<= 2); same press per triangle %.2fx (<= 2)\n",
              summary["out_over_in_collision_worst"].get<double>(), summary["coarse_faces"].get<int>(), summary["fine_faces"].get<int>(),
              summary.value("same_contact_collision_ratio_fine_over_coarse", 0.0), summary.value("same_press_per_triangle_ratio_fine_over_coarse", 0.0));
}

nlohmann::json run_parts(const BenchCollisionOptions& o) {
  const Clock::time_point bench_start = Clock::now();
  nlohmann::json out;
  out["machine"] = sim_machine_info();
  out["quick"] = o.quick;
  out["full"] = o.full;
  // The step times are wall clock on a shared VM: the load says how loaded it was.
  out["load_average_start"] = load_average();
  out["contact_response"] = host::to_string(o.contact_response);
  out["in_solver_tool_friction"] = o.in_solver_tool_friction;
  out["soft_model"] = o.soft_model == host::SoftBodyModel::kFem ? "fem" : "shell";
  if (o.soft_model == host::SoftBodyModel::kFem && (o.runs("indentation") || o.runs("scaling")))
    throw EvalError("bench collision: the volumetric ball (--soft-model fem) runs the sweep and cells parts only: add --only sweep --only cells");
  const SceneDescription base = with_response(base_scene(), o.contact_response);
  if (o.runs("sweep")) {
    run_sweep(o, out);
    out["sweep_seconds"] = seconds_since(bench_start);
  }
  if (o.runs("cells")) {
    const Clock::time_point cells_start = Clock::now();
    run_motion_cells(o, out);
    out["cells_seconds"] = seconds_since(cells_start);
  }
  const std::vector<int> mesh_faces = o.quick ? std::vector<int>{320, 1280, 5120} : std::vector<int>{320, 1280, 5120, 20480};
  if (o.runs("indentation")) {
    const Clock::time_point indentation_start = Clock::now();
    const double indent_hold_s = o.quick ? 0.03 : 0.08;
    const double finest_force_at_depth_n = run_indentation(base, mesh_faces, indent_hold_s, out);
    run_convergence(mesh_faces, indent_hold_s, finest_force_at_depth_n, o.contact_response, out);
    out["indentation_convergence_seconds"] = seconds_since(indentation_start);
  }
  if (o.runs("scaling")) {
    const Clock::time_point scaling_start = Clock::now();
    run_scaling(o, mesh_faces, out);
    out["scaling_seconds"] = seconds_since(scaling_start);
  }
  out["total_seconds"] = seconds_since(bench_start);
  out["load_average_end"] = load_average();
  return out;
}

}  // namespace

bool BenchCollisionOptions::runs(const char* part) const {
  return only.empty() || std::find(only.begin(), only.end(), part) != only.end();
}

nlohmann::json run_bench_collision(const BenchCollisionOptions& options) {
  try {
    return run_parts(options);
  } catch (const host::SceneError& e) {
    throw EvalError(e.what());
  }
}

}  // namespace fissure::eval
