// Gmsh / VTK / TetGen tetrahedral mesh files (tet_mesh_file.hpp). Hand-written readers: the
// Debian packages that read these formats are a whole application's library (libgmsh: one
// global model per process; VTK: hundreds of MB of headers) and none reads all three; each
// format here is a few whitespace-separated sections, read token by token with their lines.
#include "fissure/host_sim/tet_mesh_file.hpp"
#include "mesh_detail.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace fissure::host {
namespace {

std::string quoted(const std::string& path) { return "'" + path + "'"; }

std::string number_text(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

/// Whitespace-separated tokens of a text file with the line each starts on; TetGen's '#'
/// comments run to the end of the line.
class Cursor {
 public:
  Cursor(std::string path, std::string text, bool hash_comments) : path_(std::move(path)), text_(std::move(text)), hash_(hash_comments) {}

  const std::string& path() const { return path_; }
  int line() const { return token_line_; }

  /// The next token, false at the end of the text.
  bool next(std::string_view& token) {
    skip_space(true);
    if (pos_ >= text_.size()) {
      token_line_ = line_;
      return false;
    }
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_])) == 0 && !(hash_ && text_[pos_] == '#')) ++pos_;
    token = std::string_view(text_).substr(begin, pos_ - begin);
    token_line_ = line_;
    return true;
  }

  /// The rest of the current line (after the last token), without its end; moves past it.
  std::string_view rest_of_line() {
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    std::string_view rest = std::string_view(text_).substr(begin, pos_ - begin);
    if (!rest.empty() && rest.back() == '\r') rest.remove_suffix(1);
    return rest;
  }

  [[noreturn]] void fail(const std::string& reason) const { throw MeshError(quoted(path_) + " line " + std::to_string(token_line_) + ": " + reason); }

  /// The next token; at the end of the file, an error saying what was expected.
  std::string_view expect(const std::string& what) {
    std::string_view token;
    if (!next(token)) fail("the file ends where " + what + " is expected");
    return token;
  }

  /// `token` as an integer in [lo, hi]; `what` names it in the error.
  long long parse_integer(std::string_view token, const std::string& what, long long lo, long long hi) const {
    long long value = 0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size()) fail(what + " is '" + std::string(token) + "', not an integer");
    if (value < lo || value > hi) {
      fail(what + " is " + std::to_string(value) + ", expected " + std::to_string(lo) + (hi == LLONG_MAX ? " or more" : " .. " + std::to_string(hi)));
    }
    return value;
  }

  long long integer(const std::string& what, long long lo, long long hi) { return parse_integer(expect(what), what, lo, hi); }

  /// The next whole line, for line-structured headers (VTK's first three lines), trimmed.
  std::string_view next_whole_line() {
    if (pos_ < text_.size() && text_[pos_] == '\n') {
      ++pos_;
      ++line_;
    }
    token_line_ = line_;
    std::string_view line = rest_of_line();
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.front())) != 0) line.remove_prefix(1);
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back())) != 0) line.remove_suffix(1);
    return line;
  }

  double coordinate(const std::string& what) {
    const std::string token(expect(what));
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size() || !std::isfinite(value)) fail(what + " is '" + token + "', not a finite number");
    return value;
  }

  /// Expects the keyword `word` (a section end, a VTK keyword); `after` says what came before.
  void keyword(const std::string& word, const std::string& after) {
    const std::string_view token = expect("'" + word + "' " + after);
    if (token != word) fail("expected '" + word + "' " + after + ", got '" + std::string(token) + "'");
  }

 private:
  void skip_space(bool newlines) {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        if (!newlines) return;
        ++line_;
        ++pos_;
      } else if (std::isspace(static_cast<unsigned char>(c)) != 0) {
        ++pos_;
      } else if (hash_ && c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else {
        return;
      }
    }
  }

  std::string path_;
  std::string text_;
  bool hash_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int token_line_ = 1;
};

