// Generated tool meshes: the convex thin spatula with rounded rims (paper Fig. 1 middle, Fig. 2).
#include <fissure/host_sim/thin_tool.hpp>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace fissure::host {

ConvexMeshToolShape make_rounded_spatula_mesh(const RoundedSpatulaParams& params, double pairing_ray_limit_m) {
  const double rim_radius_m = 0.5 * params.thickness_m;
  if (!(params.length_m > 0.0 && params.width_m > 0.0 && params.thickness_m > 0.0))
    throw std::invalid_argument("rounded spatula: length, width and thickness must be > 0");
  if (!(params.corner_radius_m > rim_radius_m) || 2.0 * params.corner_radius_m > std::min(params.length_m, params.width_m))
    throw std::invalid_argument("rounded spatula: corner_radius_m must exceed thickness/2 and fit the outline");
  if (params.corner_segments < 1 || params.rim_segments < 2 || params.face_divisions < 1)
    throw std::invalid_argument("rounded spatula: corner_segments >= 1, rim_segments >= 2, face_divisions >= 1");

  // The solid is the Minkowski sum of a flat rounded rectangle (inner outline, offset inward by
  // the rim radius) with a ball of radius thickness/2: flat faces at y = ±thickness/2 and a rim
  // with a half-circle profile. Convex by construction.
  const double inner_corner_radius_m = params.corner_radius_m - rim_radius_m;
  const double cx = 0.5 * params.length_m - params.corner_radius_m;
  const double cz = 0.5 * params.width_m - params.corner_radius_m;
  struct OutlinePoint {
    double x, z, mx, mz;
  };
  std::vector<OutlinePoint> outline;
  const double corner_x[4] = {cx, -cx, -cx, cx};
  const double corner_z[4] = {cz, cz, -cz, -cz};
  for (int corner = 0; corner < 4; ++corner) {
    for (int s = 0; s <= params.corner_segments; ++s) {
      const double theta = (corner + static_cast<double>(s) / params.corner_segments) * 0.5 * std::numbers::pi;
      const double mx = std::cos(theta);
      const double mz = std::sin(theta);
      outline.push_back({corner_x[corner] + inner_corner_radius_m * mx, corner_z[corner] + inner_corner_radius_m * mz, mx, mz});
    }
  }
  const int k_count = static_cast<int>(outline.size());
  ConvexMeshToolShape mesh;
  mesh.pairing_ray_limit_m = pairing_ray_limit_m;
  // Rim rings j = 0 (bottom, y = −r) .. rim_segments (top, y = +r).
  const int rings = params.rim_segments + 1;
  const auto rim_vertex = [&](int k, int j) { return j * k_count + (k % k_count); };
  for (int j = 0; j < rings; ++j) {
    const double phi = -0.5 * std::numbers::pi + std::numbers::pi * j / params.rim_segments;
    for (const auto& o : outline) {
      const double radial = rim_radius_m * std::cos(phi);
      mesh.vertices_tool_m.emplace_back(o.x + radial * o.mx, rim_radius_m * std::sin(phi), o.z + radial * o.mz);
    }
  }
  for (int j = 0; j + 1 < rings; ++j) {
    for (int k = 0; k < k_count; ++k) {
      mesh.triangles.push_back({rim_vertex(k, j), rim_vertex(k + 1, j), rim_vertex(k + 1, j + 1)});
      mesh.triangles.push_back({rim_vertex(k, j), rim_vertex(k + 1, j + 1), rim_vertex(k, j + 1)});
    }
  }
  // Flat faces: nested scaled copies of the outline (scale i / D) around the centre, so node
  // density grows with face_divisions; ring D is the rim's top / bottom ring.
  for (const double sign : {1.0, -1.0}) {
    const int outer_ring_start = sign > 0 ? rim_vertex(0, rings - 1) : rim_vertex(0, 0);
    const int centre = static_cast<int>(mesh.vertices_tool_m.size());
    mesh.vertices_tool_m.emplace_back(0.0, sign * rim_radius_m, 0.0);
    std::vector<int> ring_start(static_cast<std::size_t>(params.face_divisions + 1), -1);
    for (int i = 1; i < params.face_divisions; ++i) {
      ring_start[static_cast<std::size_t>(i)] = static_cast<int>(mesh.vertices_tool_m.size());
      const double scale = static_cast<double>(i) / params.face_divisions;
      for (const auto& o : outline) mesh.vertices_tool_m.emplace_back(scale * o.x, sign * rim_radius_m, scale * o.z);
    }
    ring_start[static_cast<std::size_t>(params.face_divisions)] = outer_ring_start;
    const auto at = [&](int ring, int k) { return ring_start[static_cast<std::size_t>(ring)] + (k % k_count); };
    for (int k = 0; k < k_count; ++k) mesh.triangles.push_back({centre, at(1, k), at(1, k + 1)});
    for (int i = 1; i < params.face_divisions; ++i) {
      for (int k = 0; k < k_count; ++k) {
        mesh.triangles.push_back({at(i, k), at(i + 1, k), at(i + 1, k + 1)});
        mesh.triangles.push_back({at(i, k), at(i + 1, k + 1), at(i, k + 1)});
      }
    }
  }
  // Orient every triangle outward (the solid is star-shaped about the origin).
  for (auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices_tool_m[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices_tool_m[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices_tool_m[static_cast<std::size_t>(t[2])];
    if ((b - a).cross(c - a).dot(a + b + c) < 0.0) std::swap(t[1], t[2]);
  }
  return mesh;
}

}  // namespace fissure::host
