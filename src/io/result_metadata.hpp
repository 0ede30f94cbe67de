// What a result and a partial file share: coordinate variables and root attributes
// (io/layout.hpp), and the descriptive attributes of the data.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "hdf5.hpp"
#include "result_reader.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"

namespace superball {

struct RunFigures {
    // The run that writes the figures: its ranks, hosts and threads are recorded, its line
    // appended to the file's history (once: a run records its figures at the start and at
    // the end).
    Provenance run;
    double wall_seconds = 0;  // of every run of the file so far
    bool complete = false;
};

// The coordinate variables of the range axes (/xi, /W, /alpha, ...: float64 samples, made
// dimension scales), scalar variables for the fixed coordinates (/U), and every root
// attribute, provenance included (source, build, date_created: the run that creates the
// file; history: one line per run). `kind`: layout::kind_result or kind_partial. Collective in a parallel file;
// the samples are written where `write_samples` (one rank). Returns the coordinate
// variables of the range axes, in axis order.
std::vector<h5::Id> write_metadata(hid_t file, const Job& job, const Grid& grid, const char* kind, const RunFigures& run,
                                   bool write_samples);

// long_name and units of the data, flag_values and flag_meanings of /outcome, the fixed
// coordinates as CF scalar coordinates, and the axes attached as dimension scales.
void describe_data(hid_t wall_bounces, hid_t outcome, const Job& job, const std::vector<h5::Id>& axes);

// The run's figures on an open file (replacing those written before; the run's history
// line is added to those of the runs before).
void write_run_figures(hid_t file, const RunFigures& run);

// The HDF5 type of the counts of a job: 16 bits unless max_bounces needs more.
hid_t count_type(const Job& job);
// Its size in bytes (2 or 4), for callers outside io/ that compare it with a file's.
std::size_t count_bytes(const Job& job);

// What a result of `job` says about itself (the reader's ResultInfo) as write_metadata
// writes it: for a writer that must describe its file without reading it back.
ResultInfo result_info(const Job& job, const Grid& grid);

}  // namespace superball
