#pragma once
// Counts every global operator new in the test executable that links allocation_counter.cpp
// (which replaces the global allocation functions), so a test can assert that a stretch of
// code made no heap allocation: compare allocation_count() before and after.
namespace fissure::testing {

[[nodiscard]] long allocation_count() noexcept;

}  // namespace fissure::testing
