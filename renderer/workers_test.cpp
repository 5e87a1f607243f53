// Worker threads (workers.h): all the work done whatever the thread count
// (the system may refuse threads: fewer start), and an exception in any
// thread rethrown after every thread has joined.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>

#include "errors.h"
#include "workers.h"

using namespace ra;

namespace {

TEST(Workers, AllWorkIsDoneWhateverTheThreadCount) {
  for (int n : {1, 2, 7, 64}) {
    std::atomic<int> next{0}, sum{0};
    const int ran = run_workers(n, [&] {
      for (int i; (i = next.fetch_add(1)) < 1000;) sum += i;
    });
    EXPECT_EQ(sum.load(), 999 * 1000 / 2) << n;
    EXPECT_GE(ran, 1);
    EXPECT_LE(ran, n);
  }
}

// A worker's exception, from whichever thread, reaches the caller after the
// others are joined (escaping a thread, or a joinable std::thread destroyed,
// would abort the process; the asan build found the first).
TEST(Workers, AnExceptionInAnyThreadIsRethrownAfterJoining) {
  std::atomic<int> calls{0};
  EXPECT_THROW(run_workers(4,
                           [&] {
                             if (calls.fetch_add(1) == 0) throw InputError("first");
                           }),
               InputError);
  EXPECT_EQ(calls.load(), 4);
}

}  // namespace
