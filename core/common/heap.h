// The heap of a short batch process (`pvtwin calibrate`): taken from the
// system once, backed by huge pages, kept until exit.
#pragma once

#include <cstddef>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PVTWIN_SANITIZER_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
#define PVTWIN_SANITIZER_ALLOCATOR 1
#endif
#endif

namespace pvtwin {

// Whether malloc is a sanitizer's (UseHugePageHeap then does nothing).
#ifdef PVTWIN_SANITIZER_ALLOCATOR
inline constexpr bool kSanitizerAllocator = true;
#else
inline constexpr bool kSanitizerAllocator = false;
#endif

// A calibration writes its whole working set once: the series, the drivers,
// the residuals, the Jacobians (some 12 MB for 14 days at 1 min, 150 MB at
// 5 s). Each fresh 4 KiB page costs a page fault, and those faults were a
// tenth of the process's CPU time. This sets the allocator up for that:
//   - one arena for all threads, and no separate mappings for large blocks,
//     so that every allocation comes from the one heap;
//   - freed memory is kept for the next allocation instead of being
//     returned (and faulted in again);
//   - the heap is grown by `bytes` at once, and the kernel is advised to
//     back that range with transparent huge pages (madvise): 2 MiB per
//     fault. Where THP is off ("never") the advice does nothing.
// For processes that end after their work: memory is not returned before
// exit. False when the advice was not given: the C library is not glibc,
// the allocator is a sanitizer's, or the memory or the advice was refused.
// Only the speed depends on it.
bool UseHugePageHeap(std::size_t bytes);

}  // namespace pvtwin
