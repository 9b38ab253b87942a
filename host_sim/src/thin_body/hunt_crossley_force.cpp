// Stage 5: contact force, Hunt-Crossley per deformed triangle (BRIEF §3 item 5, §4; paper "The
// interaction force model").
//
// For every triangle with at least one colliding node (the contacted faces), held on the tool
// plane with outward normal n (the tool pushes the soft surface along n):
//
// normal_displacement (default) — per colliding vertex v of the triangle (share s_v, see below):
//   x_v = max(0, n·(q − p_v,rest))     how far the tool face (q: a point on it) has advanced along n
//                                      past the vertex's rest position; for a vertex held on the
//                                      face (gap ≈ skin) this is its displacement from rest along n
//   F   = Σ_v s_v·(w/3)·max(0, k·x_vⁿ + λ·x_vⁿ·ẋ_v)
//   x_v depends on the tool pose and the rest shape only, so ẋ_v is the tool's approach speed
//   along n (no differentiated node noise); which vertices collide, and their shares s_v, come
//   from the soft body's state.
//   Why: the paper's centroid distance counts every motion of the triangle as indentation —
//   sliding along the face, wrapping round the rim, the whole body sagging or rolling (a clamp
//   jaw that had squeezed the ball held it with ~30 N after opening; a 10 m/s plunge left 36 N
//   sideways). Along n only the part the tool actually pushed counts. And because x is measured
//   per vertex, a node that joins the contact set where the face meets its rest position adds
//   ≈ 0 (under the centroid measure the triangle's whole x came in with it: a coarse ball under a
//   held plate jumped between 1.5 N / 6 triangles and 4 N / 13 triangles at ~0.2 mm of depth),
//   and a held node leaving the face fades out over release_distance (s_v ramps 1 → 0,
//   enforced_displacement.cpp) instead of dropping a triangle's worth in one step. A node that
//   joins elsewhere (carried round a rim, pushed by its neighbours) arrives with its whole x, so
//   s_v also ramps in over contact_onset_ramp_s from the step the corner joins. Summed over
//   the triangles around it, vertex v carries s_v·k·x_vⁿ·(its third of each adjacent area): a
//   nodal quadrature of the contact pressure k·xⁿ over the contacted surface.
//
// centroid_distance (the paper's, kept for fidelity):
//   x  = |centroid now − rest centroid|, F = w·c·(k·xⁿ + λ·xⁿ·ẋ), c = colliding vertices / 3 in
//   per-unit-area mode (the contact indicator interpolated over the triangle), 1 otherwise.
//
// Both: ẋ = first-order low-pass of (x − x_prev)/dt, α = dt / (dt + 1/(2π·fc)); the filter state
//   restarts at 0 when a triangle (corner) enters contact, x_prev then taken at the start of the
//   step (m_q), so there is no damping kick at first touch. Lag ≈ 1/(2π·fc). F is clamped ≥ 0
//   (pulling back faster than k/λ would go negative). w = rest area (per_unit_area, default:
//   refining the mesh converges the total) or 1 (the paper's per-triangle sum, which grows with
//   mesh density). Each triangle pushes the tool along −n; the sum is the force on the tool.
#include "collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <numbers>

namespace fissure::host::thin_body {
namespace {

Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// Last step's x of a corner and this plane's x at the previous pose agree to rounding when the
// triangle stayed on one plane (both are offset + n·(t − rest) in double); a larger gap is a
// change of the triangle's force plane (1 nm: far below any real indentation step).
constexpr double kPlaneSwitchTolerance_m = 1.0e-9;
// A rim point lies on a tool face within this (the clip's rounding on mm-sized tools).
constexpr double kRimOnPlane_m = 1.0e-7;

Eigen::Vector3d centroid(const SoftSurfaceModel& surface, const btSoftBody& soft, int face, bool start_of_step) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const int node : surface.face_nodes[static_cast<std::size_t>(face)])
    sum += to_eigen(start_of_step ? soft.m_nodes[node].m_q : soft.m_nodes[node].m_x);
  return sum / 3.0;
}

