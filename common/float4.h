#pragma once
// One ball's hot data in one 16-byte slot: position + radius, or velocity +
// inverse mass (kernels.h's rows). A neighbour's row is then a single aligned
// load in the SIMD kernels, and read field by field in the scalar one.

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

namespace fishtank {

struct alignas(16) Float4 {
  float x = 0.0f, y = 0.0f, z = 0.0f, w = 0.0f;
};
static_assert(sizeof(Float4) == 16 && alignof(Float4) == 16);

// The squared length of x, y, z: a velocity row's squared speed.
inline float squared_length3(const Float4& v) { return v.x * v.x + v.y * v.y + v.z * v.z; }

// Every x86-64 processor's cache line.
inline constexpr std::size_t kCacheLineBytes = 64;

// Cache-line aligned storage, so a thread's chunk never starts mid-line and the
// arrays never share a line with unrelated data.
template <class T>
struct CacheAlignedAllocator {
  using value_type = T;
  static constexpr std::size_t kAlignment = kCacheLineBytes;
  CacheAlignedAllocator() = default;
  template <class U>
  CacheAlignedAllocator(const CacheAlignedAllocator<U>&) {}
  T* allocate(std::size_t n) {
    std::size_t bytes = (n * sizeof(T) + kAlignment - 1) / kAlignment * kAlignment;
    if (void* p = std::aligned_alloc(kAlignment, bytes)) return static_cast<T*>(p);
    throw std::bad_alloc();
  }
  void deallocate(T* p, std::size_t) { std::free(p); }
  template <class U>
  bool operator==(const CacheAlignedAllocator<U>&) const {
    return true;
  }
  template <class U>
  bool operator!=(const CacheAlignedAllocator<U>&) const {
    return false;
  }
};

template <class T>
using AlignedVector = std::vector<T, CacheAlignedAllocator<T>>;

}  // namespace fishtank
