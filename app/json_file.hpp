#pragma once
// The --json FILE every benchmark command writes: the result indented, one trailing newline.
#include <string>

#include <nlohmann/json.hpp>

namespace fissure::app {

/// Throws CommandError naming `path` when it cannot be opened or written.
void write_json_file(const std::string& path, const nlohmann::json& json);

}  // namespace fissure::app
