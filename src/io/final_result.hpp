// The result of a complete run (io/layout.hpp), written from its partial file once every
// tile is done.
//
// Parallel HDF5 1.10 writes compressed (filtered) datasets only collectively, which a
// dynamic schedule cannot do while tiles finish at unpredictable times; so the run writes
// uncompressed tiles to the partial file, and this pass, collective, reads them back and
// writes the result: every rank takes a contiguous share of the result's chunks (about
// 256 Ki points each, chosen for readers and for the compressor rather than for the
// schedule), compresses them (shuffle + deflate) in collective writes of a bounded number
// of chunks, so memory stays small whatever the grid. The result is written under
// OUTPUT.finishing and renamed to OUTPUT when closed: no incomplete file ever takes the
// result's name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "job/grid.hpp"
#include "job/job.hpp"
#include "mpi/mpi.hpp"
#include "result_metadata.hpp"
#include "retained_tiles.hpp"

namespace superball {

// Points of a result chunk: 2^18, i.e. 512 KiB of 16-bit counts and 256 KiB of outcomes.
inline constexpr std::uint64_t result_chunk_points = std::uint64_t{1} << 18;

// The chunks of a result of this grid shape, as tiles (the closing pass shares them out
// among the ranks in contiguous runs of chunk numbers).
Tiling result_chunks(const Extent& shape);

struct FinishReport {
    std::uint64_t raw_bytes = 0;   // of the data uncompressed
    std::uint64_t file_bytes = 0;  // of the result file
    double seconds = 0;
    std::string sidecar_note;      // "sidecar: PATH", or why there is none
};

// Tiles kept in memory by the ranks that computed them (retained_tiles.hpp), for the
// closing pass: the partial file's tiling, and this rank's store (null: none kept here).
struct Retained {
    const Tiling* tiling = nullptr;
    const RetainedTiles* tiles = nullptr;
};

// Collective: writes the result of `job` at `output` from the partial file `partial`
// (every tile done), with the run's figures; rank 0 then writes the XDMF sidecar and
// removes the partial file. Returns on every rank. When some rank passes tiles it kept
// (`retained`, the same tiling on every rank), each rank gathers its share of the result
// whole before writing it: the tiles kept anywhere through one MPI_Alltoallv, the rest
// read from the partial file; the share must then fit in memory (the caller decides).
FinishReport write_result(const std::filesystem::path& partial, const std::filesystem::path& output, const Job& job,
                          const Grid& grid, const mpi::Comm& comm, const RunFigures& run, const Retained& retained = {});

}  // namespace superball