std::string read_text(const std::string& path, const std::string& what) {
  std::error_code code;
  if (std::filesystem::is_directory(path, code)) throw MeshError(quoted(path) + " is a directory, not " + what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshError("cannot open " + quoted(path));
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string too_many(std::size_t count, std::size_t limit) {
  return "too large: " + std::to_string(count) + " tetrahedra, the limit is " + std::to_string(limit);
}

/// What the readers collect besides the TetMesh: each vertex's and element's number in the
/// file (for messages), and the file that holds the elements (TetGen: the .ele).
struct FileIds {
  std::vector<long long> vertex_ids;
  std::vector<long long> element_ids;
  std::string element_file;
  std::string element_word;  ///< "element", "cell", "tetrahedron"
  std::string vertex_word;   ///< "node", "point"
};

/// Orientation and degeneracy (tet_mesh_file.hpp): turns inverted elements round, refuses flat ones.
void orient(TetMesh& mesh, const FileIds& ids) {
  Vec3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const Vec3& v : mesh.vertices_m) {
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
  }
  const double diagonal_m = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
  const double limit6_m3 = kDegenerateVolumeRelative * diagonal_m * diagonal_m * diagonal_m;
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    auto& corners = mesh.tetrahedra[t];
    const Vec3& a = mesh.vertices_m[static_cast<std::size_t>(corners[0])];
    const Vec3& b = mesh.vertices_m[static_cast<std::size_t>(corners[1])];
    const Vec3& c = mesh.vertices_m[static_cast<std::size_t>(corners[2])];
    const Vec3& d = mesh.vertices_m[static_cast<std::size_t>(corners[3])];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    const double volume6 = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
    if (!(std::abs(volume6) > limit6_m3)) {
      std::string nodes;
      for (const int i : corners) nodes += (nodes.empty() ? "" : ", ") + std::to_string(ids.vertex_ids[static_cast<std::size_t>(i)]);
      throw MeshError(quoted(ids.element_file) + " line " + std::to_string(mesh.tetrahedron_lines[t]) + ": " + ids.element_word + " " +
                      std::to_string(ids.element_ids[t]) + " is degenerate: volume " + number_text(volume6 / 6.0) + " m³ (" + ids.vertex_word + "s " +
                      nodes + "), a tetrahedron needs more than " + number_text(limit6_m3 / 6.0) + " m³ (1e-12 of the mesh diagonal cubed, /6)");
    }
    if (volume6 < 0.0) {
      std::swap(corners[2], corners[3]);
      ++mesh.reordered_count;
    }
  }
}

// ---- Gmsh .msh 4.1 ASCII --------------------------------------------------------------------

constexpr int kGmshTetrahedron = 4;  // Gmsh element type: 4-node tetrahedron

