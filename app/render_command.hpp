#pragma once
// `fissure render SCENE`: the scene's host simulation (scripted trajectory, or a straight plunge
// at --plunge m/s like `fissure bench collision`'s sweep) drawn by viewer/: PNG frames written
// headlessly (--frames DIR --frame-every N | --frame-at T…) and/or a live window (--view).
// `fissure bench view` reuses run_render() to measure what drawing costs the host step.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "fissure/host_sim/scene_description.hpp"

namespace fissure::app {

struct RenderOptions {
  std::string scene;
  std::optional<host::SceneCollisionMethod> method;
  double seconds = -1.0;         ///< simulated seconds; < 0: the trajectory's (or plunge's) length
  double settle_seconds = 0.5;
  double plunge_speed_m_per_s = 0.0;  ///< > 0: replace the trajectory by a straight plunge
  double plunge_hold_s = 0.3;
  std::string frames_dir;
  int frame_every = 10;          ///< steps between frames
  std::vector<double> frame_at_s;  ///< if set: frames at these simulated times only
  bool wait_for_frames = true;   ///< false: the writer may drop frames (host never waits)
  int width_px = 960, height_px = 720;
  double yaw_deg = 30.0, pitch_deg = 25.0, zoom = 1.0;  ///< camera (zoom > 1 = closer)
  bool view = false;
  bool realtime = false;         ///< pace steps at wall-clock rate (implied by --view)
  bool publish_only = false;     ///< bench: capture + publish into an exchange nobody reads
  bool hold_view_at_end = true;  ///< keep the window (and the process) up after the trajectory until closed
  bool quiet = false;
};

struct RenderOutcome {
  std::string scene, method;
  long steps = 0;
  std::vector<double> step_s;     ///< HostSimulation::step wall time per step (its own total_s)
  std::vector<double> publish_s;  ///< capture_snapshot + publish per published snapshot
  std::vector<double> frame_s;    ///< frame writer: render + read back + PNG per frame
  std::uint64_t frames_written = 0, frames_dropped = 0;
  std::uint64_t view_frames = 0;
  bool view_open = false;
  std::string gl_description;
  int crossed_nodes_max = 0;
  double force_max_n = 0.0;
};

/// Runs a render session. Throws CommandError on a bad scene / unwritable directory / no
/// headless GL for --frames.
RenderOutcome run_render(const RenderOptions& options);

void register_render(CommandTree& tree);

}  // namespace fissure::app
