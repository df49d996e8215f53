#pragma once
// A counting global operator new for the allocation tests: counts heap
// allocations while g_armed is set. Replaces the global operators, so
// include it from exactly one file of a test binary (each allocation test
// is a binary of its own).
#include <atomic>
#include <cstdlib>
#include <new>

// TOUCHDOWN_TEST_ASAN: 1 in an AddressSanitizer build, whose runtime owns
// malloc (GCC defines __SANITIZE_ADDRESS__; clang 14 only answers
// __has_feature(address_sanitizer)).
#if defined(__SANITIZE_ADDRESS__)
#define TOUCHDOWN_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TOUCHDOWN_TEST_ASAN 1
#endif
#endif
#ifndef TOUCHDOWN_TEST_ASAN
#define TOUCHDOWN_TEST_ASAN 0
#endif

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
