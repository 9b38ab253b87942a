// Stage 2 of the thin-body collision (host_sim/src/thin_body/node_sweep.cpp), tested through its
// internal interface: the contacts it finds must be exactly those of a brute-force sweep that
// applies the node test to EVERY tool node against every candidate triangle — no bins, no
// footprint, no skipping — in every step, including the steps that carry the soft surface through
// the tool within one step. (A footprint of the triangle's swept bounds + contact + memory depth
// loses a node that touches a triangle at the start of such a step and ends far behind it: its
// projection on the end triangle lies outside those bounds. This test catches that in about a
// third of such steps.)
// Random soft surfaces (a 1280-face sphere pressed into / swept past the tool, with every node
// jittered), random side memory, box tools with rims, a convex spatula, and a fine plate whose
// bins are clamped at 256 cells per axis (edge cells holding nodes from far outside them).
// Each suite prints the node tests per step (held / pressing / through), the sweep's cost measure.
#include "thin_body/collision_state.hpp"

#include <gtest/gtest.h>

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "soft_scene_fixture.hpp"

namespace fissure::host {
namespace {

// The node test of node_sweep.cpp, written out for one tool node against one triangle, with no
// bins and no skipping (the same arithmetic, so the comparison can be exact).
struct Tri {
  Eigen::Vector3d a, e0, e1, normal;
  double d00 = 0, d01 = 0, d11 = 0, inverse = 0;
  bool valid = false;
};

Tri tri(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double sign) {
  Tri t;
  t.a = a;
  t.e0 = b - a;
  t.e1 = c - a;
  const Eigen::Vector3d n = t.e0.cross(t.e1);
  const double length = n.norm();
  t.d00 = t.e0.dot(t.e0);
  t.d01 = t.e0.dot(t.e1);
  t.d11 = t.e1.dot(t.e1);
  const double denominator = t.d00 * t.d11 - t.d01 * t.d01;
  t.valid = length > 1e-18 && denominator > 0.0;
  t.normal = t.valid ? Eigen::Vector3d(sign * n / length) : Eigen::Vector3d::Zero();
  t.inverse = t.valid ? 1.0 / denominator : 0.0;
  return t;
}

bool inside(const Tri& t, const Eigen::Vector3d& p) {
  const Eigen::Vector3d v2 = p - t.a;
  const double d20 = v2.dot(t.e0);
  const double d21 = v2.dot(t.e1);
  const double v = (t.d11 * d20 - t.d01 * d21) * t.inverse;
  const double w = (t.d00 * d21 - t.d01 * d20) * t.inverse;
  return v >= -1e-7 && w >= -1e-7 && v + w <= 1.0 + 1e-7;
}

struct BruteForce {
  std::vector<int> face;
  std::vector<double> tau, facing;
  // The contact lies, across the bins' axes, outside its triangle's swept bounds + contact distance
  // + memory depth (a footprint padded that way loses such nodes).
  std::vector<char> beyond_swept_bounds;
};

BruteForce brute_force(const thin_body::CollisionModel& model, const thin_body::CollisionData& data, const std::vector<int>& face_prev) {
  const auto count = static_cast<std::size_t>(model.tool.node_count());
  BruteForce out{std::vector<int>(count, -1), std::vector<double>(count, 0.0), std::vector<double>(count, 0.0), std::vector<char>(count, 0)};
  const double contact = model.params.contact_distance_m;
  const double sign = model.soft.outward_sign;
  for (const int face : data.broad.candidate_faces) {
    const auto& v = model.soft.face_nodes[static_cast<std::size_t>(face)];
    const auto s = [&](int k) { return data.broad.start_tool_m[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const auto e = [&](int k) { return data.broad.end_tool_m[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const Tri start = tri(s(0), s(1), s(2), sign);
    const Tri end = tri(e(0), e(1), e(2), sign);
    if (!start.valid || !end.valid) continue;
    Eigen::AlignedBox3d swept;
    for (int k = 0; k < 3; ++k) swept.extend(s(k)).extend(e(k));
    const double pad = contact + model.memory_depth_m;
    swept.min().array() -= pad;
    swept.max().array() += pad;
    for (std::size_t n = 0; n < count; ++n) {
      const Eigen::Vector3d& p = model.tool.positions_tool_m()[n];
      const double s_end = end.normal.dot(p - end.a);
      if (s_end > contact) continue;
      const double s_start = start.normal.dot(p - start.a);
      if (s_start < -contact && !(face_prev[n] >= 0 && s_start >= -model.memory_depth_m)) continue;
      const double tau = s_start > contact ? (s_start - contact) / (s_start - s_end) : 1.0;
      Tri at = end;
      if (tau < 1.0) at = tri(s(0) + tau * (e(0) - s(0)), s(1) + tau * (e(1) - s(1)), s(2) + tau * (e(2) - s(2)), sign);
      if (!at.valid || !inside(at, p)) continue;
      if (out.face[n] < 0 || tau < out.tau[n] - 1e-12) {
        out.face[n] = face;
        out.tau[n] = tau;
        out.facing[n] = model.tool.normals_tool()[n].dot(at.normal);
        const int iu = model.bins.axis_u;
        const int iv = model.bins.axis_v;
        out.beyond_swept_bounds[n] =
            p[iu] < swept.min()[iu] || p[iu] > swept.max()[iu] || p[iv] < swept.min()[iv] || p[iv] > swept.max()[iv] ? 1 : 0;
      }
    }
  }
  return out;
}

// Soft node positions in the tool frame: the sphere's rest shape, turned and placed so that it
// reaches `depth` past the tool's face at (u, v), plus a random jitter per node.
void place_sphere(const btSoftBody& soft, const Eigen::Vector3d& centre_tool, const Eigen::Matrix3d& rotation, double jitter_m, std::mt19937& rng,
                  std::vector<Eigen::Vector3d>& out) {
  std::uniform_real_distribution<double> noise(-jitter_m, jitter_m);
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  for (int i = 0; i < soft.m_nodes.size(); ++i) com += Eigen::Vector3d(soft.m_nodes[i].m_x.x(), soft.m_nodes[i].m_x.y(), soft.m_nodes[i].m_x.z());
  com /= soft.m_nodes.size();
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    const Eigen::Vector3d x(soft.m_nodes[i].m_x.x(), soft.m_nodes[i].m_x.y(), soft.m_nodes[i].m_x.z());
    out[static_cast<std::size_t>(i)] = centre_tool + rotation * (x - com) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

// What a comparison saw (so a test can check it exercised something): tool-node contacts, and
// those beyond their triangle's swept bounds + contact + memory depth.
struct Seen {
  int contacts = 0;
  int beyond_swept_bounds = 0;
};

// Runs `trials` random steps through sweep_tool_nodes and the brute force and compares them.
Seen compare_with_brute_force(const ToolNodes& tool, int trials, unsigned seed, const std::string& label, int sphere_resolution = 639) {
  test_scene::SoftWorld world(true);
  world.add_sphere(test_scene::kSphereRadius_m, sphere_resolution);  // 639: 1280 faces; 63: 128
  const btSoftBody& soft = world.soft();
  ThinBodyCollisionParams params;
  thin_body::CollisionModel model = thin_body::build_collision_model(tool, soft, params, true);
  thin_body::CollisionData data;
  thin_body::allocate_collision_data(model, data);
  const int w = tool.thin_axis();
  const Eigen::AlignedBox3d& bounds = tool.bounds_tool_m();
  const double r = test_scene::kSphereRadius_m;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Seen seen;
  // Node tests per step by kind (held / pressing / through), all steps and the unjittered ones.
  std::array<long, 3> node_tests_by_kind{};
  std::array<int, 3> trials_by_kind{};
  std::array<long, 3> rigid_node_tests_by_kind{};
  std::array<int, 3> rigid_trials_by_kind{};
  for (int trial = 0; trial < trials; ++trial) {
    ++data.step;
    // Start and end: the sphere pressed into the tool's +w face (depths −2 … +8 mm), sometimes
    // swept through the tool within the step (end past the far face), sometimes just moved a
    // little (a held contact), turned a little or a lot, with node jitter up to 1 mm.
    const Eigen::Matrix3d turn = random_rotation(rng);
    const double u = bounds.min()[(w + 1) % 3] + unit(rng) * bounds.sizes()[(w + 1) % 3];
    const double v = bounds.min()[(w + 2) % 3] + unit(rng) * bounds.sizes()[(w + 2) % 3];
    Eigen::Vector3d centre_start = Eigen::Vector3d::Zero();
    centre_start[(w + 1) % 3] = u;
    centre_start[(w + 2) % 3] = v;
    centre_start[w] = bounds.max()[w] + r - (-0.002 + 0.01 * unit(rng));
    Eigen::Vector3d centre_end = centre_start;
    const int kind = trial % 3;
    if (kind == 0) centre_end[w] -= 1e-4 * unit(rng);                       // held
    if (kind == 1) centre_end[w] -= 0.003 * unit(rng);                      // pressing
    if (kind == 2) centre_end[w] -= bounds.sizes()[w] + 0.02 * unit(rng);  // through the tool in one step
    const Eigen::Matrix3d rotation_start = turn;
    const Eigen::Matrix3d rotation_end = trial % 2 == 0 ? turn : Eigen::Matrix3d(turn * Eigen::AngleAxisd(0.2 * unit(rng), Eigen::Vector3d::UnitX()));
    const double jitter = trial % 4 == 0 ? 0.0 : 1e-3 * unit(rng);
    place_sphere(soft, centre_start, rotation_start, jitter, rng, data.broad.start_tool_m);
    place_sphere(soft, centre_end, rotation_end, jitter, rng, data.broad.end_tool_m);
    data.broad.candidate_faces.clear();
    for (int f = 0; f < model.soft.face_count; ++f) data.broad.candidate_faces.push_back(f);
    // Side memory: last step's contacts (what the sweep keeps from the step before) on ~20 % of
    // the nodes on one face, so the memory-depth path and the per-plane "had contact" are used.
    data.sweep.contact_nodes.clear();
    std::fill(data.sweep.node_face.begin(), data.sweep.node_face.end(), -1);
    for (int n = 0; n < tool.node_count(); ++n) {
      if (unit(rng) < 0.2 && tool.normals_tool()[static_cast<std::size_t>(n)][w] > 0.5) {
        data.sweep.node_face[static_cast<std::size_t>(n)] = 0;
        data.sweep.contact_nodes.push_back(n);
      }
    }
    const std::vector<int> face_prev = data.sweep.node_face;
    std::fill(data.sweep.node_age.begin(), data.sweep.node_age.end(), 1);  // so that the expected ages are 2 (held on) or 1 (new)
    const BruteForce expected = brute_force(model, data, face_prev);
    thin_body::sweep_tool_nodes(model, data);
    node_tests_by_kind[static_cast<std::size_t>(kind)] += data.sweep.node_tests;
    ++trials_by_kind[static_cast<std::size_t>(kind)];
    if (jitter == 0.0) {
      rigid_node_tests_by_kind[static_cast<std::size_t>(kind)] += data.sweep.node_tests;
      ++rigid_trials_by_kind[static_cast<std::size_t>(kind)];
    }
    int contacts = 0;
    int mismatches = 0;
    for (std::size_t n = 0; n < expected.face.size(); ++n) {
      contacts += expected.face[n] >= 0 ? 1 : 0;
      seen.beyond_swept_bounds += expected.face[n] >= 0 && expected.beyond_swept_bounds[n] != 0 ? 1 : 0;
      const bool same = data.sweep.node_face[n] == expected.face[n] &&
                        (expected.face[n] < 0 || (data.sweep.node_tau[n] == expected.tau[n] && data.sweep.node_facing[n] == expected.facing[n]));
      if (!same && mismatches++ < 3)
        ADD_FAILURE() << label << " trial " << trial << " tool node " << n << ": sweep face " << data.sweep.node_face[n] << " tau " << data.sweep.node_tau[n]
                      << ", brute force face " << expected.face[n] << " tau " << expected.tau[n];
    }
    EXPECT_EQ(mismatches, 0) << label << " trial " << trial;
    // The contact list: every node in contact once, in index order, and their ages.
    std::vector<int> listed;
    for (std::size_t n = 0; n < expected.face.size(); ++n)
      if (expected.face[n] >= 0) listed.push_back(static_cast<int>(n));
    EXPECT_EQ(data.sweep.contact_nodes, listed) << label << " trial " << trial;
    for (const int n : listed)
      EXPECT_EQ(data.sweep.node_age[static_cast<std::size_t>(n)], face_prev[static_cast<std::size_t>(n)] >= 0 ? 2 : 1) << label << " node " << n;
    seen.contacts += contacts;
  }
  const auto per_step = [](const std::array<long, 3>& tests, const std::array<int, 3>& steps, std::size_t kind) {
    return tests[kind] / std::max(1, steps[kind]);
  };
  std::cout << label << " (" << tool.node_count() << " tool nodes): node tests per step held / pressing / through the tool "
            << per_step(node_tests_by_kind, trials_by_kind, 0) << " / " << per_step(node_tests_by_kind, trials_by_kind, 1) << " / "
            << per_step(node_tests_by_kind, trials_by_kind, 2) << "; without node jitter " << per_step(rigid_node_tests_by_kind, rigid_trials_by_kind, 0)
            << " / " << per_step(rigid_node_tests_by_kind, rigid_trials_by_kind, 1) << " / " << per_step(rigid_node_tests_by_kind, rigid_trials_by_kind, 2)
            << "\n";
  return seen;
}

TEST(NodeSweep, PlateWithRimsFindsExactlyTheBruteForceContacts) {
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.05, 0.001, 0.05);  // the bench's 100 × 2 × 100 mm plate, 2 mm grid
  shape.nodes_u = shape.nodes_v = 51;
  const Seen seen = compare_with_brute_force(ToolNodes::from_box(shape), 60, 11U, "plate");
  EXPECT_GT(seen.contacts, 1000) << "the random steps must produce contacts to compare";
  EXPECT_GT(seen.beyond_swept_bounds, 0) << "the steps through the tool must produce contacts the old footprint lost";
}

TEST(NodeSweep, ThinAxisAlongXFindsExactlyTheBruteForceContacts) {
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.0005, 0.03, 0.02);  // a 1 mm blade, thin along x
  shape.thin_axis = 0;
  shape.nodes_u = 31;
  shape.nodes_v = 21;
  const Seen seen = compare_with_brute_force(ToolNodes::from_box(shape), 60, 12U, "blade");
  EXPECT_GT(seen.contacts, 300);
  EXPECT_GT(seen.beyond_swept_bounds, 0);
}

TEST(NodeSweep, ConvexSpatulaFindsExactlyTheBruteForceContacts) {
  RoundedSpatulaParams params;  // 40 × 40 × 2 mm, rounded rims: tilted planes
  const Seen seen = compare_with_brute_force(ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, 3.0 * params.thickness_m)), 60, 13U,
                                             "convex spatula");
  EXPECT_GT(seen.contacts, 100);
  EXPECT_GT(seen.beyond_swept_bounds, 0);
}

TEST(NodeSweep, BinsClampedAt256CellsFindExactlyTheBruteForceContacts) {
  // 301 × 301 nodes per face: the bins stop at 256 cells per axis, so the last row / column of
  // cells holds every node beyond it (an edge cell unbounded outwards).
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.03, 0.0005, 0.03);
  shape.nodes_u = shape.nodes_v = 301;
  shape.edge_nodes = false;
  const ToolNodes tool = ToolNodes::from_box(shape);
  ThinBodyCollisionParams params;
  test_scene::SoftWorld world(true);
  world.add_sphere(test_scene::kSphereRadius_m, 63);
  const thin_body::CollisionModel model = thin_body::build_collision_model(tool, world.soft(), params, true);
  ASSERT_EQ(model.bins.cells_u, 256) << "premise: the bins are clamped";
  const Seen seen = compare_with_brute_force(tool, 12, 14U, "fine plate", 63);
  EXPECT_GT(seen.contacts, 1000);
  EXPECT_GT(seen.beyond_swept_bounds, 0);
}

}  // namespace
}  // namespace fissure::host
