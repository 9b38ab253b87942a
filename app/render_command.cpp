// `fissure render SCENE`: see render_command.hpp.
#include "render_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/proxy_builder.hpp"
#include "fissure/host_sim/proxy_model.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/viewer/frame_writer.hpp"
#include "fissure/viewer/orbit_camera.hpp"
#include "fissure/viewer/render_snapshot.hpp"
#include "fissure/viewer/view_window.hpp"
#include "fissure/eval/sim_report.hpp"

namespace fissure::app {
using namespace fissure::eval;  // sim_quantile, SimProgress, sim_machine_info
namespace {

using Clock = std::chrono::steady_clock;

// The plunge is `fissure bench collision`'s tunnelling sweep (app/bench_collision.cpp): start
// 15 mm above the settled soft top, stop 20 mm below it, the tool lifted to 0.2 m while the
// body settles.
constexpr double kPlungeStartClearanceM = 0.015;
constexpr double kPlungeDepthM = 0.02;
constexpr double kPlungeParkHeightM = 0.2;
// While paused or after the trajectory with the window open: how often the loop looks again.
constexpr std::chrono::milliseconds kIdlePoll{20};

host::SceneCollisionMethod next_method(host::SceneCollisionMethod m) {
  switch (m) {
    case host::SceneCollisionMethod::kPaired: return host::SceneCollisionMethod::kRay;
    case host::SceneCollisionMethod::kRay: return host::SceneCollisionMethod::kBullet;
    case host::SceneCollisionMethod::kBullet: return host::SceneCollisionMethod::kPaired;
  }
  return host::SceneCollisionMethod::kPaired;
}

// Half of the collidable part's extent along world y at the start orientation: the plunge
// starts and stops with the tool's leading face, as the bench does.
double leading_half_y_m(const host::SceneDescription& scene) {
  const host::ToolPartGeometry geometry = host::tool_part_geometry(scene);
  const Eigen::Matrix3d r = host::to_tool_pose(scene.trajectory.start).orientation_world.toRotationMatrix();
  return r.row(1).cwiseAbs().dot(geometry.box_half_extents_m);
}

struct Sinks {
  viewer::FrameWriter* frames = nullptr;
  viewer::ViewWindow* window = nullptr;
  viewer::SnapshotExchange* unread = nullptr;  // publish_only: an exchange nobody fetches
};

// One pass over the trajectory with one method. Returns the method to restart with when the
// window asked for a switch, nullopt when the pass ended.
std::optional<host::SceneCollisionMethod> run_pass(const RenderOptions& o, const host::SceneDescription& scene, host::SceneCollisionMethod method,
                                                   std::unique_ptr<viewer::RenderModel>& model, Sinks& sinks,
                                                   const std::function<void(const viewer::RenderModel&)>& on_model, RenderOutcome& out) {
  std::unique_ptr<host::HostSimulation> sim;
  try {
    sim = std::make_unique<host::HostSimulation>(scene, method);
  } catch (const std::exception& e) {
    throw CommandError(scene.source_path + ": cannot build the simulation: " + e.what());
  }
  const double dt = scene.simulation.time_step_s;
  host::ToolPose pose = host::to_tool_pose(scene.trajectory.start);
  double end_y = 0.0;
  long steps = 0;
  if (o.plunge_speed_m_per_s > 0.0) {
    host::ToolPose parked = pose;
    parked.position_world_m.y() = kPlungeParkHeightM;
    (void)sim->step(parked);
    sim->settle(o.settle_seconds);
    const double top_m = sim->soft_bounds_world_m().max().y();
    const double half = leading_half_y_m(scene);
    pose.position_world_m.y() = top_m + kPlungeStartClearanceM + half;
    end_y = top_m - kPlungeDepthM + half;
    const double travel_s = (pose.position_world_m.y() - end_y) / o.plunge_speed_m_per_s;
    steps = std::lround(std::ceil((o.seconds > 0.0 ? o.seconds : travel_s + o.plunge_hold_s) / dt));
  } else {
    sim->settle(o.settle_seconds);
    steps = std::lround((o.seconds > 0.0 ? o.seconds : host::trajectory_duration_s(scene)) / dt);
  }
  steps = std::max(1L, steps);
  if (!model) {
    try {
      model = std::make_unique<viewer::RenderModel>(viewer::make_render_model(*sim));
    } catch (const std::exception& e) {
      throw CommandError(e.what());
    }
    on_model(*model);
  }
  // The patches `fissure run` would send; none for the bullet method (no contact records).
  std::optional<host::ProxyBuilder> builder;
  if (auto m = host::proxy_model_for(scene, *sim)) builder.emplace(*m);
  ContactProxy proxy{};
  host::ProxyPartMotion motion;
  std::array<Eigen::Vector3d, host::kMaxToolParts> previous_part_p{};
  auto snapshot = std::make_unique<viewer::RenderSnapshot>();
  snapshot->overlay.method = method;

  if (!o.quiet) {
    std::printf("render %s: method %s, %ld steps of %.3g ms%s\n", scene.name.c_str(), host::to_string(method), steps, dt * 1e3,
                o.plunge_speed_m_per_s > 0.0 ? " (plunge)" : "");
  }
  out.scene = scene.name;
  out.method = host::to_string(method);
  out.steps = steps;
  out.step_s.reserve(out.step_s.size() + static_cast<std::size_t>(steps));
  out.publish_s.reserve(out.publish_s.size() + static_cast<std::size_t>(steps));
  const std::uint64_t switches_at_start = sinks.window != nullptr ? sinks.window->method_switch_requests() : 0;
  std::size_t next_frame_at = 0;
  const Clock::time_point wall_start = Clock::now();
  for (long i = 0; i < steps; ++i) {
    if (sinks.window != nullptr) {
      while (sinks.window->paused() && !sinks.window->closed() && sinks.window->method_switch_requests() == switches_at_start) {
        std::this_thread::sleep_for(kIdlePoll);
      }
      if (sinks.window->method_switch_requests() != switches_at_start) return next_method(method);
    }
    if (o.realtime || (sinks.window != nullptr && !sinks.window->closed())) {
      std::this_thread::sleep_until(wall_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(static_cast<double>(i) * dt)));
    }
    host::TrajectorySample target;
    if (o.plunge_speed_m_per_s > 0.0) {
      pose.position_world_m.y() = std::max(end_y, pose.position_world_m.y() - o.plunge_speed_m_per_s * dt);
      target.pose.position_world_m = to_vec3(pose.position_world_m);
      target.pose.orientation_world = {pose.orientation_world.w(), pose.orientation_world.x(), pose.orientation_world.y(), pose.orientation_world.z()};
    } else {
      target = sim->scripted_target();
    }
    const host::HostStepResult& r = sim->step(host::to_tool_pose(target.pose), target.jaw_gap_m);
    out.step_s.push_back(r.times.total_s);
    out.crossed_nodes_max = std::max(out.crossed_nodes_max, r.crossing.crossed_nodes);
    out.force_max_n = std::max(out.force_max_n, r.force_on_tool_world_n.norm());

    bool frame_due = false;
    if (sinks.frames != nullptr) {
      if (!o.frame_at_s.empty()) {
        if (next_frame_at < o.frame_at_s.size() && r.time_s >= o.frame_at_s[next_frame_at] - 0.5 * dt) {
          frame_due = true;
          while (next_frame_at < o.frame_at_s.size() && r.time_s >= o.frame_at_s[next_frame_at] - 0.5 * dt) ++next_frame_at;
        }
      } else {
        frame_due = i % o.frame_every == 0 || i + 1 == steps;
      }
    }
    const bool publish = frame_due || sinks.window != nullptr || sinks.unread != nullptr;
    if (!publish) continue;

    const Clock::time_point t0 = Clock::now();
    if (builder) {
      std::array<host::ToolPose, host::kMaxToolParts> parts{};
      host::tool_part_poses(scene, sim->tool_pose(), r.jaw_gap_m, parts);
      const host::ProxyBuilderModel& m = builder->model();
      for (int jaw = 0; jaw < m.jaw_count; ++jaw) {
        const auto j = static_cast<std::size_t>(jaw);
        const auto part = static_cast<std::size_t>(m.part_of_jaw[j]);
        const Eigen::Vector3d p = parts[j].position_world_m;
        motion.p_world_m[part] = p;
        motion.v_world_m_per_s[part] = i == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d((p - previous_part_p[j]) / dt);
        previous_part_p[j] = p;
      }
      (void)builder->build(r.contacts, sim->tool_pose(), motion, static_cast<TimeNs>(std::llround(r.time_s * 1e9)), proxy);
      viewer::capture_patches(proxy, *snapshot);
    }
    viewer::capture_snapshot(*sim, *snapshot);
    if (sinks.window != nullptr) {
      snapshot->overlay.paused = sinks.window->paused();
      sinks.window->exchange().publish(*snapshot);
    }
    if (sinks.unread != nullptr) sinks.unread->publish(*snapshot);
    if (frame_due) sinks.frames->publish(*snapshot);
    out.publish_s.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    if (frame_due && o.wait_for_frames) sinks.frames->wait_until_written(snapshot->sequence);
  }
  // Trajectory done: with the window still open, keep showing the end until it is closed or a
  // method switch restarts the scene.
  if (o.hold_view_at_end && sinks.window != nullptr && !sinks.window->closed()) {
    if (!o.quiet) std::printf("render %s: trajectory done; press M in the window to rerun with the next method, Q to quit\n", scene.name.c_str());
    while (!sinks.window->closed()) {
      if (sinks.window->method_switch_requests() != switches_at_start) return next_method(method);
      std::this_thread::sleep_for(kIdlePoll);
    }
  }
  return std::nullopt;
}

void print_summary(const RenderOptions& o, const RenderOutcome& r) {
  std::printf("host step median %.1f us, p99 %.1f us; snapshot capture+publish median %.2f us, p99 %.2f us (%zu publishes)\n",
              sim_quantile(r.step_s, 0.5) * 1e6, sim_quantile(r.step_s, 0.99) * 1e6, sim_quantile(r.publish_s, 0.5) * 1e6,
              sim_quantile(r.publish_s, 0.99) * 1e6, r.publish_s.size());
  std::printf("crossed nodes max %d, |F| max %.3f N\n", r.crossed_nodes_max, r.force_max_n);
  if (!o.frames_dir.empty()) {
    std::printf("frames: %llu written to %s (%llu dropped), %.1f ms per frame median [%s]\n",
                static_cast<unsigned long long>(r.frames_written), o.frames_dir.c_str(), static_cast<unsigned long long>(r.frames_dropped),
                sim_quantile(r.frame_s, 0.5) * 1e3, r.gl_description.c_str());
  }
  if (r.view_open) std::printf("view: %llu frames drawn\n", static_cast<unsigned long long>(r.view_frames));
}

}  // namespace

