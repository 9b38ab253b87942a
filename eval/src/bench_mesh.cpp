// `fissure bench mesh` (bench_mesh.hpp). Rows: the convex rounded-rim spatula of
// convex-spatula-sphere (make_rounded_spatula_mesh) at ~1k, ~41k and ~362k triangles (issue
// 24's measured sizes), written to a temporary file and loaded as a scene loads it. Stages,
// each timed on its own (wall clock, one run each: the 362k rows take seconds, not µs):
//   read  — read_tool_mesh: parse the file and run every check (check_tool_mesh);
//   check — check_tool_mesh alone on the parsed mesh (part of read);
// the 41k and 362k tools again as binary and ASCII STL (read and check only: the rest is the
// OBJ row's), and tilted to the axes (tilted_row); and soft bodies from the organ-like lobe (make_organ_blob) at 1280, 20480 and
// 327680 triangles: read = read_soft_body_mesh (parse + closed-surface checks), build =
// build_soft_body (the Bullet body with its links, as a scene's world builds it); and
// tetrahedral meshes of a box (tet_row: n³ cubes of 6 Kuhn tetrahedra, n = 10, 20, 40: 6,000,
// 48,000 and 384,000 tetrahedra) in each format: read = read_soft_body_tet_mesh (parse, weld,
// boundary and checks), build = create_from_tet_mesh (nodes, links, tetras, faces).
//   nodes — ToolNodes::from_convex_mesh: a node per triangle, coplanar planes merged, pairing rays;
//   volume — ToolVolume::from_convex_mesh: the metrics' planes and footprint;
//   load = read + nodes + volume (what `fissure sim` pays before the first step).
#include "fissure/eval/bench_mesh.hpp"

#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <BulletSoftBody/btSoftBody.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>

#include <Eigen/Geometry>

#include "fissure/host_sim/contact_metrics.hpp"
#include "fissure/host_sim/mesh_checks.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"
#include "fissure/host_sim/tet_mesh.hpp"
#include "fissure/host_sim/thin_tool.hpp"
#include "fissure/host_sim/tool_mesh_io.hpp"
#include "fissure/eval/sim_report.hpp"

namespace fissure::eval {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_of(const std::function<void()>& work) {
  const Clock::time_point start = Clock::now();
  work();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct SpatulaSize {
  const char* name;
  int corner_segments, rim_segments, face_divisions;
};

// Triangles = 4·(corner_segments + 1)·(2·rim_segments + 4·face_divisions − 2).
constexpr SpatulaSize kSizes[] = {
    {"1k", 6, 6, 8},        // 1,176: the shipped convex-spatula.obj
    {"41k", 34, 12, 68},    // 41,160
    {"362k", 99, 25, 214},  // 361,600
};

host::ConvexMeshToolShape spatula(const SpatulaSize& size) {
  host::RoundedSpatulaParams p;  // the shipped spatula's outline (app/sim_command.cpp)
  p.length_m = 0.06;
  p.width_m = 0.025;
  p.thickness_m = 0.002;
  p.corner_radius_m = 0.008;
  p.corner_segments = size.corner_segments;
  p.rim_segments = size.rim_segments;
  p.face_divisions = size.face_divisions;
  return host::make_rounded_spatula_mesh(p, 1.5 * p.thickness_m);  // convex-spatula-sphere's pairing limit
}

nlohmann::json tool_row(const SpatulaSize& size, const fs::path& dir) {
  const host::ConvexMeshToolShape shape = spatula(size);
  host::ToolMesh mesh;
  for (const auto& v : shape.vertices_tool_m) mesh.vertices_m.push_back({v.x(), v.y(), v.z()});
  mesh.triangles = shape.triangles;
  const fs::path path = dir / (std::string("spatula-") + size.name + ".obj");
  host::write_tool_mesh_obj(mesh, path.string(), "bench mesh");
  nlohmann::json row{{"mesh", std::string("spatula-") + size.name},
                     {"format", "obj"},
                     {"triangles", mesh.triangles.size()},
                     {"vertices", mesh.vertices_m.size()},
                     {"file_bytes", fs::file_size(path)}};
  std::printf("%-14s %-6s %9zu tris  ", row["mesh"].get<std::string>().c_str(), "obj", mesh.triangles.size());
  std::fflush(stdout);
  host::ToolMesh loaded;
  const double read_s = seconds_of([&] { loaded = host::read_tool_mesh(path.string()); });
  std::printf("read %8.3f s  ", read_s);
  std::fflush(stdout);
  const double check_s = seconds_of([&] { host::check_tool_mesh(loaded); });
  std::printf("(check %8.3f s)  ", check_s);
  std::fflush(stdout);
  host::ConvexMeshToolShape from_file;
  for (const auto& v : loaded.vertices_m) from_file.vertices_tool_m.emplace_back(v[0], v[1], v[2]);
  from_file.triangles = loaded.triangles;
  from_file.pairing_ray_limit_m = shape.pairing_ray_limit_m;
  int paired = 0;
  const double nodes_s = seconds_of([&] {
    const host::ToolNodes nodes = host::ToolNodes::from_convex_mesh(from_file);
    paired = nodes.pairing_report().mutual + nodes.pairing_report().one_way;
  });
  std::printf("nodes %8.3f s  ", nodes_s);
  std::fflush(stdout);
  const double volume_s = seconds_of([&] { (void)host::ToolVolume::from_convex_mesh(from_file.vertices_tool_m, from_file.triangles); });
  const double load_s = read_s + nodes_s + volume_s;
  std::printf("volume %7.3f s  load %8.3f s\n", volume_s, load_s);
  row["read_s"] = read_s;
  row["check_s"] = check_s;
  row["nodes_s"] = nodes_s;
  row["volume_s"] = volume_s;
  row["load_s"] = load_s;
  row["paired_nodes"] = paired;
  fs::remove(path);
  return row;
}

void write_stl(const host::ToolMesh& mesh, const fs::path& path, bool binary) {
  std::ofstream out(path, std::ios::binary);
  if (binary) {
    std::string bytes(80, ' ');
    const auto u32 = [&](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((v >> (8 * k)) & 0xFFU));
    };
    const auto f32 = [&](double d) {
      const auto f = static_cast<float>(d);
      std::uint32_t bits = 0;
      std::memcpy(&bits, &f, sizeof bits);
      u32(bits);
    };
    u32(static_cast<std::uint32_t>(mesh.triangles.size()));
    for (const auto& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) f32(0.0);
      for (const int c : t)
        for (const double x : mesh.vertices_m[static_cast<std::size_t>(c)]) f32(x);
      bytes.append(2, '\0');
    }
    out << bytes;
    return;
  }
  out.precision(9);
  out << "solid bench\n";
  for (const auto& t : mesh.triangles) {
    out << "facet normal 0 0 0\nouter loop\n";
    for (const int c : t) {
      const Vec3& v = mesh.vertices_m[static_cast<std::size_t>(c)];
      out << "vertex " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    }
    out << "endloop\nendfacet\n";
  }
  out << "endsolid bench\n";
}

