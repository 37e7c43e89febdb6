#pragma once
// ImageBuffer<T>: a std::vector for the whole-image working arrays of passes over every pixel (the
// denoiser, the error estimate). Its elements are left uninitialised where made without a value
// (ImageBuffer<float>(n), resize(n)): each pass writes every element of its output, and zeroing it
// first was a pass over memory of its own. Blocks of 2 MiB and more are aligned to 2 MiB and advised to the
// kernel as transparent huge pages (madvise MADV_HUGEPAGE), so that their first touch faults once per
// 2 MiB, not once per 4 KiB: `candela denoise` at 1920 x 1080 spent 45% of its time in page faults on
// a 2-core virtual machine, 5.5 s -> 3.0 s with huge pages (docs/performance.md). Where the kernel's
// huge pages are off ("never"), the advice is ignored and nothing else changes.
#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace candela {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t(2) << 20;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) return static_cast<T*>(::operator new(bytes));
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
    madvise(p, rounded, MADV_HUGEPAGE);
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) noexcept {
    if (n * sizeof(T) < kHugePage)
      ::operator delete(p);
    else
      std::free(p);
  }
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;  // default-initialised: uninitialised for numbers
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using ImageBuffer = std::vector<T, HugePageAllocator<T>>;

}  // namespace candela
