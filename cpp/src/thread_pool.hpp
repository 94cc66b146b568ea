// A small pool of std::threads for the batch layer (no OpenMP: a wheel must not
// bring its own runtime, and the pool must survive fork()).
#pragma once

#include <functional>

namespace principled_brdf {

// Runs task(0) ... task(count - 1) on up to `threads` threads (the caller is
// one of them) and returns when all are done. Tasks must not throw.
void parallel_for(int count, int threads, const std::function<void(int)>& task);

}  // namespace principled_brdf