TetMesh read_gmsh(const std::string& path, std::size_t max_tetrahedra) {
  Cursor in(path, read_text(path, "a Gmsh mesh"), false);
  TetMesh mesh;
  mesh.source = path;
  FileIds ids{{}, {}, path, "element", "node"};
  std::unordered_map<long long, int> index_of_tag;
  bool format_seen = false, nodes_seen = false, elements_seen = false;
  long long elements_total = 0;
  std::string_view token;
  while (in.next(token)) {
    if (token.empty() || token[0] != '$') in.fail("expected a section ($MeshFormat, $Nodes, $Elements, …), got '" + std::string(token) + "'");
    const std::string name(token.substr(1));
    if (name == "MeshFormat") {
      const std::string version(in.expect("the format version"));
      if (version != "4.1") {
        in.fail("Gmsh format version " + version + "; this reader reads 4.1 (save with: gmsh FILE.geo -3 -format msh41 -o FILE.msh)");
      }
      if (in.integer("the file type", 0, 1) == 1) in.fail("a binary .msh; save it as ASCII (gmsh option -bin 0, the default)");
      (void)in.expect("the data size");
      in.keyword("$EndMeshFormat", "after the format line");
      format_seen = true;
    } else if (name == "Nodes") {
      if (!format_seen) in.fail("$Nodes before $MeshFormat: not a Gmsh 4.1 file");
      const long long blocks = in.integer("$Nodes numEntityBlocks", 0, LLONG_MAX);
      const long long count = in.integer("$Nodes numNodes", 0, LLONG_MAX);
      (void)in.integer("$Nodes minNodeTag", 0, LLONG_MAX);
      (void)in.integer("$Nodes maxNodeTag", 0, LLONG_MAX);
      // A node is shared by several tetrahedra: more than 4 per allowed tetrahedron is no body we load.
      if (static_cast<unsigned long long>(count) > 4 * static_cast<unsigned long long>(max_tetrahedra)) {
        in.fail("too large: " + std::to_string(count) + " nodes, the limit is " + std::to_string(4 * max_tetrahedra) + " (4 per tetrahedron allowed)");
      }
      mesh.vertices_m.reserve(static_cast<std::size_t>(count));
      index_of_tag.reserve(static_cast<std::size_t>(count));
      std::vector<long long> tags;
      for (long long b = 0; b < blocks; ++b) {
        const long long dim = in.integer("node block " + std::to_string(b + 1) + " entityDim", 0, 3);
        (void)in.integer("node block entityTag", LLONG_MIN, LLONG_MAX);
        const long long parametric = in.integer("node block parametric flag", 0, 1);
        const long long left = count - static_cast<long long>(mesh.vertices_m.size());
        const long long n = in.integer("node block " + std::to_string(b + 1) + " numNodesInBlock", 0, LLONG_MAX);
        if (n > left) in.fail("node block " + std::to_string(b + 1) + " holds " + std::to_string(n) + " nodes, but only " + std::to_string(left) + " of the header's numNodes " + std::to_string(count) + " are left");
        tags.clear();
        for (long long i = 0; i < n; ++i) tags.push_back(in.integer("node tag", 1, LLONG_MAX));
        for (const long long tag : tags) {
          Vec3 p{};
          for (std::size_t axis = 0; axis < 3; ++axis) p[axis] = in.coordinate("node " + std::to_string(tag) + " coordinate " + "xyz"[axis]);
          for (long long k = 0; parametric == 1 && k < dim; ++k) (void)in.expect("node " + std::to_string(tag) + "'s parametric coordinate");
          const auto [it, added] = index_of_tag.try_emplace(tag, static_cast<int>(mesh.vertices_m.size()));
          if (!added) in.fail("node tag " + std::to_string(tag) + " appears twice (node tags are unique)");
          mesh.vertices_m.push_back(p);
          ids.vertex_ids.push_back(tag);
        }
      }
      if (static_cast<long long>(mesh.vertices_m.size()) != count) {
        (void)in.expect("$EndNodes");
        in.fail("the $Nodes header announces " + std::to_string(count) + " nodes, its blocks hold " + std::to_string(mesh.vertices_m.size()));
      }
      in.keyword("$EndNodes", "after the " + std::to_string(count) + " nodes the $Nodes header announces");
      nodes_seen = true;
    } else if (name == "Elements") {
      if (!nodes_seen) in.fail("$Elements before $Nodes: its node tags cannot be resolved");
      const long long blocks = in.integer("$Elements numEntityBlocks", 0, LLONG_MAX);
      elements_total = in.integer("$Elements numElements", 0, LLONG_MAX);
      (void)in.integer("$Elements minElementTag", 0, LLONG_MAX);
      (void)in.integer("$Elements maxElementTag", 0, LLONG_MAX);
      long long seen = 0;
      for (long long b = 0; b < blocks; ++b) {
        (void)in.integer("element block " + std::to_string(b + 1) + " entityDim", 0, 3);
        (void)in.integer("element block entityTag", LLONG_MIN, LLONG_MAX);
        const long long type = in.integer("element block " + std::to_string(b + 1) + " elementType", 1, 1000);
        const long long n = in.integer("element block " + std::to_string(b + 1) + " numElementsInBlock", 0, LLONG_MAX);
        if (n > elements_total - seen) {
          in.fail("element block " + std::to_string(b + 1) + " holds " + std::to_string(n) + " elements, but only " + std::to_string(elements_total - seen) + " of the header's numElements " + std::to_string(elements_total) + " are left");
        }
        seen += n;
        if (type != kGmshTetrahedron) {
          for (long long i = 0; i < n; ++i) {
            (void)in.integer("element tag", 1, LLONG_MAX);
            (void)in.rest_of_line();
          }
          continue;
        }
        if (mesh.tetrahedra.size() + static_cast<std::size_t>(n) > max_tetrahedra) in.fail(too_many(mesh.tetrahedra.size() + static_cast<std::size_t>(n), max_tetrahedra));
        for (long long i = 0; i < n; ++i) {
          const long long tag = in.integer("element tag", 1, LLONG_MAX);
          const int line = in.line();
          std::array<int, 4> corners{};
          for (std::size_t k = 0; k < 4; ++k) {
            const long long node = in.integer("element " + std::to_string(tag) + " node tag", 1, LLONG_MAX);
            const auto it = index_of_tag.find(node);
            if (it == index_of_tag.end()) {
              in.fail("element " + std::to_string(tag) + " corner " + std::to_string(k + 1) + " is node " + std::to_string(node) + ", which $Nodes does not hold (it holds " + std::to_string(mesh.vertices_m.size()) + " nodes)");
            }
            corners[k] = it->second;
          }
          const std::string_view rest = in.rest_of_line();
          if (rest.find_first_not_of(" \t") != std::string_view::npos) in.fail("element " + std::to_string(tag) + " has more than the 4 node tags of a 4-node tetrahedron (type 4)");
          mesh.tetrahedra.push_back(corners);
          mesh.tetrahedron_lines.push_back(line);
          ids.element_ids.push_back(tag);
        }
      }
      if (seen != elements_total) {
        (void)in.expect("$EndElements");
        in.fail("the $Elements header announces " + std::to_string(elements_total) + " elements, its blocks hold " + std::to_string(seen));
      }
      in.keyword("$EndElements", "after the " + std::to_string(elements_total) + " elements the $Elements header announces");
      elements_seen = true;
    } else {
      const std::string end = "$End" + name;
      const int start = in.line();
      do {
        if (!in.next(token)) in.fail("section $" + name + " (line " + std::to_string(start) + ") is not closed by " + end);
      } while (token != end);
    }
  }
  for (const auto& [seen, section] : {std::pair{format_seen, "$MeshFormat"}, std::pair{nodes_seen, "$Nodes"}, std::pair{elements_seen, "$Elements"}}) {
    if (!seen) throw MeshError(quoted(path) + ": no " + section + " section (a Gmsh mesh has $MeshFormat, $Nodes and $Elements)");
  }
  if (mesh.tetrahedra.empty()) {
    throw MeshError(quoted(path) + ": no 4-node tetrahedron (element type 4) among its " + std::to_string(elements_total) +
                    " elements: a surface mesh or second-order elements; mesh the volume with first-order elements (gmsh -3 -order 1)");
  }
  orient(mesh, ids);
  return mesh;
}

