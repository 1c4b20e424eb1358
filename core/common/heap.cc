#include "core/common/heap.h"

#include <cstdint>
#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#endif

namespace pvtwin {

bool UseHugePageHeap(std::size_t bytes) {
#if defined(__GLIBC__) && !defined(PVTWIN_SANITIZER_ALLOCATOR)
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  // Each mallopt returns 1 on success; M_TRIM_THRESHOLD -1 turns trimming off.
  if (mallopt(M_ARENA_MAX, 1) != 1 || mallopt(M_MMAP_MAX, 0) != 1 ||
      mallopt(M_TRIM_THRESHOLD, -1) != 1) {
    return false;
  }
  // Without separate mappings, this block grows the heap by `bytes`; freed,
  // it stays there as the room later allocations are carved from.
  void* const block = std::malloc(bytes);
  if (block == nullptr) return false;
  const auto at = reinterpret_cast<std::uintptr_t>(block);
  const std::uintptr_t begin = (at + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t end = (at + bytes) & ~(kHugePage - 1);
  const bool advised =
      end > begin && madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE) == 0;
  std::free(block);
  return advised;
#else
  (void)bytes;
  return false;
#endif
}

}  // namespace pvtwin
