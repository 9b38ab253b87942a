#pragma once
// Small tetrahedral meshes for the tet mesh import tests: a unit-less cube of 5 tetrahedra, a
// box of Kuhn cells (6 tetrahedra per cube, conforming), and their files in Gmsh .msh 4.1,
// VTK legacy (3.0 and 5.1) and TetGen .node/.ele, with the line each element lands on.
#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "fissure/host_sim/tet_mesh.hpp"

namespace fissure::host::test_tets {

inline double volume6(const TetMesh& m, const std::array<int, 4>& t) {
  const auto& a = m.vertices_m[static_cast<std::size_t>(t[0])];
  const auto& b = m.vertices_m[static_cast<std::size_t>(t[1])];
  const auto& c = m.vertices_m[static_cast<std::size_t>(t[2])];
  const auto& d = m.vertices_m[static_cast<std::size_t>(t[3])];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
               w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

inline void orient_positive(TetMesh& m) {
  for (auto& t : m.tetrahedra)
    if (volume6(m, t) < 0.0) std::swap(t[2], t[3]);
}

/// The box [0, sx] × [0, sy] × [0, sz] as 5 tetrahedra: four corners (0, 2, 5, 7) cut off a
/// central one; vertex i as in test_meshes::cube. All positive.
inline TetMesh cube5(double sx = 1.0, double sy = 1.0, double sz = 1.0) {
  TetMesh m;
  m.source = "cube5";
  for (int i = 0; i < 8; ++i) {
    const int x = (i == 1 || i == 2 || i == 5 || i == 6) ? 1 : 0;
    const int y = (i == 2 || i == 3 || i == 6 || i == 7) ? 1 : 0;
    const int z = i >= 4 ? 1 : 0;
    m.vertices_m.push_back({sx * x, sy * y, sz * z});
  }
  m.tetrahedra = {{0, 1, 3, 4}, {2, 1, 3, 6}, {5, 1, 4, 6}, {7, 3, 4, 6}, {1, 3, 4, 6}};
  orient_positive(m);
  return m;
}

/// A box of n[0] × n[1] × n[2] cubes of `cell_m`, each split into the 6 Kuhn tetrahedra along
/// its (0,0,0)–(1,1,1) diagonal (every shared face split the same way: conforming), from `origin`.
inline TetMesh kuhn_box(std::array<int, 3> n, double cell_m, std::array<double, 3> origin = {0.0, 0.0, 0.0}) {
  TetMesh m;
  m.source = "kuhn box";
  const auto id = [&](int i, int j, int k) { return (i * (n[1] + 1) + j) * (n[2] + 1) + k; };
  for (int i = 0; i <= n[0]; ++i)
    for (int j = 0; j <= n[1]; ++j)
      for (int k = 0; k <= n[2]; ++k) m.vertices_m.push_back({origin[0] + cell_m * i, origin[1] + cell_m * j, origin[2] + cell_m * k});
  constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k)
        for (const auto& p : kPermutations) {
          std::array<int, 3> at{i, j, k};
          std::array<int, 4> t{id(i, j, k), 0, 0, 0};
          for (int s = 0; s < 3; ++s) {
            ++at[static_cast<std::size_t>(p[s])];
            t[static_cast<std::size_t>(s) + 1] = id(at[0], at[1], at[2]);
          }
          m.tetrahedra.push_back(t);
        }
  orient_positive(m);
  return m;
}

/// Gmsh .msh 4.1 ASCII. Node tags 10·i + 7 (not 1..n: the reader maps tags); one extra
/// geometry node no element uses; a block of a point element and one of a triangle before the
/// tetrahedra (skipped). Element tags from 100. Tetrahedron t is on line first_tet_line + t.
inline std::string write_msh(const TetMesh& m, const std::filesystem::path& path) {
  std::ofstream out(path);
  out.precision(17);
  const std::size_t n = m.vertices_m.size();
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";                                // lines 1-3
  out << "$PhysicalNames\n1\n3 1 \"body\"\n$EndPhysicalNames\n";                   // lines 4-7
  out << "$Nodes\n2 " << n + 1 << " 7 " << 10 * n + 7 << "\n";                       // lines 8-9
  out << "3 1 0 " << n << "\n";
  for (std::size_t i = 0; i < n; ++i) out << 10 * i + 7 << "\n";
  for (const auto& v : m.vertices_m) out << v[0] << ' ' << v[1] << ' ' << v[2] << "\n";
  out << "0 1 0 1\n" << 10 * n + 7 << "\n0.5 0.5 0.5\n";                            // the unused node
  out << "$EndNodes\n";
  // Lines from here: $Elements, header, point block (2 lines), triangle block (2 lines), tet block header.
  out << "$Elements\n3 " << m.tetrahedra.size() + 2 << " 1 " << 100 + m.tetrahedra.size() << "\n";
  out << "0 1 15 1\n1 7\n";
  out << "2 1 2 1\n2 7 17 27\n";
  out << "3 1 4 " << m.tetrahedra.size() << "\n";
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) {
    out << 100 + t;
    for (const int c : m.tetrahedra[t]) out << ' ' << 10 * c + 7;
    out << "\n";
  }
  out << "$EndElements\n";
  return path.string();
}
/// The line of tetrahedron t in write_msh's file.
inline int msh_tet_line(const TetMesh& m, std::size_t t) { return static_cast<int>(9 + 3 + 1 + 2 * m.vertices_m.size() + 1 + 6 + 1 + t + 1); }

