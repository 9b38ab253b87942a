#pragma once
// Shape checks of a closed triangle surface (tools and soft bodies, issue 24), each linear or
// n log n in the mesh size: finite coordinates, valid indices, no degenerate triangle, every
// edge shared by exactly two triangles running it in opposite directions (closed, manifold,
// consistently oriented), one connected surface, facing outwards; and for tools, convexity
// within a tolerance (a box tree over the vertices, mesh_bvh.hpp). A failure throws MeshDefect
// naming the element (0-based inside, 1-based in the text) and the reason; describe() adds the
// file and the line.
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fissure/host_sim/mesh_file.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::host {

class MeshDefect : public std::runtime_error {
 public:
  enum class Element : std::uint8_t { kMesh, kVertex, kTriangle };
  MeshDefect(Element element, int index, const std::string& reason) : std::runtime_error(reason), element_(element), index_(index) {}
  [[nodiscard]] Element element() const noexcept { return element_; }
  [[nodiscard]] int index() const noexcept { return index_; }

 private:
  Element element_;
  int index_;
};

/// Throws MeshDefect unless the mesh is a closed, manifold, consistently and outward-oriented
/// single surface with at least 4 vertices and 4 triangles, finite coordinates and no triangle
/// whose |(b − a) × (c − a)| ≤ min_cross_m2 (twice its area; a repeated corner is degenerate).
/// Outward: the enclosed (signed) volume is positive.
void check_closed_surface(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int, 3>>& triangles, double min_cross_m2);

/// Throws MeshDefect(kTriangle) at the first triangle (in file order) whose plane has a vertex v
/// with unit_normal·(v − a) > tolerance_m (a = its first corner): the mesh is not convex.
void check_convex(const std::vector<Eigen::Vector3d>& vertices_m, const std::vector<std::array<int, 3>>& triangles, double tolerance_m);

/// "'PATH': triangle 7 (line 40): REASON" (or vertex / the whole mesh).
[[nodiscard]] std::string describe(const MeshFile& file, const MeshDefect& defect);

}  // namespace fissure::host
