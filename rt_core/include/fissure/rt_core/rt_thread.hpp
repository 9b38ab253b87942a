#pragma once
// Real-time setup of the thread that will run the loop (BRIEF §7), as an explicit policy:
//   kEnforce    — SCHED_FIFO at the requested priority and mlockall must succeed, else
//                 apply() reports failure with one clear line and the caller must not run;
//   kBestEffort — whatever fails is reported as one warning line and the loop runs anyway
//                 (CI, laptops, containers without CAP_SYS_NICE).
// CPU affinity and /dev/cpu_dma_latency are tuning, never fatal: their failures are warnings
// under both policies. Not for the tick: called once, before the loop, on the loop's thread.
#include <cstddef>

namespace fissure::rt {

enum class RtPolicy { kEnforce, kBestEffort };

/// SCHED_FIFO priority [1..99]: 80 sits above the default hard-IRQ threads (50) and below
/// the kernel's watchdog/migration threads (99) (BRIEF §7; the PREEMPT_RT HOWTO's advice).
inline constexpr int kDefaultRtPriority = 80;
/// Stack pre-faulted before the loop [bytes]: 512 KiB is far more than the tick uses
/// (RtData lives outside the stack), so no page fault can hit the loop's stack later.
inline constexpr std::size_t kDefaultStackPrefault_bytes = 512 * 1024;

struct RtThreadConfig {
  RtPolicy policy = RtPolicy::kEnforce;
  int priority = kDefaultRtPriority;
  int cpu = -1;  ///< pin the thread to this CPU; −1 = leave the affinity alone
  bool lock_memory = true;
  std::size_t stack_prefault_bytes = kDefaultStackPrefault_bytes;
  bool hold_cpu_dma_latency = true;  ///< write 0 to /dev/cpu_dma_latency and keep it open
};

struct RtSetupReport {
  bool ok = false;               ///< false only under kEnforce: do not run
  bool sched_fifo = false;
  bool memory_locked = false;
  bool affinity_set = false;
  bool dma_latency_held = false;
  bool stack_prefaulted = false;
  char message[512] = {};        ///< the error (enforce) or the warnings (best effort); "" if none
};

/// Applies the policy to the calling thread. Holds /dev/cpu_dma_latency open until release()
/// or destruction (the kernel drops the request when the file is closed).
class RtThreadSetup {
 public:
  RtThreadSetup() noexcept = default;
  RtThreadSetup(const RtThreadSetup&) = delete;
  RtThreadSetup& operator=(const RtThreadSetup&) = delete;
  ~RtThreadSetup() { release(); }

  RtSetupReport apply(const RtThreadConfig& config) noexcept;
  /// Closes /dev/cpu_dma_latency (back to the default C-state policy).
  void release() noexcept;

 private:
  int dma_latency_fd_ = -1;
};

}  // namespace fissure::rt
