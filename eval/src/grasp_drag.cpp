// The drag the hand feels (grasp.hpp, GraspDragOptions): a closed-loop lockstep session of
// scenes/spatula-ball-drag.toml, with the commanded force split along rt_core's contact normal.
#include <algorithm>
#include <cmath>
#include <vector>

#include "fissure/eval/eval_error.hpp"
#include "fissure/eval/grasp.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/session/rt_stack.hpp"
#include "fissure/session/session_host.hpp"
#include "fissure/session/session_runner.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/shared/device_mapping.hpp"

namespace fissure::eval {
namespace {

// The scene's scripted slide speed [m/s] (scenes/spatula-ball-drag.toml, issue 23's 5 cm/s).
constexpr double kSlideSpeed_m_per_s = 0.05;
// Normal force below which a tick is not part of the slide [N]: the press is ~2 N; a tool
// lifting off or touching down is not "sliding under 2 N".
constexpr double kMinSlideNormal_n = 0.5;
// The tool's speed along the surface is measured over this many ticks: one encoder count
// (~50 µm) per tick at 5 cm/s would make a per-tick difference quantised to 0 or 5 cm/s.
constexpr int kSpeedWindowTicks = 20;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(std::lround(q * static_cast<double>(values.size() - 1)));
  return values[index];
}

struct TickRecord {
  Eigen::Vector3d tool_world_m;
  Eigen::Vector3d force_device_n;
  Eigen::Vector3d normal_device;  // unit; zero out of contact
  bool sliding = false;
  double host_friction_n = 0.0;
  double host_normal_n = 0.0;
  int host_contacts = 0;
};

}  // namespace

host::SceneDescription grasp_drag_scene() { return host::load_scene(host::resolve_scene_path("spatula-ball-drag")); }

GraspDragResult run_grasp_drag(const GraspDragOptions& options) {
  using session::RtStack;
  using session::SessionHost;
  const host::SceneDescription scene = session::scene_at_host_rate(options.scene, options.host_rate_hz);
  const double ratio = options.rt_rate_hz / options.host_rate_hz;
  const long ticks_per_host = std::lround(ratio);
  if (ticks_per_host < 1 || std::abs(ratio - static_cast<double>(ticks_per_host)) > 1e-9 * ratio) {
    throw EvalError("drag: host rate " + std::to_string(options.host_rate_hz) + " Hz does not divide the rt rate " +
                    std::to_string(options.rt_rate_hz) + " Hz");
  }
  rt::RtConfig config;
  config.rate_hz = options.rt_rate_hz;
  config.mapping = scene.device_mapping;
  const rt::RtModel model = session::build_rt_model(config);
  const DeviceMapping& mapping = model.config.mapping;
  const auto ticks = static_cast<std::size_t>(std::llround(session::hand_script_duration_s(scene.hand) * options.rt_rate_hz));

  LockstepClock clock(0);
  falcon::SimFalconConfig sim_config;
  sim_config.hand = scene.hand;
  falcon::SimFalcon device(sim_config, clock);
  SessionHost host(scene);
  host.settle(options.settle_s);
  RtStack rt(model, device, clock);
  rt::RtLoop& loop = rt.loop();
  session::RtChannels& channels = rt.channels();

  GraspDragResult out;
  out.host_rate_hz = options.host_rate_hz;
  out.friction_static_ratio = scene.tool.friction_static_ratio;
  out.friction_kinetic_ratio = scene.tool.friction_kinetic_ratio;
  std::vector<TickRecord> records;
  records.reserve(ticks);
  session::HostStatus host_status;
  rt::TelemetrySample sample;
  std::size_t done = 0;
  while (done < ticks) {
    for (long k = 0; k < ticks_per_host && done < ticks; ++k, ++done) {
      loop.step();
      while (channels.telemetry.try_pop(sample)) {
        out.energy_max_j = std::max(out.energy_max_j, sample.energy_j);
      }
      const rt::RtData& data = loop.data();
      TickRecord r;
      r.tool_world_m = data.tool.p_tool_world_m;
      r.force_device_n = data.force_device_n;
      PartForces elastic;
      elastic.force_world_n = data.normal_load.elastic_force_world_n;
      const Eigen::Vector3d normal = part_forces_to_device(mapping, elastic);
      r.normal_device = normal.norm() > 0.0 ? Eigen::Vector3d(normal.normalized()) : Eigen::Vector3d::Zero();
      r.sliding = data.parts_sliding > 0;
      r.host_friction_n = host_status.part_friction_n[0];
      r.host_normal_n = host_status.part_normal_n[0];
      r.host_contacts = host_status.contacts;
      out.finite = out.finite && r.force_device_n.allFinite() && r.tool_world_m.allFinite();
      records.push_back(r);
    }
    host_status = host.step(channels.state, channels.proxy);
    out.crossed_nodes_max = std::max(out.crossed_nodes_max, host_status.crossed_nodes);
    out.finite = out.finite && std::isfinite(host_status.force_n);
  }

  std::vector<double> normal_n, tangential_n, ratios, host_friction, host_normal, speeds;
  int sliding_ticks = 0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (i > 0) out.max_force_step_n = std::max(out.max_force_step_n, (records[i].force_device_n - records[i - 1].force_device_n).norm());
    const TickRecord& r = records[i];
    if (i < static_cast<std::size_t>(kSpeedWindowTicks) || r.normal_device.isZero(0.0) || r.host_contacts == 0) continue;
    const Eigen::Vector3d travel = r.tool_world_m - records[i - kSpeedWindowTicks].tool_world_m;
    // Speed along the surface: the tool's travel with its normal component removed (world and
    // device axes are aligned up to the mapping's permutation and signs, which keep lengths).
    const Eigen::Vector3d normal_world = [&] {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      for (int w = 0; w < 3; ++w) n[w] = mapping.axis_sign[static_cast<std::size_t>(w)] * r.normal_device[mapping.axis_permutation[static_cast<std::size_t>(w)]];
      return n;
    }();
    const double speed = (travel - travel.dot(normal_world) * normal_world).norm() / (kSpeedWindowTicks * model.period_s);
    const double f_n = r.force_device_n.dot(r.normal_device);
    if (speed < options.sliding_speed_share * kSlideSpeed_m_per_s || f_n < kMinSlideNormal_n) continue;
    const double f_t = (r.force_device_n - f_n * r.normal_device).norm();
    normal_n.push_back(f_n);
    tangential_n.push_back(f_t);
    ratios.push_back(f_t / f_n);
    host_friction.push_back(r.host_friction_n);
    host_normal.push_back(r.host_normal_n);
    speeds.push_back(speed);
    if (r.sliding) ++sliding_ticks;
  }
  out.slide_ticks = static_cast<int>(ratios.size());
  out.normal_median_n = median(normal_n);
  out.tangential_median_n = median(tangential_n);
  out.ratio_median = median(ratios);
  out.ratio_p10 = quantile(ratios, 0.1);
  out.ratio_p90 = quantile(ratios, 0.9);
  out.host_friction_median_n = median(host_friction);
  out.host_normal_median_n = median(host_normal);
  out.slide_speed_median_m_per_s = median(speeds);
  out.sliding_tick_share = ratios.empty() ? 0.0 : static_cast<double>(sliding_ticks) / static_cast<double>(ratios.size());
  return out;
}

}  // namespace fissure::eval