/// VTK legacy 3.0 (per cell its count and indices) or 5.1 (OFFSETS / CONNECTIVITY), with a
/// triangle cell first (skipped) and the points 3 to a line. Tetrahedron t is cell t + 1.
inline std::string write_vtk(const TetMesh& m, const std::filesystem::path& path, bool version5 = false) {
  std::ofstream out(path);
  out.precision(17);
  out << "# vtk DataFile Version " << (version5 ? "5.1" : "3.0") << "\ntest mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << m.vertices_m.size() << " double\n";
  for (const auto& v : m.vertices_m) out << v[0] << ' ' << v[1] << ' ' << v[2] << "\n";
  const std::size_t cells = m.tetrahedra.size() + 1;
  if (version5) {
    out << "CELLS " << cells + 1 << ' ' << 3 + 4 * m.tetrahedra.size() << "\nOFFSETS vtktypeint64\n0 3";
    for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) out << ' ' << 3 + 4 * (t + 1);
    out << "\nCONNECTIVITY vtktypeint64\n0 1 2\n";
    for (const auto& t : m.tetrahedra) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << "\n";
  } else {
    out << "CELLS " << cells << ' ' << 4 + 5 * m.tetrahedra.size() << "\n3 0 1 2\n";
    for (const auto& t : m.tetrahedra) out << "4 " << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << "\n";
  }
  out << "CELL_TYPES " << cells << "\n5\n";
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) out << "10\n";
  out << "CELL_DATA " << cells << "\nSCALARS region int 1\nLOOKUP_TABLE default\n";
  for (std::size_t c = 0; c < cells; ++c) out << "1\n";
  return path.string();
}
/// The line of tetrahedron t in write_vtk's file (both versions).
inline int vtk_tet_line(const TetMesh& m, std::size_t t, bool version5 = false) {
  return static_cast<int>(5 + m.vertices_m.size() + (version5 ? 5 : 2) + t + 1);
}

/// TetGen .node / .ele, numbered from 1, with a comment line and a boundary marker and region
/// attribute column (as tetgen -A writes). Returns the .node path; tetrahedron t is on line 3 + t of the .ele.
inline std::string write_tetgen(const TetMesh& m, const std::filesystem::path& base) {
  {
    std::ofstream out(base.string() + ".node");
    out.precision(17);
    out << m.vertices_m.size() << " 3 0 1\n";
    for (std::size_t i = 0; i < m.vertices_m.size(); ++i) out << i + 1 << "  " << m.vertices_m[i][0] << ' ' << m.vertices_m[i][1] << ' ' << m.vertices_m[i][2] << "  0\n";
    out << "# Generated by a test\n";
  }
  std::ofstream out(base.string() + ".ele");
  out << "# tetrahedra\n" << m.tetrahedra.size() << " 4 1\n";
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) {
    out << t + 1;
    for (const int c : m.tetrahedra[t]) out << ' ' << c + 1;
    out << " 1  # region 1\n";
  }
  return base.string() + ".node";
}

/// A file's text with `from` replaced by `to` (first occurrence), written back.
inline void edit(const std::string& path, const std::string& from, const std::string& to) {
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t at = text.find(from);
  if (at != std::string::npos) text.replace(at, from.size(), to);
  std::ofstream(path) << text;
}

}  // namespace fissure::host::test_tets
