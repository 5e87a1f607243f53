// Thread start-up that falls back to fewer threads (`info --threads
// 100000` and `audit --threads 1024` under a memory limit used to abort).
#include "workers.h"

#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <algorithm>
#include <exception>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>
#include <vector>

namespace ra {
namespace {

// Under an address-space limit (RLIMIT_AS) every thread's stack takes its
// share of it. Starting threads until the system refuses one would leave
// nothing for the work itself, and the threads already running would then
// fail to allocate (std::bad_alloc, seen under `prlimit --as`). So at most
// half of the address space still free goes to stacks. No limit: no cap.
int threads_the_address_space_allows(int n) {
  rlimit as{};
  if (getrlimit(RLIMIT_AS, &as) != 0 || as.rlim_cur == RLIM_INFINITY) return n;
  pthread_attr_t attr;
  std::size_t stack = 8u << 20;
  if (pthread_attr_init(&attr) == 0) {
    pthread_attr_getstacksize(&attr, &stack);
    pthread_attr_destroy(&attr);
  }
  unsigned long pages = 0;  // the address space in use now, from /proc
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%lu", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  const double used = double(pages) * double(sysconf(_SC_PAGESIZE));
  const double free_bytes = double(as.rlim_cur) - used;
  const double fit = free_bytes > 0 ? free_bytes / 2 / double(stack) : 0;
  return fit < n ? std::max(1, int(fit)) : n;
}

}  // namespace

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
  n = threads_the_address_space_allows(n);
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
