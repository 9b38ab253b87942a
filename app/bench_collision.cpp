// `fissure bench collision --json FILE [--quick]`: issue 5's benchmark of the thin-body
// collision methods. Four parts, every one a table over a knob:
//   1. tunnelling sweep: speed × tool × method → crossed nodes, max penetration, force
//      force jitter and drift during a hold, median step time;
//   2. quasi-static force–indentation: plate into a flat slab (fitted exponent vs n) and
//      into the sphere (fitted vs the rigid-cap prediction n + 1);
//   3. mesh convergence: the sphere's force at a fixed depth per mesh size;
//   4. cost vs mesh size, in and out of contact, total and collision-only.
// All runs are lockstep (simulated time); only the step times are wall clock.
#include "bench_collision.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "sim_report.hpp"

namespace fissure::app {

namespace {

using host::HostSimulation;
using host::SceneCollisionMethod;
using host::SceneDescription;

// Where the leading face of the tool starts above the settled soft surface, and how deep
// it goes in the sweep (BRIEF §3's measurement: a plate driven down into the sphere).
constexpr double kSweepStartClearanceM = 0.015;
constexpr double kSweepDepthM = 0.02;
constexpr double kSettleS = 0.3;
// After the plunge stops, the hold's force is measured only after this settling window: a fast
// plunge hands the enforced nodes the tool's speed and they keep it for one step when the tool
// stops (the light shell rings or is dented away from the plate), which is the soft body's
// response to the impact, not force noise of the contact at rest.
constexpr double kHoldSettleS = 0.05;
// Pose-matching coefficient (Bullet kMT) of the indentation / convergence specimens; 0.05 is
// the collision unit tests' springy ball (tests/host_sim/soft_scene_fixture.hpp).
constexpr double kShapeMatchingRatio = 0.05;

struct BenchOptions {
  std::string json_path;
  bool quick = false;
};

struct SweepTool {
  std::string name;
  host::ToolKind kind;
  Vec3 size_m;          // box
  Vec3 rpy_deg;         // orientation
  double leading_half_m;  // distance from the tool origin to its leading (lowest) point
};

SceneDescription base_scene() { return host::load_scene(host::resolve_scene_path("spatula-sphere")); }

Quat quat_rpy_deg(const Vec3& rpy) {
  const double k = M_PI / 360.0;
  const double cr = std::cos(rpy[0] * k), sr = std::sin(rpy[0] * k), cp = std::cos(rpy[1] * k), sp = std::sin(rpy[1] * k);
  const double cy = std::cos(rpy[2] * k), sy = std::sin(rpy[2] * k);
  return {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy};
}

SceneDescription with_tool(const SceneDescription& base, const SweepTool& tool) {
  SceneDescription s = base;
  if (tool.kind == host::ToolKind::kConvexMesh) {
    const SceneDescription convex = host::load_scene(host::resolve_scene_path("convex-spatula-sphere"));
    s.tool = convex.tool;
  } else {
    s.tool.kind = host::ToolKind::kBox;
    s.tool.box_size_m = tool.size_m;
  }
  s.trajectory.start.orientation_world = quat_rpy_deg(tool.rpy_deg);
  return s;
}

struct LineFit {
  double mean = 0.0, slope_per_sample = 0.0, residual_stddev = 0.0;
};

// Least-squares line through v[i] against i; residual standard deviation with n − 2 dof.
LineFit fit_line(const std::vector<double>& v) {
  LineFit fit;
  const auto n = static_cast<double>(v.size());
  if (v.empty()) return fit;
  for (double x : v) fit.mean += x;
  fit.mean /= n;
  if (v.size() < 3) return fit;
  const double i_mean = 0.5 * (n - 1.0);
  double sii = 0.0, siy = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double di = static_cast<double>(i) - i_mean;
    sii += di * di;
    siy += di * (v[i] - fit.mean);
  }
  fit.slope_per_sample = siy / sii;
  double ss = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double r = v[i] - fit.mean - fit.slope_per_sample * (static_cast<double>(i) - i_mean);
    ss += r * r;
  }
  fit.residual_stddev = std::sqrt(ss / (n - 2.0));
  return fit;
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

struct SweepCell {
  int crossed = 0, wrong_side = 0, inside = 0;
  double max_penetration_m = 0.0, hold_force_n = 0.0, median_us = 0.0, p99_us = 0.0;
  // Over the hold's measuring window, with F(t) fitted by a least-squares line: jitter = residual
  // standard deviation / mean, drift = the line's change over the window / mean. Both are
  // undefined (no contact) when the mean force is 0 — the plate lost the ball.
  double jitter = 0.0, drift = 0.0;
  bool in_contact = false;
};

SweepCell run_sweep_cell(const SceneDescription& scene, SceneCollisionMethod method, double speed_m_s, double leading_half_m, double hold_s) {
  HostSimulation sim(scene, method);
  const double dt = scene.simulation.time_step_s;
  // Start well clear, settle, then find the soft surface's top.
  host::ToolPose pose = host::to_tool_pose(scene.trajectory.start);
  pose.position_world_m.y() = 0.2;
  (void)sim.step(pose);
  sim.settle(kSettleS);
  const double top_m = sim.soft_bounds_world_m().max().y();
  pose.position_world_m.y() = top_m + kSweepStartClearanceM + leading_half_m;
  const double end_y = top_m - kSweepDepthM + leading_half_m;
  // Put the tool at the start pose first (out of contact): plunging straight from the settle
  // pose (0.2 m) would make the first plunge step a ~0.12 m jump, i.e. well above the nominal speed.
  (void)sim.step(pose);
  SweepCell cell;
  std::vector<double> step_s, hold_force;
  auto record = [&](const host::HostStepResult& r) {
    cell.crossed = std::max(cell.crossed, r.crossing.crossed_nodes);
    cell.wrong_side = std::max(cell.wrong_side, r.crossing.wrong_side_nodes);
    cell.inside = std::max(cell.inside, r.crossing.inside_nodes);
    cell.max_penetration_m = std::max(cell.max_penetration_m, r.crossing.max_penetration_m);
    step_s.push_back(r.times.total_s);
  };
  while (pose.position_world_m.y() > end_y) {
    pose.position_world_m.y() = std::max(end_y, pose.position_world_m.y() - speed_m_s * dt);
    record(sim.step(pose));
  }
  const long settle_steps = std::lround(kHoldSettleS / dt);
  const long hold_steps = std::lround(hold_s / dt);
  for (long i = 0; i < settle_steps + hold_steps; ++i) {
    const host::HostStepResult& r = sim.step(pose);
    record(r);
    if (i >= settle_steps) hold_force.push_back(r.force_on_tool_world_n.norm());
  }
  const LineFit fit = fit_line(hold_force);
  cell.in_contact = fit.mean > 0.0;
  cell.jitter = cell.in_contact ? fit.residual_stddev / fit.mean : 0.0;
  cell.drift = cell.in_contact ? fit.slope_per_sample * static_cast<double>(hold_force.size()) / fit.mean : 0.0;
  double mean = 0.0;
  for (double f : hold_force) mean += f;
  cell.hold_force_n = hold_force.empty() ? 0.0 : mean / static_cast<double>(hold_force.size());
  cell.median_us = sim_quantile(step_s, 0.5) * 1e6;
  cell.p99_us = sim_quantile(step_s, 0.99) * 1e6;
  return cell;
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

SceneDescription sphere_scene(int faces, bool icosphere) {
  SceneDescription s = base_scene();
  host::SoftSphere sphere = std::get<host::SoftSphere>(s.soft_body.shape);
  sphere.faces_count = faces;
  sphere.tessellation = icosphere ? host::SphereTessellation::kIcosphere : host::SphereTessellation::kBulletEllipsoid;
  s.soft_body.shape = sphere;
  // The indentation is about the contact law, not the ball sagging: no gravity, the ball
  // just touches the ground. A plate wider than any contact patch.
  s.simulation.gravity_world_m_per_s2 = {0.0, 0.0, 0.0};
  // The Hunt-Crossley force at a fixed depth depends on the contacted area, so the ball must
  // push back on the plate: an edge-link shell without pressure has no restoring force, its
  // cap falls away from a held plate (measured: 5120 faces went from 115 to 46 contacts over
  // 2.7 s) and the contact patch becomes a property of the mesh. Pose matching (Bullet kMT)
  // is the mesh-independent restoring force (each node pulled towards its rest place).
  s.soft_body.shape_matching_ratio = kShapeMatchingRatio;
  s.tool.box_size_m = {0.1, 0.002, 0.1};
  s.tool.node_spacing_m = 0.002;
  return s;
}

nlohmann::json run_bench(const BenchOptions& o) {
  nlohmann::json out;
  out["machine"] = sim_machine_info();
  out["quick"] = o.quick;
  const SceneDescription base = base_scene();
  const double n_configured = base.hunt_crossley.exponent_n;

  // ---- 1. Tunnelling sweep. -------------------------------------------------------------
  const std::vector<double> speeds = o.quick ? std::vector<double>{0.1, 10.0, 50.0} : std::vector<double>{0.1, 0.5, 1, 2, 5, 10, 20, 50};
  const std::vector<SweepTool> tools = {
      {"plate_4mm", host::ToolKind::kBox, {0.04, 0.004, 0.04}, {0, 0, 0}, 0.002},
      {"plate_1mm", host::ToolKind::kBox, {0.04, 0.001, 0.04}, {0, 0, 0}, 0.0005},
      // Thin axis (tool y) turned to world x: the 40 mm edge leads downwards.
      {"blade_edge_first", host::ToolKind::kBox, {0.04, 0.001, 0.04}, {0, 0, -90}, 0.02},
      {"convex_spatula", host::ToolKind::kConvexMesh, {0, 0, 0}, {0, 0, 0}, 0.001},
  };
  const std::vector<SceneCollisionMethod> methods = {SceneCollisionMethod::kBullet, SceneCollisionMethod::kRay, SceneCollisionMethod::kPaired};
  const double hold_s = o.quick ? 0.1 : 0.5;
  nlohmann::json sweep = nlohmann::json::array();
  SimProgress progress("bench collision: sweep", static_cast<long>(speeds.size() * tools.size() * methods.size()));
  long done = 0;
  std::printf("\n1. Tunnelling sweep (sphere 128 faces, 1 kHz, plunge %.0f mm, hold %.1f s)\n", kSweepDepthM * 1e3, hold_s);
  std::printf("(hold measured after a %.0f ms settling window; jitter = residual std / mean about a fitted line, drift = the line's\n"
              " change over the hold / mean; 'lost' = no contact left in the hold)\n", kHoldSettleS * 1e3);
  std::printf("%-17s %-7s %7s | %7s %7s %7s | %9s %8s %8s %9s %9s\n", "tool", "method", "v m/s", "crossed", "wrong", "inside", "pen mm",
              "jitter", "drift", "F_hold N", "med us");
  for (const SweepTool& tool : tools) {
    const SceneDescription scene = with_tool(base, tool);
    for (SceneCollisionMethod method : methods) {
      for (double v : speeds) {
        const SweepCell c = run_sweep_cell(scene, method, v, tool.leading_half_m, hold_s);
        progress.update(++done, tool.name + " " + host::to_string(method));
        char jitter[16] = "lost", drift[16] = "lost";
        if (c.in_contact) {
          std::snprintf(jitter, sizeof jitter, "%.4f", c.jitter);
          std::snprintf(drift, sizeof drift, "%+.4f", c.drift);
        }
        std::printf("\r%-17s %-7s %7.1f | %7d %7d %7d | %9.3f %8s %8s %9.3f %9.1f\033[K\n", tool.name.c_str(), host::to_string(method), v, c.crossed,
                    c.wrong_side, c.inside, c.max_penetration_m * 1e3, jitter, drift, c.hold_force_n, c.median_us);
        sweep.push_back({{"method", host::to_string(method)}, {"tool", tool.name}, {"speed_m_s", v}, {"crossed_nodes", c.crossed},
                         {"wrong_side_nodes", c.wrong_side}, {"inside_nodes", c.inside}, {"max_penetration_m", c.max_penetration_m},
                         {"force_jitter", c.in_contact ? nlohmann::json(c.jitter) : nlohmann::json(nullptr)},
                         {"force_drift", c.in_contact ? nlohmann::json(c.drift) : nlohmann::json(nullptr)},
                         {"hold_in_contact", c.in_contact}, {"hold_settle_s", kHoldSettleS}, {"hold_force_n", c.hold_force_n}, {"step_median_us", c.median_us}, {"step_p99_us", c.p99_us}});
      }
    }
  }
  progress.finish("");
  out["sweep"] = sweep;

  // ---- 2 + 3. Indentation and convergence. -------------------------------------------------
  const std::vector<int> mesh_faces = o.quick ? std::vector<int>{320, 1280, 5120} : std::vector<int>{320, 1280, 5120, 20480};
  const double indent_hold_s = o.quick ? 0.03 : 0.08;
  std::printf("\n2. Quasi-static force-indentation (paired, Hunt-Crossley n = %.2f, %s)\n", n_configured,
              base.hunt_crossley.mode == host::HuntCrossleyMode::kPerUnitArea ? "per unit area" : "per triangle");
  {
    SceneDescription slab = base;
    host::SoftSlab shape;
    shape.center_world_m = {0.0, 0.0125, 0.0};
    shape.size_m = {0.08, 0.02, 0.08};
    shape.top_cells_count = {16, 16};
    slab.soft_body.shape = shape;
    slab.simulation.gravity_world_m_per_s2 = {0.0, 0.0, 0.0};
    slab.soft_body.shape_matching_ratio = kShapeMatchingRatio;  // see sphere_scene()
    slab.tool.box_size_m = {0.04, 0.002, 0.04};  // smaller than the slab: the contact set is fixed
    slab.tool.node_spacing_m = 0.002;
    const std::vector<double> depths = {0.0005, 0.001, 0.0015, 0.002, 0.003, 0.004};
    const auto slab_curve = indentation_curve(slab, depths, indent_hold_s);
    const double slab_n = fitted_exponent(slab_curve);
    const SceneDescription sphere = sphere_scene(mesh_faces.back(), true);
    const std::vector<double> sphere_depths = {0.001, 0.002, 0.003, 0.004, 0.005, 0.006};
    const auto sphere_curve = indentation_curve(sphere, sphere_depths, indent_hold_s);
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
  }
  {
    constexpr double kDepthM = 0.004;
    std::printf("\n3. Mesh convergence: sphere force at %.0f mm (paired)\n%8s %12s\n", kDepthM * 1e3, "faces", "F N");
    nlohmann::json rows = nlohmann::json::array();
    for (int faces : mesh_faces) {
      const auto curve = indentation_curve(sphere_scene(faces, true), {kDepthM}, indent_hold_s);
      std::printf("%8d %12.5f\n", faces, curve[0].second);
      rows.push_back({{"faces", faces}, {"depth_m", kDepthM}, {"force_at_depth_n", curve[0].second}});
    }
    out["convergence"] = rows;
  }

  // ---- 4. Cost vs mesh size. -------------------------------------------------------------
  {
    std::printf("\n4. Cost vs mesh size (plate 100 x 2 x 100 mm; in contact at 4 mm depth)\n%-7s %8s %10s %12s %14s\n", "method", "faces",
                "contact", "step med us", "collision us");
    nlohmann::json rows = nlohmann::json::array();
    const long samples = o.quick ? 100 : 300;
    std::vector<std::pair<SceneCollisionMethod, SceneDescription>> cases;
    SceneDescription paper = sphere_scene(128, false);
    cases.emplace_back(SceneCollisionMethod::kBullet, paper);
    cases.emplace_back(SceneCollisionMethod::kPaired, paper);
    for (int faces : mesh_faces) cases.emplace_back(SceneCollisionMethod::kPaired, sphere_scene(faces, true));
    for (const auto& [method, scene] : cases) {
      for (bool in_contact : {false, true}) {
        HostSimulation sim(scene, method);
        host::ToolPose pose = host::to_tool_pose(scene.trajectory.start);
        pose.position_world_m.y() = 0.3;
        (void)sim.step(pose);
        sim.settle(0.05);
        const double top = sim.soft_bounds_world_m().max().y();
        // Out of contact: 2 cm above. In contact: approach quasi-statically (a jump would
        // hand the enforced nodes the jump's speed and launch the ball) to 4 mm depth.
        pose.position_world_m.y() = top + (in_contact ? 0.002 : 0.02) + 0.001;
        const double target_y = top - 0.004 + 0.001;
        while (in_contact && pose.position_world_m.y() > target_y) {
          pose.position_world_m.y() = std::max(target_y, pose.position_world_m.y() - 0.02 * scene.simulation.time_step_s);
          (void)sim.step(pose);
        }
        for (int i = 0; i < 50; ++i) (void)sim.step(pose);
        std::vector<double> total, collision;
        for (long i = 0; i < samples; ++i) {
          const host::HostStepResult& r = sim.step(pose);
          total.push_back(r.times.total_s);
          collision.push_back(r.times.collision_s);
        }
        const double med = sim_quantile(total, 0.5) * 1e6, col = sim_quantile(collision, 0.5) * 1e6;
        std::printf("%-7s %8d %10s %12.1f %14.2f\n", host::to_string(method), sim.soft_face_count(), in_contact ? "in" : "out", med, col);
        rows.push_back({{"method", host::to_string(method)}, {"faces", sim.soft_face_count()}, {"in_contact", in_contact},
                        {"step_median_us", med}, {"step_p99_us", sim_quantile(total, 0.99) * 1e6}, {"collision_median_us", col},
                        {"contacts", sim.last().contact_count}});
      }
    }
    out["scaling"] = rows;
  }
  return out;
}

}  // namespace

void register_bench_collision(CommandTree& tree) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* cmd = tree.bench.add_subcommand("collision", "Thin-body collision: tunnelling sweep, force-indentation, convergence, cost vs mesh");
  cmd->add_option("--json", options->json_path, "Write the results JSON here")->required();
  cmd->add_flag("--quick", options->quick, "CI-sized run (fewer speeds and meshes, shorter holds)");
  cmd->callback([options] {
    nlohmann::json result;
    try {
      result = run_bench(*options);
    } catch (const host::SceneError& e) {
      throw CommandError(e.what());
    }
    std::ofstream out(options->json_path);
    if (!out) throw CommandError("cannot write '" + options->json_path + "'");
    out << result.dump(2) << '\n';
    std::printf("\nwrote %s\n", options->json_path.c_str());
  });
}

}  // namespace fissure::app