// ---- VTK legacy unstructured grid ------------------------------------------------------------

constexpr long long kVtkTetra = 10;  // VTK cell type: VTK_TETRA

TetMesh read_vtk(const std::string& path, std::size_t max_tetrahedra) {
  Cursor in(path, read_text(path, "a VTK file"), false);
  TetMesh mesh;
  mesh.source = path;
  FileIds ids{{}, {}, path, "cell", "point"};
  // Header: "# vtk DataFile Version x.y", a free title line, ASCII | BINARY.
  if (in.next_whole_line().rfind("# vtk DataFile Version", 0) != 0) in.fail("not a VTK legacy file: line 1 must be '# vtk DataFile Version x.y'");
  (void)in.next_whole_line();
  const std::string encoding(in.next_whole_line());
  if (encoding == "BINARY") in.fail("a BINARY VTK file; save it as ASCII (meshio: binary=False; ParaView: File type ASCII)");
  if (encoding != "ASCII") in.fail("expected ASCII or BINARY, got '" + encoding + "'");
  std::string_view token;
  in.keyword("DATASET", "after ASCII");
  const std::string dataset(in.expect("the dataset type"));
  if (dataset != "UNSTRUCTURED_GRID") in.fail("DATASET " + dataset + ": tetrahedra come in an UNSTRUCTURED_GRID");
  bool points_seen = false, cells_seen = false, types_seen = false;
  std::vector<long long> offsets;       // cell c: connectivity[offsets[c] .. offsets[c + 1])
  std::vector<long long> connectivity;
  std::vector<int> cell_lines;
  while (!types_seen && in.next(token)) {
    if (token == "POINTS") {
      const long long n = in.integer("the POINTS count", 0, LLONG_MAX);
      (void)in.expect("the POINTS data type");
      if (static_cast<unsigned long long>(n) > 4 * static_cast<unsigned long long>(max_tetrahedra)) {
        in.fail("too large: " + std::to_string(n) + " points, the limit is " + std::to_string(4 * max_tetrahedra) + " (4 per tetrahedron allowed)");
      }
      mesh.vertices_m.reserve(static_cast<std::size_t>(n));
      for (long long i = 0; i < n; ++i) {
        Vec3 p{};
        for (std::size_t axis = 0; axis < 3; ++axis) p[axis] = in.coordinate("point " + std::to_string(i) + " coordinate " + "xyz"[axis]);
        mesh.vertices_m.push_back(p);
        ids.vertex_ids.push_back(i);
      }
      points_seen = true;
    } else if (token == "CELLS") {
      if (!points_seen) in.fail("CELLS before POINTS");
      const long long first_count = in.integer("the CELLS count", 1, LLONG_MAX);
      const long long second_count = in.integer("the CELLS size", 0, LLONG_MAX);
      if (static_cast<unsigned long long>(first_count) > 8 * static_cast<unsigned long long>(max_tetrahedra)) {
        in.fail("too large: " + std::to_string(first_count) + " cells, the limit is " + std::to_string(max_tetrahedra) + " tetrahedra (and 8 cells per tetrahedron)");
      }
      token = in.expect("the cells");
      if (token == "OFFSETS") {
        // Version 5.x: OFFSETS type, first_count offsets; CONNECTIVITY type, second_count indices.
        (void)in.expect("the OFFSETS data type");
        for (long long i = 0; i < first_count; ++i) {
          offsets.push_back(in.integer("offset " + std::to_string(i), i == 0 ? 0 : offsets.back(), second_count));
        }
        if (offsets.empty() || offsets.front() != 0 || offsets.back() != second_count) {
          in.fail("the OFFSETS run from " + std::to_string(offsets.empty() ? 0 : offsets.front()) + " to " +
                  std::to_string(offsets.empty() ? 0 : offsets.back()) + ", expected 0 to the CONNECTIVITY size " + std::to_string(second_count));
        }
        in.keyword("CONNECTIVITY", "after the offsets");
        (void)in.expect("the CONNECTIVITY data type");
        cell_lines.assign(offsets.size() - 1, 0);
        std::size_t cell = 0;
        for (long long i = 0; i < second_count; ++i) {
          while (cell + 1 < offsets.size() && offsets[cell + 1] <= i) ++cell;
          connectivity.push_back(in.integer("cell " + std::to_string(cell) + " point index", LLONG_MIN, LLONG_MAX));
          if (cell < cell_lines.size() && cell_lines[cell] == 0) cell_lines[cell] = in.line();
        }
      } else {
        // Versions up to 4.2: per cell its point count, then its point indices; the size is the
        // count of all these numbers.
        offsets.push_back(0);
        for (long long c = 0; c < first_count; ++c) {
          const std::string what = "cell " + std::to_string(c) + "'s point count";
          const long long count = c == 0 ? in.parse_integer(token, what, 1, LLONG_MAX) : in.integer(what, 1, LLONG_MAX);
          cell_lines.push_back(in.line());
          const long long used = static_cast<long long>(connectivity.size() + offsets.size());  // counts so far + this one
          if (used + count > second_count) {
            in.fail("cell " + std::to_string(c) + " goes past the CELLS size " + std::to_string(second_count) + " (the count of all numbers in the cell list)");
          }
          for (long long i = 0; i < count; ++i) connectivity.push_back(in.integer("cell " + std::to_string(c) + " point index", LLONG_MIN, LLONG_MAX));
          offsets.push_back(static_cast<long long>(connectivity.size()));
        }
        const long long used = static_cast<long long>(connectivity.size() + offsets.size()) - 1;
        if (used != second_count) in.fail("the CELLS size is " + std::to_string(second_count) + ", the cells hold " + std::to_string(used) + " numbers");
      }
      cells_seen = true;
    } else if (token == "CELL_TYPES") {
      if (!cells_seen) in.fail("CELL_TYPES before CELLS");
      const long long cells = static_cast<long long>(offsets.size()) - 1;
      in.integer("the CELL_TYPES count", cells, cells);
      for (long long c = 0; c < cells; ++c) {
        const long long type = in.integer("cell " + std::to_string(c) + "'s type", 0, LLONG_MAX);
        if (type != kVtkTetra) continue;
        const long long begin = offsets[static_cast<std::size_t>(c)], end = offsets[static_cast<std::size_t>(c) + 1];
        const int line = cell_lines[static_cast<std::size_t>(c)];
        const auto at_cell = [&](const std::string& reason) { throw MeshError(quoted(path) + " line " + std::to_string(line) + ": cell " + std::to_string(c) + " " + reason); };
        if (end - begin != 4) at_cell("is a tetrahedron (type 10) with " + std::to_string(end - begin) + " points, not 4");
        std::array<int, 4> corners{};
        for (std::size_t k = 0; k < 4; ++k) {
          const long long p = connectivity[static_cast<std::size_t>(begin) + k];
          if (p < 0 || p >= static_cast<long long>(mesh.vertices_m.size())) {
            at_cell("corner " + std::to_string(k + 1) + " is point " + std::to_string(p) + ", the file has points 0 .. " + std::to_string(static_cast<long long>(mesh.vertices_m.size()) - 1));
          }
          corners[k] = static_cast<int>(p);
        }
        if (mesh.tetrahedra.size() == max_tetrahedra) in.fail(too_many(max_tetrahedra + 1, max_tetrahedra) + " (or more)");
        mesh.tetrahedra.push_back(corners);
        mesh.tetrahedron_lines.push_back(line);
        ids.element_ids.push_back(c);
      }
      types_seen = true;
    } else if (token == "METADATA" || token == "FIELD") {
      in.fail("'" + std::string(token) + "' before CELL_TYPES: this reader reads POINTS, CELLS and CELL_TYPES first");
    } else {
      in.fail("expected POINTS, CELLS or CELL_TYPES, got '" + std::string(token) + "'");
    }
  }
  // What follows CELL_TYPES (POINT_DATA, CELL_DATA) is data on the mesh, not its shape.
  for (const auto& [seen, section] : {std::pair{points_seen, "POINTS"}, std::pair{cells_seen, "CELLS"}, std::pair{types_seen, "CELL_TYPES"}}) {
    if (!seen) throw MeshError(quoted(path) + ": no " + section + " section (an unstructured grid has POINTS, CELLS and CELL_TYPES)");
  }
  if (mesh.tetrahedra.empty()) throw MeshError(quoted(path) + ": no tetrahedron (cell type 10) among its " + std::to_string(offsets.size() - 1) + " cells");
  orient(mesh, ids);
  return mesh;
}

