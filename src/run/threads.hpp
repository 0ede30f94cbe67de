// Work on the threads of this process, for the library functions that run without MPI
// (count_on_threads, run_explore_threads: the Python module's count() and explore()).
#pragma once

#include <functional>

namespace superball {

// Calls body(i) for i = 0 .. n - 1 at once: body(0) on the calling thread (where a caller
// may poll for a stop: Python delivers signals to its main thread), the others on threads
// of their own; returns when all have returned. The first exception a body throws is
// rethrown here, once every body has returned (bodies that must stop early watch a flag).
void run_on_threads(unsigned n, const std::function<void(unsigned)>& body);

}  // namespace superball
