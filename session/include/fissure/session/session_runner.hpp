#pragma once
// One `fissure run` session: device (SimFalcon with the scene's hand, or the USB Falcon) +
// rt_core's RtLoop + the host simulation with the proxy builder, joined by the shared/
// wait-free exchanges (BRIEF §2, the in-process transport).
//   * real time: rt thread (SCHED_FIFO best effort, RtLoop::run_until) and host thread
//     (soft real time, one step per host period) — the main thread drains telemetry, writes
//     the trace, refreshes the status line ~10×/s and turns Ctrl-C into a ramp-out;
//   * lockstep: one thread on a LockstepClock — N rt ticks, one host step, repeat — so the
//     session is deterministic and runs as fast as the CPU allows.
#include <atomic>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "fissure/host_sim/scene_description.hpp"
#include "fissure/session/session_record.hpp"

namespace fissure::session {

enum class SessionDevice { kSim, kUsb };

struct SessionOptions {
  host::SceneDescription scene;
  SessionDevice device = SessionDevice::kSim;
  bool lockstep = false;
  double rt_rate_hz = 1000.0;
  /// Host step rate [Hz]; 0 = the scene's time_step_s. Other rates keep the scene's collision
  /// sub-step (time_step_s / substeps_count) and change the number of sub-steps per host step.
  double host_rate_hz = 0.0;
  /// Session length [s]; 0 = the hand script's length (SimFalcon) or until Ctrl-C (USB).
  double duration_s = 0.0;
  /// Soft body settling under gravity before the session starts [s] (not part of the trace).
  /// 1 s: with 0.2 s the sphere is still sagging when the Hunt-Crossley rest state is taken, and
  /// the first contact reports ~4 mm of "deformation" (a 3.5 N step) that is only gravity sag.
  double settle_s = 1.0;
  std::filesystem::path out_dir;
  bool plot = true;
  /// rt_core's passivity controller (the observer always runs). Off only to diagnose where
  /// energy comes from: with it off the summary's energy_j is the rendered contact's own.
  bool passivity_controller = true;
  bool status_line = true;
  /// The view: a live window (--view; no display → one line, the session runs on)
  /// and/or PNG frames of every frame_every-th host step into frames_dir (headless EGL, a
  /// writer thread; real time never waits for it and counts the frames it dropped, lockstep
  /// waits so the frames are the same on every run). Neither changes the physics.
  bool view = false;
  std::filesystem::path frames_dir;
  int frame_every = 10;
  int frame_width_px = 960;
  int frame_height_px = 720;
  /// --record: every device exchange goes to this device recording (falcon_hw/
  /// device_recording.hpp, docs/session.md "Device recordings"), staged like the other outputs.
  std::filesystem::path record_path;
  /// --replay: the device answers from this recording instead of SimFalcon (ReplayDevice). The
  /// session lasts as long as the recorded one unless --duration says less.
  std::filesystem::path replay_path;
  /// Set from a signal handler: ramp out and stop (checked ~every 10 ms in real time, every
  /// host step in lockstep).
  const std::atomic<bool>* interrupt = nullptr;
};

struct SessionOutcome {
  nlohmann::json summary;        ///< what summary.json holds
  std::filesystem::path summary_path;
  std::filesystem::path trace_path;
  std::filesystem::path plot_path;  ///< empty when not plotted
};

/// Length of a hand script [s]: each leg's distance / speed plus its hold.
double hand_script_duration_s(const HandScript& hand);

/// The scene as run at `host_rate_hz` (see SessionOptions::host_rate_hz). Throws SessionError
/// when the rate does not divide into the scene's collision sub-step.
host::SceneDescription scene_at_host_rate(const host::SceneDescription& scene, double host_rate_hz);

/// Runs the session and writes trace.csv, summary.json and session.png into out_dir.
/// Throws SessionError on set-up failures (no device, bad rates, unwritable directory).
SessionOutcome run_session(const SessionOptions& options);

}  // namespace fissure::session
