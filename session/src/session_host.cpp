#include "fissure/session/session_host.hpp"

#include "fissure/shared/message_validation.hpp"

#include <array>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <BulletSoftBody/btSoftBody.h>

#include "fissure/host_sim/proxy_model.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/shared/device_mapping.hpp"

namespace fissure::session {
namespace {

static_assert(host::kMaxProxyJaws == host::kMaxToolParts, "one proxy-builder jaw per host tool part");

Eigen::Quaterniond to_quaternion(const Quat& q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized(); }

host::ProxyBuilderModel session_proxy_model(const host::SceneDescription& scene, const host::HostSimulation& sim) {
  std::optional<host::ProxyBuilderModel> model = host::proxy_model_for(scene, sim);
  if (!model) {
    throw std::invalid_argument("scene '" + scene.name +
                                "': fissure run needs the paired or ray collision method (the proxy is built from its contacts)");
  }
  return *model;
}

// Time constant of the low-pass on the tissue's velocity under a part [s]. The contacted nodes'
// velocities jitter by centimetres per second from step to step (clamp-vessel-lift: ±3 cm/s about
// a 2 cm/s lift); over 20 ms (20 steps at 1 kHz) that averages to a few mm/s, and a grip or a lift
// changes speed over hundreds of ms.
constexpr double kSurfaceVelocityFilter_s = 0.02;

// rt_core's friction cone needs, per tool part, the host's friction force on it and the velocity
// of the tissue under it (messages.hpp, PartFriction): the contacted triangles' node velocities,
// weighted by each triangle's contact force and low-passed (kSurfaceVelocityFilter_s). (The share
// of held nodes that stick is no estimate: a spatula sliding over tissue advances by contact
// turnover while most held nodes stick for the step — spatula-ball-drag.)
void add_friction_inputs(const host::HostStepResult& result, const host::ProxyBuilderModel& model, const host::SoftWorld& world,
                         double dt_s, double sub_step_s, std::array<Eigen::Vector3d, 3>& filtered_velocity,
                         host::ProxyPartMotion& parts) {
  std::array<double, 3> weight_n{0.0, 0.0, 0.0};
  std::array<Eigen::Vector3d, 3> weighted{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (int jaw = 0; jaw < result.part_count && jaw < model.jaw_count; ++jaw) {
    const auto j = static_cast<std::size_t>(jaw);
    parts.friction_force_world_n[static_cast<std::size_t>(model.part_of_jaw[j])] += result.part_results[j].friction_force_on_tool_world_n;
  }
  for (int i = 0; i < result.contact_count && i < static_cast<int>(result.contacts.size()); ++i) {
    const host::ContactRecord& record = result.contacts[static_cast<std::size_t>(i)];
    if (record.jaw < 0 || record.jaw >= model.jaw_count || record.soft_body < 0 || record.soft_body >= world.soft_body_count() ||
        record.soft_face < 0 || record.soft_face >= world.soft(record.soft_body).m_faces.size() || !(record.force_n > 0.0)) {
      continue;
    }
    const btSoftBody::Face& face = world.soft(record.soft_body).m_faces[record.soft_face];
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    // Over the last sub-step, from positions (m_q: where it started): m_v misses the moves the
    // in-solver contact makes after Bullet's velocity update.
    for (const btSoftBody::Node* node : face.m_n) {
      const btVector3 moved = node->m_x - node->m_q;
      v += Eigen::Vector3d(moved.x(), moved.y(), moved.z()) / (3.0 * sub_step_s);
    }
    const auto part = static_cast<std::size_t>(model.part_of_jaw[static_cast<std::size_t>(record.jaw)]);
    weighted[part] += record.force_n * v;
    weight_n[part] += record.force_n;
  }
  const double share = std::min(1.0, dt_s / kSurfaceVelocityFilter_s);
  for (std::size_t part = 0; part < weighted.size(); ++part) {
    if (weight_n[part] > 0.0 && weighted[part].allFinite()) {
      filtered_velocity[part] += share * (weighted[part] / weight_n[part] - filtered_velocity[part]);
    } else {
      filtered_velocity[part].setZero();
    }
    parts.surface_velocity_world_m_per_s[part] = filtered_velocity[part];
  }
}

}  // namespace

SessionHost::SessionHost(const host::SceneDescription& scene)
    : scene_(scene), sim_(scene), builder_(session_proxy_model(scene, sim_)) {
  pose_.position_world_m = as_eigen(scene.trajectory.start.position_world_m);
  pose_.orientation_world = to_quaternion(scene.trajectory.start.orientation_world);
  take_settled_volumes();
}

void SessionHost::settle(double seconds) {
  sim_.settle(seconds);
  take_settled_volumes();
}

void SessionHost::take_settled_volumes() {
  settled_volume_m3_.clear();
  for (int b = 0; b < sim_.world().soft_body_count(); ++b) settled_volume_m3_.push_back(sim_.world().soft(b).getVolume());
}

double SessionHost::lowest_volume_ratio() const noexcept {
  double lowest = std::numeric_limits<double>::infinity();
  for (int b = 0; b < sim_.world().soft_body_count(); ++b) {
    const double settled = settled_volume_m3_[static_cast<std::size_t>(b)];
    const double ratio = settled != 0.0 ? sim_.world().soft(b).getVolume() / settled : std::numeric_limits<double>::quiet_NaN();
    lowest = std::isnan(ratio) ? ratio : std::min(lowest, ratio);
    if (std::isnan(lowest)) break;
  }
  return lowest;
}

const HostStatus& SessionHost::step(DeviceStateExchange& state_in, ProxyExchange& proxy_out) {
  const auto start = std::chrono::steady_clock::now();
  DeviceState incoming;
  bool rt_restarted = false;
  if (state_in.try_fetch(incoming)) {
    // A non-finite sample (a corrupt link, a broken device) would turn Bullet's soft body to
    // NaN for good: keep the tool at the last finite sample and count the rejection.
    if (is_finite(incoming)) {
      // Sequences only grow within one rt_core run: a smaller one is a restarted rt_core, whose
      // epochs start again and may equal the one applied last.
      rt_restarted = have_device_ && incoming.sequence < device_.sequence;
      device_ = incoming;
      have_device_ = true;
    } else {
      ++status_.rejected_device_states;
    }
  }
  const DeviceMapping& mapping = scene_.device_mapping;
  // Epoch 0: rt_core has accepted no reading yet, its position is not one (messages.hpp).
  const std::uint8_t epoch = have_device_ ? position_epoch(device_.status_flags) : std::uint8_t{0};
  ToolState tool;
  if (epoch != 0) {
    tool = device_to_tool(mapping, as_eigen(device_.position_device_m), as_eigen(device_.velocity_device_m_per_s));
    // The jaw closing rt_core computed for this sample, so both sides place the jaws alike.
    tool.jaw_closing_m = device_.closing_axis_m;
  } else {
    // Before rt_core's first accepted sample: hold the tool where it is (the scene's start pose).
    tool.p_tool_world_m = pose_.position_world_m;
    tool.jaw_closing_m = 0.0;
  }
  pose_.position_world_m = tool.p_tool_world_m;
  // rt_core's jaws close by scale·closing in total (each moves scale·closing/2), so the gap is
  // the open gap less that.
  const double jaw_gap_m = scene_.tool.clamp.jaw_gap_open_m - mapping.scale * tool.jaw_closing_m;
  if (epoch != applied_epoch_ || rt_restarted) {
    // rt_core says this position does not continue the last one (an accepted encoder jump, the
    // first sample after a device fault, its first sample): the hand did not move the tool
    // there. Sweeping to it would carry every soft node on the way (10 cm through the ball and
    // back in the stress case encoder_jumps, which turned it inside out): re-seat the tool. The
    // step below then starts from rest at the new pose, so its tool velocity is 0, not jump / dt.
    if (epoch != 0) {
      sim_.reseat_tool(pose_, jaw_gap_m);
      ++status_.tool_reseats;
    }
    applied_epoch_ = epoch;
  }
  const host::HostStepResult& result = sim_.step(pose_, jaw_gap_m);

  host::ProxyPartMotion parts;
  for (const ToolPart part : {ToolPart::kTool, ToolPart::kJawA, ToolPart::kJawB}) {
    const PartMotion motion = part_motion(mapping, tool, part);
    parts.p_world_m[static_cast<std::size_t>(part)] = motion.p_world_m;
    parts.v_world_m_per_s[static_cast<std::size_t>(part)] = motion.v_world_m_per_s;
  }
  const host::ProxyBuilderModel& proxy_model = builder_.model();
  if (proxy_model.friction_static_ratio > 0.0) {
    add_friction_inputs(result, proxy_model, sim_.world(), scene_.simulation.time_step_s,
                        scene_.simulation.time_step_s / scene_.simulation.substeps_count, surface_velocity_world_m_per_s_, parts);
  }
  const auto host_time_ns = static_cast<TimeNs>(std::llround(result.time_s * 1e9));
  builder_.build(result.contacts, pose_, parts, host_time_ns, proxy_);
  proxy_out.publish(proxy_);

  ++status_.steps;
  status_.host_time_ns = host_time_ns;
  status_.crossed_nodes = result.crossing.crossed_nodes;
  status_.contacts = result.contact_count;
  status_.patches = proxy_.patch_count;
  status_.max_penetration_m = result.crossing.max_penetration_m;
  status_.force_n = result.force_on_tool_world_n.norm();
  status_.jaw_gap_m = result.jaw_gap_m;
  for (std::size_t part = 0; part < status_.part_normal_n.size(); ++part) {
    const bool present = static_cast<int>(part) < result.part_count;
    const Eigen::Vector3d& friction = result.part_results[part].friction_force_on_tool_world_n;
    status_.part_friction_n[part] = present ? friction.norm() : 0.0;
    status_.part_normal_n[part] = present ? (result.part_force_world_n[part] - friction).norm() : 0.0;
  }
  status_.proxy_sequence = proxy_.sequence;
  // A closed surface's signed volume (O(faces), cheap beside the step) goes below 0 when the body
  // is turned inside out; the one-sided collision then meets no triangle and contact silently stops.
  status_.soft_volume_ratio = lowest_volume_ratio();
  status_.soft_everted = status_.soft_everted || status_.soft_volume_ratio < 0.0;
  status_.step_cpu_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status_;
}

}  // namespace fissure::session
