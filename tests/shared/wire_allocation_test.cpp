// No heap allocation in encode, decode, reassembly, the link helpers and the in-memory and
// fault-injecting carriers: the rt side runs them inside its tick. Counted by replacing the
// global operator new for this test binary.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "fissure/shared/fault_injecting_carrier.hpp"
#include "fissure/shared/loopback_carrier.hpp"
#include "fissure/shared/wire_codec.hpp"
#include "fissure/shared/wire_link.hpp"
#include "fissure/shared/wire_reassembler.hpp"
#include "wire_test_messages.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};

void* counted_allocation(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
}  // namespace

// GCC 12 at -O1 (the sanitizer presets) inlines these replacements into their callers and then
// reports free() on memory from "operator new" as -Wmismatched-new-delete: a false positive for
// a replaced global operator new that itself allocates with malloc.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) { return counted_allocation(size); }
void* operator new[](std::size_t size) { return counted_allocation(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace fissure::transport {
namespace {

/// Counts operator new calls made while `body` runs.
template <typename Body>
long allocations_during(Body&& body) {
  g_allocations = 0;
  g_counting = true;
  body();
  g_counting = false;
  return g_allocations.load();
}

TEST(WireAllocation, TheCounterSeesAnAllocation) {
  // Guards against a counter that silently counts nothing (then the tests below prove nothing).
  const long count = allocations_during([] {
    int* volatile p = new int(3);
    delete p;
  });
  EXPECT_EQ(count, 1);
}

TEST(WireAllocation, EncodeAndReassemblyDoNotAllocate) {
  const ContactProxy proxy = test::make_proxy(3, kMaxContactPatches);
  const DeviceState state = test::make_device_state(3);
  auto batch = std::make_unique<wire::FrameBatch>();
  auto reassembler = std::make_unique<wire::Reassembler>();
  int completed = 0;
  const long count = allocations_during([&] {
    for (std::uint8_t transfer = 0; transfer < 50; ++transfer) {
      ContactProxy next = proxy;
      next.sequence = 10 + transfer;
      (void)wire::encode(next, transfer, *batch);
      for (std::size_t i = 0; i < batch->count; ++i) {
        completed += reassembler->push(batch->frames[i], transfer) == wire::MessageType::kContactProxy ? 1 : 0;
      }
      DeviceState next_state = state;
      next_state.sequence = 10 + transfer;
      (void)wire::encode(next_state, transfer, *batch);
      completed += reassembler->push(batch->frames[0], transfer) == wire::MessageType::kDeviceState ? 1 : 0;
      batch->frames[0].data[10] ^= 1;  // a CRC failure path too
      reassembler->push(batch->frames[0], transfer);
    }
  });
  EXPECT_EQ(count, 0);
  EXPECT_EQ(completed, 100) << "the loop did the work it claims";
  EXPECT_EQ(reassembler->stats().messages_crc_error, 50u);
}

TEST(WireAllocation, LinkEndpointsOverAFaultyLoopbackDoNotAllocate) {
  LockstepClock clock;
  auto link = std::make_unique<LoopbackLink>(clock);
  auto faulty = std::make_unique<FaultInjectingCarrier>(
      link->b(), clock, FaultConfig{.drop_probability = 0.05, .duplicate_probability = 0.05, .reorder_probability = 0.05,
                                    .corrupt_probability = 0.05, .delay_probability = 0.05, .seed = 9});
  auto rt = std::make_unique<LinkEndpoint>(*faulty, clock, LinkConfig{.role = wire::Role::kRt, .session_id = 1});
  auto host = std::make_unique<LinkEndpoint>(link->a(), clock, LinkConfig{.role = wire::Role::kHost, .session_id = 2});
  std::vector<ContactProxy> proxies;
  for (std::uint64_t n = 1; n <= 200; ++n) proxies.push_back(test::make_proxy(n, static_cast<std::uint16_t>(n % 9)));
  auto taken = std::make_unique<ContactProxy>();
  int received = 0;
  const long count = allocations_during([&] {
    for (const ContactProxy& proxy : proxies) {
      clock.advance(1'000'000);
      host->publish(proxy);
      host->tick();
      rt->publish(test::make_device_state(proxy.sequence));
      rt->tick();
      received += rt->receiver().try_take_proxy(*taken) ? 1 : 0;
    }
  });
  EXPECT_EQ(count, 0);
  EXPECT_TRUE(rt->established());
  EXPECT_GT(received, 50) << "proxies did flow";
}

}  // namespace
}  // namespace fissure::transport