// ---- TetGen .node / .ele ---------------------------------------------------------------------

TetMesh read_tetgen(const std::string& path, std::size_t max_tetrahedra) {
  const std::filesystem::path base = std::filesystem::path(path).replace_extension();
  const std::string node_path = base.string() + ".node";
  const std::string ele_path = base.string() + ".ele";
  for (const std::string& p : {node_path, ele_path}) {
    std::error_code code;
    if (!std::filesystem::exists(p, code)) {
      throw MeshError("cannot open " + quoted(p) + " (a TetGen mesh is the pair " + quoted(node_path) + " and " + quoted(ele_path) + ")");
    }
  }
  TetMesh mesh;
  mesh.source = path;
  FileIds ids{{}, {}, ele_path, "tetrahedron", "point"};
  long long first_number = 0;
  {
    Cursor in(node_path, read_text(node_path, "a TetGen .node file"), true);
    const long long n = in.integer("the point count", 1, 4 * static_cast<long long>(max_tetrahedra));
    const long long dimension = in.integer("the dimension", 2, 3);
    if (dimension != 3) in.fail("the dimension is 2; a tetrahedral mesh's .node is 3-dimensional");
    const long long attributes = in.integer("the attribute count", 0, 1000);
    const long long markers = in.integer("the boundary marker flag", 0, 1);
    mesh.vertices_m.reserve(static_cast<std::size_t>(n));
    for (long long i = 0; i < n; ++i) {
      const long long number = in.integer("point number", i == 0 ? 0 : first_number + i, i == 0 ? 1 : first_number + i);
      if (i == 0) first_number = number;
      Vec3 p{};
      for (std::size_t axis = 0; axis < 3; ++axis) p[axis] = in.coordinate("point " + std::to_string(number) + " coordinate " + "xyz"[axis]);
      for (long long k = 0; k < attributes + markers; ++k) (void)in.expect("point " + std::to_string(number) + "'s attributes and boundary marker");
      mesh.vertices_m.push_back(p);
      ids.vertex_ids.push_back(number);
    }
    std::string_view extra;
    if (in.next(extra)) in.fail("'" + std::string(extra) + "' after the " + std::to_string(n) + " points the header announces");
  }
  {
    Cursor in(ele_path, read_text(ele_path, "a TetGen .ele file"), true);
    const long long m = in.integer("the tetrahedron count", 1, LLONG_MAX);
    if (static_cast<unsigned long long>(m) > max_tetrahedra) in.fail(too_many(static_cast<std::size_t>(m), max_tetrahedra));
    const long long per = in.integer("the nodes per tetrahedron", 4, 10);
    if (per != 4 && per != 10) in.fail("the nodes per tetrahedron is " + std::to_string(per) + ", expected 4 or 10");
    const long long attributes = in.integer("the region attribute count", 0, 1000);
    const long long last = first_number + static_cast<long long>(mesh.vertices_m.size()) - 1;
    mesh.tetrahedra.reserve(static_cast<std::size_t>(m));
    for (long long j = 0; j < m; ++j) {
      const long long number = in.integer("tetrahedron number", LLONG_MIN, LLONG_MAX);
      const int line = in.line();
      std::array<int, 4> corners{};
      for (long long k = 0; k < per; ++k) {
        const long long point = in.integer("tetrahedron " + std::to_string(number) + " node", LLONG_MIN, LLONG_MAX);
        if (point < first_number || point > last) {
          in.fail("tetrahedron " + std::to_string(number) + " node " + std::to_string(k + 1) + " is point " + std::to_string(point) + ", the .node file has points " + std::to_string(first_number) + " .. " + std::to_string(last));
        }
        if (k < 4) corners[static_cast<std::size_t>(k)] = static_cast<int>(point - first_number);  // a 10-node element's corners come first
      }
      for (long long k = 0; k < attributes; ++k) (void)in.expect("tetrahedron " + std::to_string(number) + "'s region attribute");
      mesh.tetrahedra.push_back(corners);
      mesh.tetrahedron_lines.push_back(line);
      ids.element_ids.push_back(number);
    }
    std::string_view extra;
    if (in.next(extra)) in.fail("'" + std::string(extra) + "' after the " + std::to_string(m) + " tetrahedra the header announces");
  }
  orient(mesh, ids);
  return mesh;
}

using mesh_detail::lower_extension;

}  // namespace

bool is_tet_mesh_path(const std::string& path) {
  const std::string ext = lower_extension(path);
  return ext == ".msh" || ext == ".vtk" || ext == ".node" || ext == ".ele";
}

TetMesh read_tet_mesh_file(const std::string& path, std::size_t max_tetrahedra) {
  const std::string ext = lower_extension(path);
  if (ext == ".msh") return read_gmsh(path, max_tetrahedra);
  if (ext == ".vtk") return read_vtk(path, max_tetrahedra);
  if (ext == ".node" || ext == ".ele") return read_tetgen(path, max_tetrahedra);
  throw MeshError(quoted(path) + ": unknown tetrahedral mesh format '" + ext + "' (expected .msh, .vtk, or a TetGen .node / .ele)");
}

std::string tetrahedron_name(const TetMesh& mesh, int tetrahedron) {
  std::string name = "tetrahedron " + std::to_string(tetrahedron + 1);
  if (static_cast<std::size_t>(tetrahedron) < mesh.tetrahedron_lines.size()) {
    name += " (line " + std::to_string(mesh.tetrahedron_lines[static_cast<std::size_t>(tetrahedron)]) + ")";
  }
  return name;
}

}  // namespace fissure::host
