// Starting worker threads without aborting: when the system refuses a thread
// (EAGAIN under RLIMIT_NPROC or RLIMIT_AS), the work goes on with fewer.
#pragma once
#include <functional>

namespace ra {

// Runs `worker` on up to `n` threads, the calling thread being one of them,
// and returns when every copy has returned. Each copy must take its work from
// a shared queue (e.g. an atomic counter), so that fewer threads than asked
// still do all of it. Returns how many threads ran (at least 1). A thread the
// system cannot create is not an error: the ones already running suffice.
// An exception from any copy is rethrown here after every copy has returned.
int run_workers(int n, const std::function<void()>& worker);

}  // namespace ra