// One low-pass step of ẋ for a filter slot; restarts (ẋ = 0, x_prev = x_start) when the slot was
// not in contact the step before.
double filtered_rate(std::int64_t& stamp, double& x_prev_m, double& rate_m_s, std::int64_t step, double x_m,
                     double x_start_m, double dt_s, double alpha) {
  if (stamp != step - 1) {
    x_prev_m = x_start_m;
    rate_m_s = 0.0;
  }
  rate_m_s += alpha * ((x_m - x_prev_m) / dt_s - rate_m_s);
  stamp = step;
  x_prev_m = x_m;
  return rate_m_s;
}

// One triangle's record; its force pushes the tool along −normal_world (the face's outward normal).
void add_contact(const ContactRecord& record, CollisionStepResult& out) {
  out.force_on_tool_world_n -= record.force_n * record.normal_world;
  out.contacts.push_back(record);
}

// In-solver rim contacts: a candidate triangle with no colliding corner that the tool's rim
// touches or presses (rim_projection.cpp tents it over the rim) pushes the tool too, or a blade
// held edge-first in a coarse shell, whose triangles are all draped over its edge, would render
// nothing. Its share ramps with the rim's gap in front of it as a held node's does (1 touching, 0
// at release_distance). The force acts along the tool face through the deepest rim point that
// faces the triangle most (the proxy's patches are per tool face), and x is the corners' measure
// taken at the rim point's foot on the triangle: how far that face's plane has advanced past the
// rest position of the foot (n·(rim point − rest foot)), weighted as one corner (a third of the
// rest area). So when a corner of the tented triangle joins the contact on that face, its x
// continues the rim's; x along the triangle's own rest normal counted a shell draped round the
// rim as 15–31 mm deep where its corners, once held, gave 5.5 mm (a 1.7 → 18 → 0.8 N spike on the
// convex spatula's rim, docs/decisions.md).
void rim_contact_forces(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data, double alpha,
                        CollisionStepResult& out) {
  const HuntCrossleyParams& hc = model.params.hunt_crossley;
  const auto& planes = model.tool.planes();
  const double release_m = model.params.release_distance_m;
  const double band_m = model.tool.thickness_m() + model.params.solver_reach_m;
  for (const int face : data.broad.candidate_faces) {
    const auto f = static_cast<std::size_t>(face);
    const std::array<int, 3>& nodes = model.soft.face_nodes[f];
    if (std::any_of(nodes.begin(), nodes.end(), [&](int node) { return data.displacement.moved_stamp[static_cast<std::size_t>(node)] == frame.step; })) continue;
    SoftTriangleInTool triangle;
    if (!soft_triangle_in_tool(model, frame, soft, face, triangle)) continue;
    const Eigen::Vector3d& normal = triangle.normal;
    // The rim within release_distance in front of the plane needs the tool's lowest corner there.
    const ToolHeightRange range = tool_height_range(model, triangle.x[0], normal);
    if (range.lowest_m > release_m || range.highest_m < -band_m) continue;
    const TriangleToolExtent extent = triangle_tool_extent(model.tool, triangle.x, normal, std::max(band_m, release_m));
    if (!extent.meets || extent.lowest_m > release_m || extent.lowest_m < -band_m) continue;
    const double share = release_share(std::max(0.0, extent.lowest_m), release_m);
    if (!(share > 0.0)) continue;
    const Eigen::Vector3d& deepest = extent.deepest_tool_m;
    const std::array<double, 3> w = barycentric_of_foot(triangle, deepest);
    Eigen::Vector3d rest_point = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) rest_point += w[k] * model.soft.rest_node_world_m[static_cast<std::size_t>(nodes[k])];
    const Eigen::Vector3d deepest_world = frame.r_cur * deepest + frame.t_cur;
    // The tool face through the deepest point that faces the triangle most.
    int plane_index = -1;
    double facing = -std::numeric_limits<double>::infinity();
    for (std::size_t q = 0; q < planes.size(); ++q) {
      if (std::abs(planes[q].normal_tool.dot(deepest) - planes[q].offset_m) > kRimOnPlane_m) continue;
      const double facing_q = -planes[q].normal_tool.dot(normal);
      if (facing_q > facing) {
        facing = facing_q;
        plane_index = static_cast<int>(q);
      }
    }
    if (plane_index < 0) continue;
    const Eigen::Vector3d normal_world = frame.r_cur * planes[static_cast<std::size_t>(plane_index)].normal_tool;
    // The corners' measure at the foot: how far that face's plane has advanced past the rest point.
    const double x_m = std::max(0.0, normal_world.dot(deepest_world - rest_point));
    // ẋ is the tool's advance at this foot: the same rest point and tool point at the previous
    // pose. The foot itself slides over the rest surface as the tissue is carried round the rim,
    // and differencing x across that slide counted the tissue's tangential travel as indentation
    // (the rounded rim of convex-spatula-sphere: ẋ up to 1.4 × the tool's speed, docs/decisions.md).
    const Eigen::Vector3d normal_prev_world = frame.r_prev * planes[static_cast<std::size_t>(plane_index)].normal_tool;
    const double x_start_m = std::max(0.0, normal_prev_world.dot(frame.r_prev * deepest + frame.t_prev - rest_point));
    if (data.force.hc_stamp[f] == frame.step - 1) data.force.hc_x_prev_m[f] = x_start_m;
    const double rate =
        filtered_rate(data.force.hc_stamp[f], data.force.hc_x_prev_m[f], data.force.hc_rate_filtered_m_s[f], frame.step, x_m, x_start_m, frame.dt_s, alpha);
    const double area_weight = hc.per_unit_area ? model.soft.rest_area_m2[f] : 1.0;
    const double x_pow_n = std::pow(x_m, hc.n);
    const double force = share * (area_weight / 3.0) * std::max(0.0, hc.k * x_pow_n + hc.lambda * x_pow_n * rate);
    add_contact(ContactRecord{face, -1, plane_index, model.params.jaw, deepest_world, normal_world, x_m, rate, share * area_weight / 3.0, force}, out);
  }
}

}  // namespace

