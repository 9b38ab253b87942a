#pragma once
// A whole file as a string, for tests that check what a session wrote.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fissure::session::test {

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace fissure::session::test
