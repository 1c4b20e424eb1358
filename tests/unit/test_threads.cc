// core/common/threads.h: every item done once on any number of threads, and
// an exception of a worker thrown to the caller after every thread ended.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/common/threads.h"

namespace pvtwin {
namespace {

TEST(RunOnThreads, EveryItemIsDoneOnceOnAsManyThreadsAsAsked) {
  for (unsigned threads : {0u, 1u, 2u, 5u}) {
    constexpr std::size_t kItems = 200;
    std::vector<std::atomic<int>> done(kItems);
    std::atomic<std::size_t> next{0};
    std::mutex mutex;
    std::set<std::thread::id> ids;
    RunOnThreads(threads, [&] {
      {
        const std::lock_guard<std::mutex> lock(mutex);
        ids.insert(std::this_thread::get_id());
      }
      for (std::size_t k = next++; k < kItems; k = next++) ++done[k];
    });
    for (std::size_t k = 0; k < kItems; ++k) ASSERT_EQ(done[k], 1) << threads << " threads";
    EXPECT_EQ(ids.size(), std::max(threads, 1u));
    EXPECT_EQ(ids.count(std::this_thread::get_id()), 1u);  // the caller works too
  }
}

TEST(RunOnThreads, AWorkersExceptionReachesTheCallerAfterTheOthersFinish) {
  constexpr std::size_t kItems = 100;
  std::atomic<std::size_t> next{0};
  std::atomic<int> done{0};
  auto worker = [&] {
    for (std::size_t k = next++; k < kItems; k = next++) {
      if (k == 3) throw std::runtime_error("item 3");
      std::this_thread::sleep_for(std::chrono::microseconds(50));
      ++done;
    }
  };
  EXPECT_THROW(RunOnThreads(2, worker), std::runtime_error);
  // The thread that threw stopped at item 3; the other took every other
  // item and then one number past the end.
  EXPECT_EQ(next.load(), kItems + 1);
  EXPECT_EQ(done.load(), static_cast<int>(kItems) - 1);
}

TEST(RunBoth, RunsBothOnTwoThreadsAndThrowsOnceBothEnded) {
  std::thread::id first_id, second_id;
  RunBoth([&] { first_id = std::this_thread::get_id(); },
          [&] { second_id = std::this_thread::get_id(); });
  EXPECT_NE(first_id, second_id);
  EXPECT_EQ(second_id, std::this_thread::get_id());

  std::atomic<bool> second_ended{false};
  try {
    RunBoth([] { throw std::runtime_error("first"); },
            [&] {
              std::this_thread::sleep_for(std::chrono::milliseconds(20));
              second_ended = true;
              throw std::logic_error("second");
            });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");  // first()'s when both throw
  }
  EXPECT_TRUE(second_ended.load());
  EXPECT_THROW(RunBoth([] {}, [] { throw std::logic_error("second"); }), std::logic_error);
}

}  // namespace
}  // namespace pvtwin
