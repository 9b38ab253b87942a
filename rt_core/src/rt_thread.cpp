#include "fissure/rt_core/rt_thread.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace fissure::rt {
namespace {

void append(char* buffer, std::size_t size, const char* text) noexcept {
  const std::size_t used = std::strlen(buffer);
  if (used + 1 >= size) return;
  std::snprintf(buffer + used, size - used, "%s%s", used > 0 ? "; " : "", text);
}

// Touches `bytes` of stack (at most kMaxStackPrefault_bytes) so the pages are mapped, and
// locked by mlockall, before the loop needs them. noinline + volatile so the compiler can
// neither skip the writes nor shrink the frame.
constexpr std::size_t kMaxStackPrefault_bytes = 1024 * 1024;
constexpr std::size_t kPage_bytes = 4096;

[[gnu::noinline]] unsigned char prefault_stack(std::size_t bytes) noexcept {
  volatile unsigned char frame[kMaxStackPrefault_bytes];
  const std::size_t n = bytes < kMaxStackPrefault_bytes ? bytes : kMaxStackPrefault_bytes;
  // The stack grows down: the top of the frame lies next to the caller, so touch the n
  // bytes below it, page by page.
  for (std::size_t i = 0; i < n; i += kPage_bytes) frame[kMaxStackPrefault_bytes - 1 - i] = 1;
  return frame[kMaxStackPrefault_bytes - 1];
}

}  // namespace

RtSetupReport RtThreadSetup::apply(const RtThreadConfig& config) noexcept {
  RtSetupReport report;
  char text[256];
  const bool enforce = config.policy == RtPolicy::kEnforce;

  if (config.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      report.memory_locked = true;
    } else {
      std::snprintf(text, sizeof text, "mlockall(MCL_CURRENT|MCL_FUTURE) failed: %s (raise RLIMIT_MEMLOCK or run as root)",
                    std::strerror(errno));
      append(report.message, sizeof report.message, text);
      if (enforce) return report;
    }
  }
  (void)prefault_stack(config.stack_prefault_bytes);
  report.stack_prefaulted = true;

  sched_param param{};
  param.sched_priority = config.priority;
  const int min_priority = sched_get_priority_min(SCHED_FIFO);
  const int max_priority = sched_get_priority_max(SCHED_FIFO);
  if (config.priority < min_priority || config.priority > max_priority) {
    std::snprintf(text, sizeof text, "SCHED_FIFO priority %d is outside [%d, %d]", config.priority, min_priority,
                  max_priority);
    append(report.message, sizeof report.message, text);
    if (enforce) return report;
  } else if (const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); error == 0) {
    report.sched_fifo = true;
  } else {
    std::snprintf(text, sizeof text, "SCHED_FIFO priority %d not granted: %s (needs root or CAP_SYS_NICE)",
                  config.priority, std::strerror(error));
    append(report.message, sizeof report.message, text);
    if (enforce) return report;
  }

  if (config.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(config.cpu), &set);
    if (const int error = pthread_setaffinity_np(pthread_self(), sizeof set, &set); error == 0) {
      report.affinity_set = true;
    } else {
      std::snprintf(text, sizeof text, "CPU affinity %d not set: %s", config.cpu, std::strerror(error));
      append(report.message, sizeof report.message, text);
    }
  }

  if (config.hold_cpu_dma_latency && dma_latency_fd_ < 0) {
    const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    const std::int32_t zero_us = 0;
    if (fd >= 0 && write(fd, &zero_us, sizeof zero_us) == static_cast<ssize_t>(sizeof zero_us)) {
      dma_latency_fd_ = fd;
      report.dma_latency_held = true;
    } else {
      std::snprintf(text, sizeof text, "/dev/cpu_dma_latency not held at 0: %s", std::strerror(errno));
      append(report.message, sizeof report.message, text);
      if (fd >= 0) close(fd);
    }
  } else if (dma_latency_fd_ >= 0) {
    report.dma_latency_held = true;
  }
  report.ok = true;
  return report;
}

void RtThreadSetup::release() noexcept {
  if (dma_latency_fd_ >= 0) {
    close(dma_latency_fd_);
    dma_latency_fd_ = -1;
  }
}

}  // namespace fissure::rt
