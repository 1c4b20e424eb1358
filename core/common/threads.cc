#include "core/common/threads.h"

#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace pvtwin {

namespace {

// f(), its exception kept in *failure.
void Guarded(const std::function<void()>& f, std::exception_ptr* failure) {
  try {
    f();
  } catch (...) {
    *failure = std::current_exception();
  }
}

}  // namespace

void RunOnThreads(unsigned threads, const std::function<void()>& worker) {
  std::vector<std::exception_ptr> failures(threads > 0 ? threads : 1);
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(Guarded, std::cref(worker), &failures[t]);
    } catch (const std::system_error&) {
      break;
    }
  }
  Guarded(worker, &failures[0]);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

void RunBoth(const std::function<void()>& first, const std::function<void()>& second) {
  std::exception_ptr first_failure, second_failure;
  std::thread helper;
  try {
    helper = std::thread(Guarded, std::cref(first), &first_failure);
  } catch (const std::system_error&) {
    Guarded(first, &first_failure);
  }
  Guarded(second, &second_failure);
  if (helper.joinable()) helper.join();
  if (first_failure) std::rethrow_exception(first_failure);
  if (second_failure) std::rethrow_exception(second_failure);
}

void ForRowHalves(std::size_t n, std::size_t min_rows,
                  const std::function<void(std::size_t, std::size_t)>& f) {
  if (n < min_rows || std::thread::hardware_concurrency() < 2) {
    f(0, n);
    return;
  }
  const std::size_t half = n / 2;
  RunBoth([&] { f(0, half); }, [&] { f(half, n); });
}

}  // namespace pvtwin
