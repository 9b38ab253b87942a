// One scene's host step: tool motion over sub-steps, Bullet, the collision method, metrics
// (host_simulation.hpp).
#include "fissure/host_sim/host_simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

namespace fissure::host {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

int grid_nodes(double extent_m, double spacing_m) {
  // Nodes at both edges and at most `spacing` apart.
  return std::max(2, static_cast<int>(std::ceil(extent_m / spacing_m - 1e-9)) + 1);
}

ToolNodes build_tool_nodes(const SceneDescription& scene) {
  const ToolDescription& tool = scene.tool;
  if (tool.kind == ToolKind::kConvexMesh) {
    ConvexMeshToolShape shape;
    for (const Vec3& v : tool.mesh_vertices_tool_m) shape.vertices_tool_m.emplace_back(v[0], v[1], v[2]);
    shape.triangles = tool.mesh_triangles;
    shape.pairing_ray_limit_m = tool.pairing_ray_limit_m;
    return ToolNodes::from_convex_mesh(shape);
  }
  const Vec3& size = tool.kind == ToolKind::kClamp ? tool.clamp.jaw_size_m : tool.box_size_m;
  BoxToolShape shape;
  shape.half_extents_m = 0.5 * Eigen::Vector3d(size[0], size[1], size[2]);
  shape.thin_axis = 1;
  shape.nodes_u = grid_nodes(size[0], tool.node_spacing_m);
  shape.nodes_v = grid_nodes(size[2], tool.node_spacing_m);
  return ToolNodes::from_box(shape);
}

ToolVolume build_volume(const SceneDescription& scene) {
  const ToolDescription& tool = scene.tool;
  if (tool.kind == ToolKind::kConvexMesh) {
    std::vector<Eigen::Vector3d> vertices;
    for (const Vec3& v : tool.mesh_vertices_tool_m) vertices.emplace_back(v[0], v[1], v[2]);
    return ToolVolume::from_convex_mesh(vertices, tool.mesh_triangles);
  }
  const Vec3& size = tool.kind == ToolKind::kClamp ? tool.clamp.jaw_size_m : tool.box_size_m;
  return ToolVolume::from_box(0.5 * Eigen::Vector3d(size[0], size[1], size[2]));
}

// A part's report over several soft bodies: forces and counts add, the contacts join (each
// stamped with its body), the stage times add.
void accumulate(const CollisionStepResult& from, int body, CollisionStepResult& into) noexcept {
  into.force_on_tool_world_n += from.force_on_tool_world_n;
  into.friction_force_on_tool_world_n += from.friction_force_on_tool_world_n;
  into.sticking_nodes += from.sticking_nodes;
  into.sliding_nodes += from.sliding_nodes;
  for (const ContactRecord& c : from.contacts) {
    if (into.contacts.size() == into.contacts.capacity()) break;
    into.contacts.push_back(c);
    into.contacts.back().soft_body = body;
  }
  into.colliding_tool_nodes += from.colliding_tool_nodes;
  into.excluded_pairs += from.excluded_pairs;
  into.both_face_contacts += from.both_face_contacts;
  into.contacted_triangles += from.contacted_triangles;
  into.displaced_soft_nodes += from.displaced_soft_nodes;
  into.guard_corrections += from.guard_corrections;
  into.broad_phase_hit = into.broad_phase_hit || from.broad_phase_hit;
  into.seconds_broad += from.seconds_broad;
  into.seconds_narrow += from.seconds_narrow;
  into.seconds_response += from.seconds_response;
  into.seconds_force += from.seconds_force;
  into.seconds_in_solver += from.seconds_in_solver;
}

void clear_for_accumulation(CollisionStepResult& r) noexcept {
  r.force_on_tool_world_n.setZero();
  r.friction_force_on_tool_world_n.setZero();
  r.sticking_nodes = r.sliding_nodes = 0;
  r.contacts.clear();
  r.colliding_tool_nodes = r.excluded_pairs = r.both_face_contacts = r.contacted_triangles = 0;
  r.displaced_soft_nodes = r.guard_corrections = 0;
  r.broad_phase_hit = false;
  r.seconds_broad = r.seconds_narrow = r.seconds_response = r.seconds_force = r.seconds_in_solver = 0.0;
}

ToolPose interpolate(const ToolPose& a, const ToolPose& b, double s) {
  ToolPose out;
  out.position_world_m = a.position_world_m + s * (b.position_world_m - a.position_world_m);
  out.orientation_world = a.orientation_world.slerp(s, b.orientation_world);
  return out;
}

}  // namespace

