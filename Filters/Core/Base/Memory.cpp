#include "Memory.h"

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace featuremesh
{
void AdviseHugePages(const void* data, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::size_t LargestAdvised = std::size_t(256) << 20; // Memory.h: beyond it 4 KB pages fault faster
  constexpr std::uintptr_t Huge = std::uintptr_t(2) << 20;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + Huge - 1) & ~(Huge - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(Huge - 1);
  if (data && end > begin && bytes <= LargestAdvised)
  {
    // Advice only: a kernel without THP refuses it and the buffer keeps small pages.
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
#else
  (void)data;
  (void)bytes;
#endif
}

void ReturnFreedMemory()
{
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}
} // namespace featuremesh
