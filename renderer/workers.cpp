// Thread start-up that falls back to fewer threads (issue 15: `info --threads
// 100000` and `audit --threads 1024` under a memory limit used to abort).
#include "workers.h"

#include <exception>
#include <new>
#include <system_error>
#include <thread>
#include <vector>

namespace ra {

int run_workers(int n, const std::function<void()>& worker) {
  std::vector<std::thread> pool;
  try {
    pool.reserve(n > 1 ? std::size_t(n - 1) : 0);
    for (int i = 1; i < n; ++i) pool.emplace_back(worker);
  } catch (const std::system_error&) {
    // No more threads (resource limit): those started, and this one, do it all.
  } catch (const std::bad_alloc&) {
  }
  std::exception_ptr error;
  try {
    worker();
  } catch (...) {
    error = std::current_exception();  // join the others first: a joinable thread's destructor aborts
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return int(pool.size()) + 1;
}

}  // namespace ra
