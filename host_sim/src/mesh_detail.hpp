#pragma once
// Small helpers the surface- and tetrahedral-mesh readers and checks share (host_sim internal).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

namespace fissure::host::mesh_detail {

// A path's extension in lower case, with its dot ("" for none): formats are told apart by it.
inline std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Union-find root with path halving (connected parts of a mesh).
inline int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace fissure::host::mesh_detail
