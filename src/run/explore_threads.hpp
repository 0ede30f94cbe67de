// Running an exploration job in this process on threads, without MPI: the library function
// behind the Python module's explore(). The same plan (plan_explore), partial file, resume
// journal, compressed tiles appended by one writer, and closing pass (finish_result) as
// run_explore (run/explore.hpp), so the result is the file `mpirun -n T superball explore`
// writes for the same job (same tiling, data, coordinates and attributes; its provenance
// says 1 rank of T threads), and each resumes the other's interrupted runs.
#pragma once

#include "run/explore.hpp"

namespace superball {

// Plans, runs and finishes `job` on `threads` threads (0: usable_cores()), each counting
// whole tiles (a tile at a time, or an alignment unit of tiles for an uncompressed file).
// `stop` is polled on the calling thread only, between its tiles (Python checks for
// Ctrl-C there); the other threads stop at their next tile, and the run ends interrupted,
// resumable. `observer` is called from any thread, one call at a time. Throws InputError
// when planning refuses or the partial file to resume is damaged, RunError when the files
// cannot be made or finished.
RunSummary run_explore_threads(const Job& job, const ExploreSettings& settings, unsigned threads, RunObserver& observer,
                               const StopRequested& stop);

}  // namespace superball