nlohmann::json stl_row(const SpatulaSize& size, const fs::path& dir, bool binary) {
  const host::ConvexMeshToolShape shape = spatula(size);
  host::ToolMesh mesh;
  for (const auto& v : shape.vertices_tool_m) mesh.vertices_m.push_back({v.x(), v.y(), v.z()});
  mesh.triangles = shape.triangles;
  const fs::path path = dir / (std::string("spatula-") + size.name + (binary ? "-binary.stl" : "-ascii.stl"));
  write_stl(mesh, path, binary);
  const char* format = binary ? "stl-bin" : "stl-ascii";
  std::printf("%-14s %-9s %9zu tris  ", (std::string("spatula-") + size.name).c_str(), format, mesh.triangles.size());
  std::fflush(stdout);
  host::ToolMesh loaded;
  const double read_s = seconds_of([&] { loaded = host::read_tool_mesh(path.string()); });
  std::printf("read %8.3f s  (%zu vertices after welding)\n", read_s, loaded.vertices_m.size());
  nlohmann::json row{{"mesh", std::string("spatula-") + size.name}, {"format", format},     {"triangles", mesh.triangles.size()},
                     {"vertices", loaded.vertices_m.size()},          {"file_bytes", fs::file_size(path)}, {"read_s", read_s}};
  fs::remove(path);
  return row;
}

// The spatula turned 0.3 rad about (1, 2, 3): its flat faces tilted to the axes, the case a
// box around coplanar points sticks out of their plane (bench rows: the convexity check and
// the nodes stage, which need no thin axis along y).
nlohmann::json tilted_row(const SpatulaSize& size) {
  host::ConvexMeshToolShape shape = spatula(size);
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  for (auto& v : shape.vertices_tool_m) v = turn * v;
  std::printf("%-14s %-9s %9zu tris  ", (std::string("spatula-") + size.name).c_str(), "tilted", shape.triangles.size());
  std::fflush(stdout);
  // The tool check's tolerance: 1e-5 of the spatula's ~65 mm diagonal (tool_mesh_io.cpp).
  const double check_s = seconds_of([&] { host::check_convex(shape.vertices_tool_m, shape.triangles, 1e-5 * 0.065); });
  const double nodes_s = seconds_of([&] { (void)host::ToolNodes::from_convex_mesh(shape); });
  std::printf("convexity check %8.3f s  nodes %8.3f s\n", check_s, nodes_s);
  return nlohmann::json{{"mesh", std::string("spatula-") + size.name + "-tilted"}, {"triangles", shape.triangles.size()},
                        {"check_s", check_s}, {"nodes_s", nodes_s}};
}

