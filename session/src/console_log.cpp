#include "fissure/session/console_log.hpp"

#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <ctime>

namespace fissure::session {
namespace {

void log_line(const char* level, const char* format, std::va_list args) noexcept {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm local{};
  localtime_r(&seconds, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", &local);
  char text[1024];
  std::vsnprintf(text, sizeof text, format, args);
  std::fprintf(stderr, "[%s.%03lld] [%s] %s\n", stamp, static_cast<long long>(millis), level, text);
}

}  // namespace

void log_info(const char* format, ...) noexcept {
  std::va_list args;
  va_start(args, format);
  log_line("info", format, args);
  va_end(args);
}

void log_warn(const char* format, ...) noexcept {
  std::va_list args;
  va_start(args, format);
  log_line("warning", format, args);
  va_end(args);
}

}  // namespace fissure::session
