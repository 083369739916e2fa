// The global operator new and delete, counting through malloc_usable_size while an
// AllocationScope is open (one at a time).
#include "allocation_counter.hpp"

#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<bool> counting{false};
std::atomic<std::size_t> total{0};
// Signed: a block from before the scope may be freed inside it, taking live below zero.
std::atomic<std::ptrdiff_t> live{0}, peak{0};

void* allocate(std::size_t n) {
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p == nullptr) throw std::bad_alloc();
  if (counting.load(std::memory_order_relaxed)) {
    const std::size_t size = malloc_usable_size(p);
    total += size;
    const std::ptrdiff_t now = live += static_cast<std::ptrdiff_t>(size);
    for (std::ptrdiff_t seen = peak.load(); now > seen && !peak.compare_exchange_weak(seen, now);) {
    }
  }
  return p;
}

void release(void* p) {
  if (p == nullptr) return;
  if (counting.load(std::memory_order_relaxed)) {
    live -= static_cast<std::ptrdiff_t>(malloc_usable_size(p));
  }
  std::free(p);
}

}  // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }

namespace lamina::test {

AllocationScope::AllocationScope() {
  total = 0;
  live = 0;
  peak = 0;
  counting = true;
}

AllocationScope::~AllocationScope() { counting = false; }

std::size_t AllocationScope::total_bytes() const { return total.load(); }

std::size_t AllocationScope::peak_bytes() const { return static_cast<std::size_t>(std::max<std::ptrdiff_t>(peak.load(), 0)); }

}  // namespace lamina::test
