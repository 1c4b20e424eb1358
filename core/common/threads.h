// Work on more than one thread, for the callers that split their work:
// each keeps working when the system refuses a thread (std::system_error
// on a plant controller at its thread limit), on fewer threads.
#pragma once

#include <cstddef>
#include <functional>

namespace pvtwin {

// worker() on `threads` threads, the calling one among them; on fewer when
// the system refuses a thread. Each worker takes its items from a counter
// shared by all, so every item is done on however many run.
void RunOnThreads(unsigned threads, const std::function<void()>& worker);

// first() on a helper thread while second() runs on this one; both on this
// one, first() first, when the system refuses the thread. An exception of
// either is thrown here once both have ended (first()'s when both throw).
void RunBoth(const std::function<void()>& first, const std::function<void()>& second);

// f(begin, end) over the rows [0, n): the first half on a helper thread
// and the second on this one when n ≥ min_rows and the machine has two
// cores (both halves here when the system refuses the thread, as RunBoth
// does), else f(0, n) here. For row-local work (each row's results read
// that row's inputs only), whose result is then the same to the bit: each
// row's arithmetic does not depend on its thread.
void ForRowHalves(std::size_t n, std::size_t min_rows,
                  const std::function<void(std::size_t, std::size_t)>& f);

}  // namespace pvtwin