nlohmann::json soft_row(int subdivisions, const fs::path& dir) {
  const host::SurfaceMesh blob = host::make_organ_blob(subdivisions);
  const fs::path path = dir / ("organ-blob-" + std::to_string(subdivisions) + ".obj");
  host::write_tool_mesh_obj(host::ToolMesh{blob.vertices_m, blob.triangles}, path.string(), "bench soft mesh");
  std::printf("organ-blob     %-9s %9zu tris  ", "obj", blob.triangles.size());
  std::fflush(stdout);
  host::SurfaceMesh loaded;
  const double read_s = seconds_of([&] { loaded = host::read_soft_body_mesh(path.string()); });
  host::SoftBodyDescription description;
  host::SoftMesh shape;
  shape.vertices_world_m = loaded.vertices_m;
  shape.triangles = loaded.triangles;
  description.shape = shape;
  description.shape_matching_ratio = 0.05;  // the shipped scenes' pose matching: setPose runs too
  int links = 0;
  const double build_s = seconds_of([&] {
    btSoftBodyWorldInfo info;
    const std::unique_ptr<btSoftBody> body(host::build_soft_body(info, description));
    links = body->m_links.size();
  });
  std::printf("read %8.3f s  build %8.3f s  (%d links)\n", read_s, build_s, links);
  nlohmann::json row{{"mesh", "organ-blob"}, {"format", "obj"},   {"triangles", blob.triangles.size()}, {"vertices", blob.vertices_m.size()},
                     {"read_s", read_s},     {"build_s", build_s}, {"links", links}};
  fs::remove(path);
  return row;
}

// A box of n³ cubes (1 mm each), each split into the 6 Kuhn tetrahedra along its (0,0,0)–(1,1,1)
// diagonal: conforming, all positive (the permutations of even parity keep the order, the odd
// ones swap the last two corners).
host::TetMesh kuhn_box(int n) {
  host::TetMesh m;
  const auto id = [&](int i, int j, int k) { return (i * (n + 1) + j) * (n + 1) + k; };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) m.vertices_m.push_back({1e-3 * i, 1e-3 * j, 1e-3 * k});
  constexpr int kPermutations[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {1, 0, 2}, {2, 1, 0}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (int p = 0; p < 6; ++p) {
          std::array<int, 3> at{i, j, k};
          std::array<int, 4> t{id(i, j, k), 0, 0, 0};
          for (int s = 0; s < 3; ++s) {
            ++at[static_cast<std::size_t>(kPermutations[p][s])];
            t[static_cast<std::size_t>(s) + 1] = id(at[0], at[1], at[2]);
          }
          if (p >= 3) std::swap(t[2], t[3]);
          m.tetrahedra.push_back(t);
        }
  return m;
}

void write_tet_file(const host::TetMesh& m, const fs::path& path, const std::string& format) {
  std::ofstream out(path);
  out.precision(9);
  const std::size_t n = m.vertices_m.size();
  if (format == "msh") {
    out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 " << n << " 1 " << n << "\n3 1 0 " << n << "\n";
    for (std::size_t i = 0; i < n; ++i) out << i + 1 << '\n';
    for (const Vec3& v : m.vertices_m) out << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    out << "$EndNodes\n$Elements\n1 " << m.tetrahedra.size() << " 1 " << m.tetrahedra.size() << "\n3 1 4 " << m.tetrahedra.size() << '\n';
    for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) {
      out << t + 1;
      for (const int c : m.tetrahedra[t]) out << ' ' << c + 1;
      out << '\n';
    }
    out << "$EndElements\n";
  } else if (format == "vtk") {
    out << "# vtk DataFile Version 3.0\nbench box\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " << n << " double\n";
    for (const Vec3& v : m.vertices_m) out << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    out << "CELLS " << m.tetrahedra.size() << ' ' << 5 * m.tetrahedra.size() << '\n';
    for (const auto& t : m.tetrahedra) out << "4 " << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
    out << "CELL_TYPES " << m.tetrahedra.size() << '\n';
    for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) out << "10\n";
  } else {
    out << n << " 3 0 0\n";
    for (std::size_t i = 0; i < n; ++i) out << i + 1 << ' ' << m.vertices_m[i][0] << ' ' << m.vertices_m[i][1] << ' ' << m.vertices_m[i][2] << '\n';
    std::ofstream ele(fs::path(path).replace_extension(".ele"));
    ele << m.tetrahedra.size() << " 4 0\n";
    for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) ele << t + 1 << ' ' << m.tetrahedra[t][0] + 1 << ' ' << m.tetrahedra[t][1] + 1 << ' ' << m.tetrahedra[t][2] + 1 << ' ' << m.tetrahedra[t][3] + 1 << '\n';
  }
}

