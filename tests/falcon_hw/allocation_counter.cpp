// Replaced global allocation functions that count. Kept in their own translation unit so the
// compiler cannot inline them into call sites (GCC would then flag new/free pairs as
// mismatched); behaviour is otherwise malloc/free.
#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

namespace fissure::testing {
long allocation_count() noexcept { return g_allocations.load(std::memory_order_relaxed); }
}  // namespace fissure::testing

// GCC 12 at -O1 (the sanitizer presets) inlines these replacements into their callers and then
// reports free() on memory from "operator new" as -Wmismatched-new-delete: a false positive for
// a replaced global operator new that itself allocates with malloc.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return ::operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return ::operator new(size, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
