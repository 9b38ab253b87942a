#include "fissure/session/output_staging.hpp"

#include <unistd.h>

#include <set>

#include "fissure/session/session_error.hpp"

namespace fissure::session {
namespace fs = std::filesystem;
namespace {

void create_parent(const fs::path& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec)) {
    throw SessionError("cannot create the output directory '" + dir.string() + "'" + (ec ? ": " + ec.message() : ""));
  }
}

void move_into_place(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) throw SessionError("cannot move the finished '" + from.string() + "' to '" + to.string() + "': " + ec.message());
}

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

fs::path OutputStaging::temporary_name(const fs::path& final_path) {
  const std::string hidden = "." + final_path.stem().string() + ".incomplete-" + std::to_string(::getpid()) + final_path.extension().string();
  return final_path.parent_path() / hidden;
}

fs::path OutputStaging::file(const fs::path& final_path) {
  create_parent(final_path.parent_path());
  Staged s;
  s.temporary = temporary_name(final_path);
  s.final_path = final_path;
  staged_.push_back(s);
  return s.temporary;
}

fs::path OutputStaging::directory(const fs::path& final_dir, std::string stale_prefix, std::string stale_suffix) {
  Staged s;
  s.temporary = final_dir / (".incomplete-" + std::to_string(::getpid()));
  s.final_path = final_dir;
  s.is_directory = true;
  s.stale_prefix = std::move(stale_prefix);
  s.stale_suffix = std::move(stale_suffix);
  create_parent(s.temporary);
  staged_.push_back(s);
  return staged_.back().temporary;
}

void OutputStaging::commit() {
  for (const Staged& s : staged_) {
    std::error_code ec;
    if (!s.is_directory) {
      if (fs::exists(s.temporary, ec)) move_into_place(s.temporary, s.final_path);
      continue;
    }
    std::set<std::string> written;
    for (const fs::directory_entry& entry : fs::directory_iterator(s.temporary, ec)) {
      const std::string name = entry.path().filename().string();
      move_into_place(entry.path(), s.final_path / name);
      written.insert(name);
    }
    for (const fs::directory_entry& entry : fs::directory_iterator(s.final_path, ec)) {
      const std::string name = entry.path().filename().string();
      if (!entry.is_regular_file(ec) || written.count(name) != 0) continue;
      if (name.rfind(s.stale_prefix, 0) == 0 && ends_with(name, s.stale_suffix)) fs::remove(entry.path(), ec);
    }
    fs::remove_all(s.temporary, ec);
  }
  staged_.clear();
}

OutputStaging::~OutputStaging() {
  for (const Staged& s : staged_) {
    std::error_code ec;
    fs::remove_all(s.temporary, ec);
  }
}

}  // namespace fissure::session
