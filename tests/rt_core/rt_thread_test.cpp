#include "fissure/rt_core/rt_thread.hpp"

#include <gtest/gtest.h>

#include <string>

namespace fissure::rt {
namespace {

// Only the parts that cannot change the test process's scheduling: a priority outside
// SCHED_FIFO's range is refused under kEnforce and tolerated (with a warning) under kBestEffort.
TEST(RtThreadSetup, EnforceRefusesWhatCannotBeHadAndBestEffortWarns) {
  RtThreadConfig config;
  config.priority = 1000;
  config.lock_memory = false;
  config.hold_cpu_dma_latency = false;
  config.stack_prefault_bytes = 64 * 1024;

  RtThreadSetup enforce;
  config.policy = RtPolicy::kEnforce;
  const RtSetupReport refused = enforce.apply(config);
  EXPECT_FALSE(refused.ok);
  EXPECT_FALSE(refused.sched_fifo);
  EXPECT_NE(std::string(refused.message).find("priority 1000"), std::string::npos) << refused.message;

  RtThreadSetup best_effort;
  config.policy = RtPolicy::kBestEffort;
  const RtSetupReport warned = best_effort.apply(config);
  EXPECT_TRUE(warned.ok);
  EXPECT_TRUE(warned.stack_prefaulted);
  EXPECT_NE(std::string(warned.message).find("priority 1000"), std::string::npos) << warned.message;
}

}  // namespace
}  // namespace fissure::rt
