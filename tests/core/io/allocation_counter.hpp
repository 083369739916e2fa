#pragma once
// Counts what operator new hands out while a scope is open (allocation_counter.cpp replaces the
// global operator new and delete of lamina_io_tests): the readers' tests bound the bytes a hostile
// file can make them allocate, instead of timing them.
#include <cstddef>

namespace lamina::test {

class AllocationScope {
 public:
  AllocationScope();
  ~AllocationScope();
  AllocationScope(AllocationScope&&) = delete;  // nor copied: one scope, open while it lives

  std::size_t total_bytes() const;  // every allocation since the scope opened, freed or not
  std::size_t peak_bytes() const;   // the most held at once, above what was held when it opened
};

}  // namespace lamina::test