void hunt_crossley_force(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft,
                         CollisionData& data, CollisionStepResult& out) {
  const HuntCrossleyParams& hc = model.params.hunt_crossley;
  const double time_constant_s = 1.0 / (2.0 * std::numbers::pi * model.params.velocity_filter_cutoff_hz);
  const double alpha = frame.dt_s / (frame.dt_s + time_constant_s);
  const auto& planes = model.tool.planes();
  const bool normal_measure = hc.measure == DeformationMeasure::kNormalDisplacement;
  const double onset_ramp_per_step =
      model.params.contact_onset_ramp_s > frame.dt_s ? frame.dt_s / model.params.contact_onset_ramp_s : 1.0;
  for (const int face : data.exclusion.contacted_faces) {
    const auto f = static_cast<std::size_t>(face);
    const Eigen::Vector3d c_now = centroid(model.soft, soft, face, false);
    const int plane_index = data.exclusion.face_plane[f];
    const ToolPlane& plane = planes[static_cast<std::size_t>(plane_index)];
    const Eigen::Vector3d normal_world = frame.r_cur * plane.normal_tool;
    const Eigen::Vector3d normal_prev_world = frame.r_prev * plane.normal_tool;
    const double area_weight = hc.per_unit_area ? model.soft.rest_area_m2[f] : 1.0;

    double force = 0.0;
    double x_record = 0.0;
    double rate_record = 0.0;
    double weight = 0.0;
    if (normal_measure) {
      double share_sum = 0.0;
      double share_x_pow_n = 0.0;
      double share_x_pow_n_rate = 0.0;
      for (std::size_t corner = 0; corner < 3; ++corner) {
        const int node = model.soft.face_nodes[f][corner];
        const auto v = static_cast<std::size_t>(node);
        if (data.displacement.moved_stamp[v] != frame.step) continue;  // not a colliding vertex
        const Eigen::Vector3d& rest = model.soft.rest_node_world_m[v];
        const double x = std::max(0.0, plane.offset_m + normal_world.dot(frame.t_cur - rest));
        const double x_start = std::max(0.0, plane.offset_m + normal_prev_world.dot(frame.t_prev - rest));
        const std::size_t slot = 3 * f + corner;
        const bool joined = data.force.hc_corner_stamp[slot] != frame.step - 1;
        double& onset = data.force.hc_corner_onset[slot];
        onset = joined ? onset_ramp_per_step : std::min(1.0, onset + onset_ramp_per_step);
        const double share = data.displacement.node_share[v] * onset;
        // In the world rest frame x is a function of the tool pose and of the plane only, so this
        // plane's x at the previous pose (x_start) is last step's x — unless the triangle's force
        // plane changed (its first colliding corner is now held on another plane, e.g. round a
        // rim): then last step's x was taken along another normal, and differencing across the
        // switch turned a change of plane into an indentation rate (mm per ms is m/s, × λ). The
        // filter restarts from x_start at a switch, as at first contact.
        if (data.force.hc_corner_stamp[slot] == frame.step - 1 &&
            std::abs(data.force.hc_corner_x_prev_m[slot] - x_start) > kPlaneSwitchTolerance_m)
          data.force.hc_corner_stamp[slot] = -1;
        const double rate = filtered_rate(data.force.hc_corner_stamp[slot], data.force.hc_corner_x_prev_m[slot],
                                          data.force.hc_corner_rate_filtered_m_s[slot], frame.step, x, x_start, frame.dt_s, alpha);
        const double x_pow_n = std::pow(x, hc.n);
        force += share * (area_weight / 3.0) * std::max(0.0, hc.k * x_pow_n + hc.lambda * x_pow_n * rate);
        share_sum += share;
        share_x_pow_n += share * x_pow_n;
        share_x_pow_n_rate += share * x_pow_n * rate;
      }
      // One record per triangle that reproduces its elastic part: weight·k·xⁿ = Σ s_v·(w/3)·k·x_vⁿ.
      weight = area_weight * share_sum / 3.0;
      x_record = share_sum > 0.0 ? std::pow(share_x_pow_n / share_sum, 1.0 / hc.n) : 0.0;
      rate_record = share_x_pow_n > 0.0 ? share_x_pow_n_rate / share_x_pow_n : 0.0;
    } else {
      const double x = (c_now - model.soft.rest_centroid_world_m[f]).norm();
      const double x_start = (centroid(model.soft, soft, face, true) - model.soft.rest_centroid_world_m[f]).norm();
      const double rate =
          filtered_rate(data.force.hc_stamp[f], data.force.hc_x_prev_m[f], data.force.hc_rate_filtered_m_s[f], frame.step, x, x_start, frame.dt_s, alpha);
      // Per unit area the sum is a quadrature of k·xⁿ over the contacted surface. A triangle at the
      // rim of the patch has only some vertices on the tool: counting its whole area there adds a
      // ring one edge wide (an O(h) error — with the whole area, 1280/5120/20480 faces gave
      // 1.47/1.25/1.19 N at 4 mm). Its contacted share is taken as the fraction of its vertices
      // that are colliding (the contact indicator interpolated linearly over the triangle).
      double contacted_share = 1.0;
      if (hc.per_unit_area) {
        int colliding = 0;
        for (const int node : model.soft.face_nodes[f]) colliding += data.displacement.moved_stamp[static_cast<std::size_t>(node)] == frame.step ? 1 : 0;
        contacted_share = colliding / 3.0;
      }
      weight = contacted_share * area_weight;
      const double x_pow_n = std::pow(x, hc.n);
      force = std::max(0.0, weight * (hc.k * x_pow_n + hc.lambda * x_pow_n * rate));
      x_record = x;
      rate_record = rate;
    }
    add_contact(ContactRecord{face, data.exclusion.face_lead_node[f], plane_index, model.params.jaw, c_now, normal_world, x_record, rate_record, weight, force}, out);
  }
  if (model.params.response == ContactResponse::kInSolver) rim_contact_forces(model, frame, soft, data, alpha, out);
}

}  // namespace fissure::host::thin_body
