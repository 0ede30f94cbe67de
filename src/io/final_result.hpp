// The result of a complete run (io/layout.hpp): its partial file, every tile done, made
// the result in place. One process does it (rank 0), after every rank has closed the
// file: compressed tiles are indexed where rank 0's appender wrote them
// (io/placed_chunks.hpp: no byte of data is read or written again), the run's figures
// written, the journal removed; then the file takes the result's name, so that no
// incomplete file ever has it, and the XDMF sidecar is written beside it. What is left
// after the last tile is counted costs about half a microsecond per tile, whatever the
// grid.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "job/tiles.hpp"
#include "partial_file.hpp"
#include "result_metadata.hpp"
#include "result_reader.hpp"

namespace superball {

struct FinishReport {
    std::uint64_t raw_bytes = 0;   // of the data uncompressed
    std::uint64_t file_bytes = 0;  // of the result file
    double seconds = 0;
    std::string sidecar_note;      // "sidecar: PATH", or why there is none
};

// Makes the partial file `partial` (of layout `layout`, with every tile done as the flags
// `done` say; where each compressed tile lies read from its journal, a window at a time)
// the result `output`, with the run's figures; `info` describes it (for its sidecar: the
// data are not read back). Throws h5::Error or
// std::runtime_error naming the file on failure; the partial file is then as it was
// (PlacedChunks's undo log), and a resume finishes it.
FinishReport finish_result(const std::filesystem::path& partial, const std::filesystem::path& output, const ResultInfo& info,
                           const Tiling& tiling, const PartialLayout& layout, std::span<const std::uint8_t> done,
                           const RunFigures& run);

}  // namespace superball