HostSimulation::HostSimulation(const SceneDescription& scene, std::optional<SceneCollisionMethod> method, const HostSimulationOptions& options)
    : scene_(scene), method_(method.value_or(scene.simulation.collision_method)) {
  const bool bullet = method_ == SceneCollisionMethod::kBullet;
  world_ = std::make_unique<SoftWorld>(scene_, bullet, bullet || options.solver_node_bounds);
  const int parts = world_->part_count();
  const int bodies = world_->soft_body_count();
  int faces_total = 0;
  for (int b = 0; b < bodies; ++b) faces_total += world_->soft(b).m_faces.size();
  const int nodes_total = world_->first_node(bodies);
  tool_pose_ = to_tool_pose(scene_.trajectory.start);
  jaw_gap_m_ = scene_.trajectory.start_jaw_gap_m >= 0.0 ? scene_.trajectory.start_jaw_gap_m : scene_.tool.clamp.jaw_gap_open_m;
  tool_part_poses(scene_, tool_pose_, jaw_gap_m_, part_poses_);
  collisions_.resize(static_cast<std::size_t>(bodies * parts));
  for (int p = 0; p < parts; ++p) {
    if (bullet) {
      collisions_[static_cast<std::size_t>(p)] = std::make_unique<BulletCollision>(*world_->probe(), world_->part_body(p), p);  // one body (SoftWorld)
    } else {
      tool_nodes_.push_back(build_tool_nodes(scene_));
    }
  }
  if (!bullet) {
    ThinBodyCollisionParams params;
    params.hunt_crossley = scene_.hunt_crossley;
    params.response = scene_.simulation.contact_response;
    params.friction_static_ratio = scene_.tool.friction_static_ratio;
    params.friction_kinetic_ratio = scene_.tool.friction_kinetic_ratio;
    params.friction_shear_damping_pa_s_per_m = scene_.tool.friction_shear_damping_pa_s_per_m;
    // The onset ramp answers the in-solver response's joins (a node carried round a rim arrives with
    // its whole x). A force that lags its position on the way in is active to the hand (less force
    // pressing in than coming out): after_step's nodes join at the tool's face with x ≈ 0, so it
    // goes without (docs/decisions.md, "Contact inside the solver", fourth session).
    if (params.response == ContactResponse::kAfterStep) params.contact_onset_ramp_s = 0.0;
    for (int b = 0; b < bodies; ++b) {
      btSoftBody& soft = world_->soft(b);
      for (int p = 0; p < parts; ++p) {
        params.jaw = p;
        const ToolNodes& nodes = tool_nodes_[static_cast<std::size_t>(p)];
        SoftNodeBounds* bounds = world_->node_bounds(b);
        collisions_[static_cast<std::size_t>(b * parts + p)] = method_ == SceneCollisionMethod::kPaired ? make_paired_collision(nodes, soft, params, bounds)
                                                                                                       : make_ray_collision(nodes, soft, params, bounds);
      }
      if (params.response == ContactResponse::kInSolver) {
        for (int p = 0; p < parts; ++p) world_->add_solver_contact(collisions_[static_cast<std::size_t>(b * parts + p)]->solver_contact(), b);
      }
    }
  }
  const ToolVolume volume = build_volume(scene_);
  for (int p = 0; p < parts; ++p) trackers_.emplace_back(volume, nodes_total);
  soft_faces_.reserve(static_cast<std::size_t>(faces_total));
  for (int b = 0; b < bodies; ++b) {
    first_faces_.push_back(static_cast<int>(soft_faces_.size()));
    const btSoftBody& soft = world_->soft(b);
    const int first = world_->first_node(b);
    for (int f = 0; f < soft.m_faces.size(); ++f) {
      std::array<int, 3> face{};
      for (std::size_t k = 0; k < 3; ++k) face[k] = first + static_cast<int>(soft.m_faces[f].m_n[k] - &soft.m_nodes[0]);
      soft_faces_.push_back(face);
    }
  }
  first_faces_.push_back(faces_total);
  const int records = std::max(faces_total, nodes_total);
  result_.part_count = parts;
  result_.contacts.reserve(static_cast<std::size_t>(parts * records));
  for (auto& r : result_.part_results) r.reserve_for(records);
  if (bodies > 1) {
    body_part_results_.resize(static_cast<std::size_t>(bodies * parts));
    for (auto& r : body_part_results_) r.reserve_for(records);
  }
  for (int p = 0; p < parts; ++p) world_->set_part_pose(p, part_poses_[static_cast<std::size_t>(p)]);
  world_->copy_node_positions(nodes_);
  for (int p = 0; p < parts; ++p) trackers_[static_cast<std::size_t>(p)].reset(nodes_, to_isometry(part_poses_[static_cast<std::size_t>(p)]));
}

HostSimulation::~HostSimulation() = default;