nlohmann::json tet_row(int cells, const std::string& format, bool build, const fs::path& dir) {
  const host::TetMesh box = kuhn_box(cells);
  const fs::path path = dir / ("box-" + std::to_string(cells) + "." + (format == "tetgen" ? std::string("node") : format));
  write_tet_file(box, path, format);
  std::uintmax_t bytes = fs::file_size(path);
  if (format == "tetgen") bytes += fs::file_size(fs::path(path).replace_extension(".ele"));
  std::printf("box-%-3d        %-9s %9zu tets  ", cells, format.c_str(), box.tetrahedra.size());
  std::fflush(stdout);
  host::VolumeMesh loaded;
  const double read_s = seconds_of([&] { loaded = host::read_soft_body_tet_mesh(path.string()); });
  std::printf("read %8.3f s", read_s);
  nlohmann::json row{{"mesh", "box-" + std::to_string(cells)}, {"format", format},  {"tetrahedra", box.tetrahedra.size()},
                     {"vertices", box.vertices_m.size()},        {"file_bytes", bytes}, {"read_s", read_s},
                     {"boundary_triangles", loaded.boundary_triangles.size()}};
  if (build) {
    int links = 0;
    btSoftBodyWorldInfo info;
    std::unique_ptr<btSoftBody> body;
    const double build_s = seconds_of([&] { body.reset(host::create_from_tet_mesh(info, loaded, 1000.0)); });
    links = body->m_links.size();
    const double free_s = seconds_of([&] { body.reset(); });
    std::printf("  build %8.3f s  (free %6.3f s; %d links, %zu boundary triangles)", build_s, free_s, links, loaded.boundary_triangles.size());
    row["build_s"] = build_s;
    row["free_s"] = free_s;
    row["links"] = links;
  }
  std::printf("\n");
  fs::remove(path);
  if (format == "tetgen") fs::remove(fs::path(path).replace_extension(".ele"));
  return row;
}

}  // namespace

nlohmann::json run_bench_mesh(const BenchMeshOptions& options) {
  const fs::path dir = fs::temp_directory_path() / ("fissure-bench-mesh-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  nlohmann::json out;
  out["machine"] = sim_machine_info();
  out["quick"] = options.quick;
  nlohmann::json rows = nlohmann::json::array();
  std::printf("convex tool meshes (rounded spatula), load stages:\n");
  for (const SpatulaSize& size : kSizes) {
    if (options.quick && std::string(size.name) == "362k") continue;
    rows.push_back(tool_row(size, dir));
  }
  out["tool_meshes"] = rows;
  nlohmann::json stl = nlohmann::json::array();
  for (const SpatulaSize& size : kSizes) {
    if (std::string(size.name) == "1k" || (options.quick && std::string(size.name) == "362k")) continue;
    stl.push_back(stl_row(size, dir, true));
    stl.push_back(stl_row(size, dir, false));
  }
  out["tool_meshes_stl"] = stl;
  nlohmann::json tilted = nlohmann::json::array();
  for (const SpatulaSize& size : kSizes) {
    if (std::string(size.name) == "1k" || (options.quick && std::string(size.name) == "362k")) continue;
    tilted.push_back(tilted_row(size));
  }
  out["tool_meshes_tilted"] = tilted;
  std::printf("soft-body meshes (organ-like lobe):\n");
  nlohmann::json soft = nlohmann::json::array();
  for (const int subdivisions : {3, 5, 7}) {
    if (options.quick && subdivisions == 7) continue;
    soft.push_back(soft_row(subdivisions, dir));
  }
  out["soft_meshes"] = soft;
  std::printf("tetrahedral meshes (box of n³ Kuhn cells):\n");
  nlohmann::json tets = nlohmann::json::array();
  for (const int cells : {10, 20, 40}) {
    if (options.quick && cells == 40) continue;
    for (const char* format : {"msh", "vtk", "tetgen"}) tets.push_back(tet_row(cells, format, std::string(format) == "msh", dir));
  }
  out["tet_meshes"] = tets;
  fs::remove_all(dir);
  return out;
}

}  // namespace fissure::eval
