// Thread start-up that falls back to fewer threads (issue 15: `info --threads
// 100000` and `audit --threads 1024` under a memory limit used to abort).
#include "workers.h"

#include <exception>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>
#include <vector>

namespace ra {

int run_workers(int n, const std::function<void()>& worker) {
  // The first exception of any copy is rethrown once all have returned (one
  // escaping a thread would terminate the process).
  std::exception_ptr error;
  std::mutex mu;
  auto guarded = [&] {
    try {
      worker();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mu);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  try {
    pool.reserve(n > 1 ? std::size_t(n - 1) : 0);
    for (int i = 1; i < n; ++i) pool.emplace_back(guarded);
  } catch (const std::system_error&) {
    // No more threads (resource limit): those started, and this one, do it all.
  } catch (const std::bad_alloc&) {
  }
  guarded();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return int(pool.size()) + 1;
}

}  // namespace ra
