#include "json_file.hpp"

#include <fstream>

#include "commands.hpp"

namespace fissure::app {

void write_json_file(const std::string& path, const nlohmann::json& json) {
  std::ofstream file(path);
  if (!file) throw CommandError("cannot write '" + path + "'");
  file << json.dump(2) << '\n';
  if (!file) throw CommandError("failed writing '" + path + "'");
}

}  // namespace fissure::app