const ToolNodes* HostSimulation::tool_nodes(int part) const noexcept {
  return static_cast<std::size_t>(part) < tool_nodes_.size() ? &tool_nodes_[static_cast<std::size_t>(part)] : nullptr;
}

Eigen::AlignedBox3d HostSimulation::soft_bounds_world_m() const noexcept {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : nodes_) box.extend(p);
  return box;
}

int HostSimulation::soft_face_count() const noexcept { return static_cast<int>(soft_faces_.size()); }
int HostSimulation::triangles_cut_by_tool(double depth_tolerance_m) const {
  int cut = 0;
  for (int p = 0; p < world_->part_count(); ++p) {
    const auto k = static_cast<std::size_t>(p);
    cut += triangles_cut_by_volume(trackers_[k].volume(), nodes_, soft_faces_, to_isometry(part_poses_[k]), depth_tolerance_m);
  }
  return cut;
}

int HostSimulation::soft_node_count() const noexcept { return world_->first_node(world_->soft_body_count()); }

TrajectorySample HostSimulation::scripted_target() const noexcept { return sample_trajectory(scene_, time_s_ + scene_.simulation.time_step_s); }

void HostSimulation::settle(double seconds) {
  const int steps = static_cast<int>(std::ceil(seconds / scene_.simulation.time_step_s));
  for (int i = 0; i < steps; ++i) step(tool_pose_, jaw_gap_m_);
  for (std::size_t c = 0; c < collisions_.size(); ++c) collisions_[c]->reset_rest_state(world_->soft(static_cast<int>(c) / world_->part_count()));
  time_s_ = 0.0;  // the scripted trajectory starts after settling
  world_->copy_node_positions(nodes_);
  for (int p = 0; p < world_->part_count(); ++p) trackers_[static_cast<std::size_t>(p)].reset(nodes_, to_isometry(part_poses_[static_cast<std::size_t>(p)]));
}

int HostSimulation::reseat_tool(const ToolPose& tool_pose, double jaw_gap_m) {
  const bool clamp = scene_.tool.kind == ToolKind::kClamp;
  const std::array<ToolPose, kMaxToolParts> previous = part_poses_;
  tool_pose_ = tool_pose;
  jaw_gap_m_ = clamp ? std::clamp(jaw_gap_m, scene_.tool.clamp.jaw_gap_min_m, scene_.tool.clamp.jaw_gap_open_m) : 0.0;
  tool_part_poses(scene_, tool_pose_, jaw_gap_m_, part_poses_);
  int put_out = 0;
  const int parts = world_->part_count();
  for (int p = 0; p < parts; ++p) world_->teleport_part(p, part_poses_[static_cast<std::size_t>(p)]);
  for (int b = 0; b < world_->soft_body_count(); ++b) {
    for (int p = 0; p < parts; ++p) {
      const auto k = static_cast<std::size_t>(p);
      put_out += collisions_[static_cast<std::size_t>(b * parts + p)]->reseat(previous[k], part_poses_[k], world_->soft(b));
    }
  }
  // The crossing metric judges each node's relative path between two updates: from the old pose
  // to the new one every node in between would count as "through". A re-seat is not a path; the
  // sides are taken afresh here (after the nodes inside were put out), as after settle().
  world_->copy_node_positions(nodes_);
  for (int p = 0; p < world_->part_count(); ++p) trackers_[static_cast<std::size_t>(p)].reset(nodes_, to_isometry(part_poses_[static_cast<std::size_t>(p)]));
  return put_out;
}