RenderOutcome run_render(const RenderOptions& o) {
  host::SceneDescription scene;
  try {
    scene = host::load_scene(host::resolve_scene_path(o.scene));
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  RenderOutcome out;
  std::unique_ptr<viewer::RenderModel> model;
  std::unique_ptr<viewer::FrameWriter> frames;
  std::unique_ptr<viewer::ViewWindow> window;
  std::unique_ptr<viewer::SnapshotExchange> unread;
  Sinks sinks;
  if (o.publish_only) {
    unread = std::make_unique<viewer::SnapshotExchange>();
    sinks.unread = unread.get();
  }
  // The sinks need the model, which needs a settled simulation: start them when it exists.
  const auto on_model = [&](const viewer::RenderModel& m) {
    if (!o.frames_dir.empty()) {
      viewer::FrameWriterOptions fo;
      fo.directory = o.frames_dir;
      fo.width_px = o.width_px;
      fo.height_px = o.height_px;
      fo.camera = viewer::default_camera(m);
      fo.camera.yaw_deg = static_cast<float>(o.yaw_deg);
      fo.camera.pitch_deg = static_cast<float>(o.pitch_deg);
      fo.camera.distance_m /= static_cast<float>(o.zoom);
      std::string error;
      frames = viewer::FrameWriter::start(m, fo, error);
      if (!frames) throw CommandError("--frames: " + error);
      out.gl_description = frames->gl_description();
      sinks.frames = frames.get();
    }
    if (o.view) {
      std::string why_not;
      viewer::ViewWindowOptions wo;
      wo.width_px = o.width_px;
      wo.height_px = o.height_px;
      wo.method_switching = true;  // run_pass restarts with the next method on M
      window = viewer::ViewWindow::open(m, wo, why_not);
      if (!window) {
        std::printf("%s\n", why_not.c_str());
      } else {
        out.view_open = true;
        sinks.window = window.get();
      }
    }
  };
  std::optional<host::SceneCollisionMethod> method = o.method.value_or(scene.simulation.collision_method);
  while (method) method = run_pass(o, scene, *method, model, sinks, on_model, out);
  if (frames) {
    frames->finish();
    out.frames_written = frames->frames_written();
    out.frames_dropped = frames->frames_dropped();
    out.frame_s = frames->frame_times_s();
    if (!frames->error().empty()) throw CommandError("--frames: " + frames->error());
  }
  if (window) out.view_frames = window->frames_drawn();
  return out;
}

void register_render(CommandTree& tree) {
  auto o = std::make_shared<RenderOptions>();
  auto method = std::make_shared<std::string>();
  auto json_path = std::make_shared<std::string>();
  CLI::App* cmd = tree.root.add_subcommand("render", "Draw a scene's host simulation: PNG frames headlessly (--frames) and/or a live window (--view)");
  cmd->add_option("scene", o->scene, "Scene name (scenes/NAME.toml) or path to a scene file")->required();
  std::vector<std::string> method_names;
  for (const host::SceneCollisionMethod m : host::kCollisionMethods) method_names.emplace_back(host::to_string(m));
  cmd->add_option("--method", *method, "Collision method: paired | ray | bullet (default: the scene's)")->check(CLI::IsMember(method_names));
  cmd->add_option("--seconds", o->seconds, "Simulated seconds (default: the trajectory's or plunge's length)")->check(CLI::PositiveNumber);
  cmd->add_option("--settle-seconds", o->settle_seconds, "Let the soft body settle under gravity first [s]")->check(CLI::NonNegativeNumber);
  cmd->add_option("--plunge", o->plunge_speed_m_per_s, "Replace the trajectory by a straight plunge at this speed [m/s] (bench collision's sweep: 15 mm above to 20 mm below the top)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--hold", o->plunge_hold_s, "With --plunge: hold at the bottom this long [s]")->check(CLI::NonNegativeNumber);
  cmd->add_option("--frames", o->frames_dir, "Write PNG frames (headless OpenGL) into this directory");
  cmd->add_option("--frame-every", o->frame_every, "Steps between frames")->check(CLI::PositiveNumber);
  cmd->add_option("--frame-at", o->frame_at_s, "Frames at these simulated times [s] only (after settling)");
  cmd->add_flag("--drop-frames", [o](std::int64_t) { o->wait_for_frames = false; },
                "Never wait for the frame writer (frames it has no time for are dropped)");
  cmd->add_option("--width", o->width_px, "Image width [px]")->check(CLI::Range(64, 4096));
  cmd->add_option("--height", o->height_px, "Image height [px]")->check(CLI::Range(64, 4096));
  cmd->add_option("--yaw", o->yaw_deg, "Camera yaw about world y [deg] (0: looking along -z)");
  cmd->add_option("--pitch", o->pitch_deg, "Camera pitch above the horizon [deg]")->check(CLI::Range(-89.0, 89.0));
  cmd->add_option("--zoom", o->zoom, "Camera zoom (> 1 closer)")->check(CLI::PositiveNumber);
  cmd->add_flag("--view", o->view, "Open a live window (GLFW); without a display it says so and runs on");
  cmd->add_flag("--realtime", o->realtime, "Pace the steps at wall-clock rate (implied by --view)");
  cmd->add_flag("--quiet", o->quiet, "Only the summary");
  cmd->add_option("--json", *json_path, "Write the timings summary JSON here");
  cmd->callback([o, method, json_path] {
    RenderOptions options = *o;
    if (!method->empty()) options.method = host::parse_collision_method(*method);  // IsMember checked the name
    std::sort(options.frame_at_s.begin(), options.frame_at_s.end());
    const RenderOutcome r = run_render(options);
    print_summary(options, r);
    if (!json_path->empty()) {
      nlohmann::json j;
      j["scene"] = r.scene;
      j["method"] = r.method;
      j["steps"] = r.steps;
      j["host_step_us"] = {{"median", sim_quantile(r.step_s, 0.5) * 1e6}, {"p99", sim_quantile(r.step_s, 0.99) * 1e6}};
      j["capture_publish_us"] = {{"median", sim_quantile(r.publish_s, 0.5) * 1e6}, {"p99", sim_quantile(r.publish_s, 0.99) * 1e6},
                                 {"count", r.publish_s.size()}};
      j["frames"] = {{"written", r.frames_written}, {"dropped", r.frames_dropped}, {"median_ms", sim_quantile(r.frame_s, 0.5) * 1e3},
                     {"gl", r.gl_description}};
      j["view"] = {{"open", r.view_open}, {"frames_drawn", r.view_frames}};
      j["crossed_nodes_max"] = r.crossed_nodes_max;
      j["force_max_n"] = r.force_max_n;
      j["machine"] = sim_machine_info();
      std::ofstream f(*json_path);
      if (!f) throw CommandError("cannot write the JSON summary '" + *json_path + "'");
      f << j.dump(2) << '\n';
    }
  });
}

}  // namespace fissure::app
