// UseHugePageHeap: the allocations after it come from one advised range.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/common/heap.h"

namespace pvtwin {
namespace {

// The VmFlags of the mapping that holds `address` (/proc/self/smaps); empty
// when none does.
std::string VmFlagsAt(const void* address) {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    unsigned long long begin = 0, end = 0;
    if (std::sscanf(line.c_str(), "%llx-%llx ", &begin, &end) == 2 &&
        line.find(':') > line.find(' ')) {
      inside = begin <= at && at < end;
    } else if (inside && line.starts_with("VmFlags:")) {
      return line.substr(8) + " ";
    }
  }
  return "";
}

// In a child process (the allocator's settings are the process's): exit 0
// when an 8 MiB block allocated after UseHugePageHeap lies in a mapping
// advised for huge pages, 1 when it does not, 2 when the call says it gave
// no advice.
void CheckBlockAfterTheCall() {
  if (!UseHugePageHeap(std::size_t{64} << 20)) std::_Exit(2);
  // glibc maps a block this large on its own by default: without the
  // settings it lands outside the advised range.
  char* const block = static_cast<char*>(std::malloc(std::size_t{8} << 20));
  // Its middle: the range advised starts at the first 2 MiB boundary.
  const std::string flags = VmFlagsAt(block + (std::size_t{4} << 20));
  std::free(block);
  std::_Exit(flags.find(" hg ") != std::string::npos ? 0 : 1);
}

TEST(HugePageHeap, LaterBlocksComeFromTheAdvisedRange) {
  if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled")) {
    GTEST_SKIP() << "this kernel has no transparent huge pages";
  }
  const int expected = kSanitizerAllocator ? 2 : 0;
  EXPECT_EXIT(CheckBlockAfterTheCall(), ::testing::ExitedWithCode(expected), "");
}

}  // namespace
}  // namespace pvtwin
