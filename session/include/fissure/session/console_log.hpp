#pragma once
// One-line progress and warning messages on stderr for the session's set-up and supervision
// threads (never the rt thread): "[HH:MM:SS.mmm] [info] text", the layout of the host
// program's spdlog lines, without a logging library, so that the RT box's build needs none.
namespace fissure::session {

[[gnu::format(printf, 1, 2)]] void log_info(const char* format, ...) noexcept;
[[gnu::format(printf, 1, 2)]] void log_warn(const char* format, ...) noexcept;

}  // namespace fissure::session
