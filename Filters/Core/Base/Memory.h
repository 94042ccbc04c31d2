// Fresh large buffers. A first touch of a 4 KB page costs ~3 us on a VM (289 ms per 100 MB
// measured here, against ~14 ms for 2 MB pages): each 36 MB array of a BraTS volume ~0.1 s before
// any work is done. Buffers advised before their first touch fault 2 MB at a time where the kernel
// offers transparent huge pages on request (Linux THP "madvise" or "always"); elsewhere nothing changes.
// Buffers over 256 MB are not advised: a VM that hands free 2 MB blocks back to its host faults
// huge pages it has no warm blocks for at ~2.3 s per GB against ~0.4 s for 4 KB pages, and no
// warm pool holds a 512^3 image's arrays.
#pragma once

#include <cstddef>
#include <vector>

namespace featuremesh
{
// Asks for huge pages over the whole 2 MB blocks of [data, data + bytes) when bytes <= 256 MB; not yet
// touched memory only.
void AdviseHugePages(const void* data, std::size_t bytes);

// Hands the pages of freed heap blocks back to the system (glibc's malloc_trim; elsewhere nothing).
// Blocks under malloc's mmap threshold (at most 32 MB) stay resident when freed, and the next large
// buffer (a label image) comes on top of them: after a large image's temporaries, this lowers the
// process's peak.
void ReturnFreedMemory();

// `v` holding n copies of `value` in fresh memory advised for huge pages (its old contents dropped).
template <typename T>
void AssignFresh(std::vector<T>& v, std::size_t n, const T& value = T())
{
  std::vector<T>().swap(v);
  v.reserve(n);
  AdviseHugePages(v.data(), n * sizeof(T));
  v.assign(n, value);
}
} // namespace featuremesh