const HostStepResult& HostSimulation::step(const ToolPose& tool_target, double jaw_gap_m) {
  const Clock::time_point start = Clock::now();
  const int parts = world_->part_count();
  const int bodies = world_->soft_body_count();
  const int substeps = scene_.simulation.substeps_count;
  const double h = scene_.simulation.time_step_s / substeps;
  const bool clamp = scene_.tool.kind == ToolKind::kClamp;
  const double gap_target = clamp ? std::clamp(jaw_gap_m, scene_.tool.clamp.jaw_gap_min_m, scene_.tool.clamp.jaw_gap_open_m) : 0.0;
  const ToolPose from = tool_pose_;
  const double gap_from = jaw_gap_m_;
  result_.times = HostStepTimes{};
  std::array<ToolPose, kMaxToolParts> previous = part_poses_;
  result_.crossing = CrossingSnapshot{};
  double metrics_s = 0.0;
  for (int s = 1; s <= substeps; ++s) {
    const double a = static_cast<double>(s) / substeps;
    tool_pose_ = interpolate(from, tool_target, a);
    jaw_gap_m_ = clamp ? gap_from + a * (gap_target - gap_from) : 0.0;
    tool_part_poses(scene_, tool_pose_, jaw_gap_m_, part_poses_);
    for (int p = 0; p < parts; ++p) world_->set_part_pose(p, part_poses_[static_cast<std::size_t>(p)]);
    for (std::size_t c = 0; c < collisions_.size(); ++c) {
      const auto k = c % static_cast<std::size_t>(parts);
      collisions_[c]->prepare_step(previous[k], part_poses_[k], h);  // in_solver: detected and solved inside the step
    }
    const Clock::time_point bullet_start = Clock::now();
    world_->step(h);
    result_.times.bullet_s += seconds_since(bullet_start);
    for (int p = 0; p < parts; ++p) {
      if (bodies > 1) clear_for_accumulation(result_.part_results[static_cast<std::size_t>(p)]);
    }
    for (std::size_t c = 0; c < collisions_.size(); ++c) {
      const int body = static_cast<int>(c) / parts;
      const auto k = c % static_cast<std::size_t>(parts);
      // One body (most scenes): the collision reports straight into its part's result.
      CollisionStepResult& r = bodies > 1 ? body_part_results_[c] : result_.part_results[k];
      const Clock::time_point collision_start = Clock::now();
      collisions_[c]->step(previous[k], part_poses_[k], h, world_->soft(body), r);
      // bullet's collision ran inside stepSimulation (measured by the probe); ours runs here.
      result_.times.collision_s += method_ == SceneCollisionMethod::kBullet ? r.seconds_narrow + r.seconds_response : seconds_since(collision_start);
      // In-solver, the detection and the projections ran inside Bullet's step: they are ours.
      result_.times.collision_s += r.seconds_in_solver;
      result_.times.bullet_s -= r.seconds_in_solver;
      if (bodies > 1) accumulate(r, body, result_.part_results[k]);
    }
    world_->end_step();
    previous = part_poses_;
    // The metrics follow every sub-step: the crossing tracker judges each node's relative path
    // between two updates as a straight line, which is the collision's own model of one
    // sub-step, not of a whole host step (20 sub-steps at a 20 ms host step).
    const Clock::time_point metrics_start = Clock::now();
    measure();
    metrics_s += seconds_since(metrics_start);
  }
  time_s_ += scene_.simulation.time_step_s;
  result_.time_s = time_s_;
  result_.jaw_gap_m = jaw_gap_m_;
  result_.force_on_tool_world_n.setZero();
  result_.contacts.clear();
  for (int p = 0; p < parts; ++p) {
    const CollisionStepResult& r = result_.part_results[static_cast<std::size_t>(p)];
    result_.part_force_world_n[static_cast<std::size_t>(p)] = r.force_on_tool_world_n;
    result_.force_on_tool_world_n += r.force_on_tool_world_n;
    for (const ContactRecord& c : r.contacts) {
      if (result_.contacts.size() < result_.contacts.capacity()) result_.contacts.push_back(c);
    }
  }
  result_.contact_count = static_cast<int>(result_.contacts.size());
  result_.times.metrics_s = metrics_s;
  result_.times.total_s = seconds_since(start) - metrics_s;
  return result_;
}

void HostSimulation::measure() noexcept {
  world_->copy_node_positions(nodes_);
  // This sub-step's counts summed over the parts; the host step reports its worst sub-step (and
  // every rim pass of its sub-steps).
  CrossingSnapshot sum;
  for (int p = 0; p < world_->part_count(); ++p) {
    const CrossingSnapshot s = trackers_[static_cast<std::size_t>(p)].update(nodes_, to_isometry(part_poses_[static_cast<std::size_t>(p)]));
    sum.crossed_nodes += s.crossed_nodes;
    sum.wrong_side_nodes += s.wrong_side_nodes;
    sum.inside_nodes += s.inside_nodes;
    sum.through_nodes += s.through_nodes;
    sum.rim_passes += s.rim_passes;
    sum.endpoint_crossed_nodes += s.endpoint_crossed_nodes;
    sum.max_penetration_m = std::max(sum.max_penetration_m, s.max_penetration_m);
  }
  CrossingSnapshot& step_worst = result_.crossing;
  step_worst.crossed_nodes = std::max(step_worst.crossed_nodes, sum.crossed_nodes);
  step_worst.wrong_side_nodes = std::max(step_worst.wrong_side_nodes, sum.wrong_side_nodes);
  step_worst.inside_nodes = std::max(step_worst.inside_nodes, sum.inside_nodes);
  step_worst.through_nodes = std::max(step_worst.through_nodes, sum.through_nodes);
  step_worst.rim_passes += sum.rim_passes;
  step_worst.endpoint_crossed_nodes = std::max(step_worst.endpoint_crossed_nodes, sum.endpoint_crossed_nodes);
  step_worst.max_penetration_m = std::max(step_worst.max_penetration_m, sum.max_penetration_m);
}

}  // namespace fissure::host
