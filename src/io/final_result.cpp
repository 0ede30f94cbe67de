#include "final_result.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <system_error>

#include "hdf5.hpp"
#include "layout.hpp"
#include "placed_chunks.hpp"
#include "posix_file.hpp"
#include "xdmf.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {

std::uint64_t size_of(const fs::path& p)
{
    std::error_code ec;
    const auto n = fs::file_size(p, ec);
    return ec ? 0 : n;
}

}  // namespace

FinishReport finish_result(const fs::path& partial, const fs::path& output, const ResultInfo& info, const Tiling& tiling,
                           const PartialLayout& layout, std::span<const std::uint8_t> done, const RunFigures& run)
{
    const auto started = std::chrono::steady_clock::now();
    for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
        if (t >= done.size() || done[t] == 0) throw std::logic_error(fmt::format("finish_result: tile {} is not done", t));
    }
    {
        PlacedChunks file(partial);
        if (layout.compressed) {
            const h5::Id counts = h5::open_dataset(file.file(), layout::wall_bounces);
            const h5::Id outcomes = h5::open_dataset(file.file(), layout::outcome);
            std::vector<hsize_t> origin;  // one buffer for every tile: this loop runs once a chunk
            // Where the tiles lie, read from the journal a window at a time (1.5 MiB) rather
            // than all of them at once: 24 bytes a tile is 100 MiB at 4 million tiles.
            const PosixFile journal(partial, false);
            constexpr std::uint64_t window = 65536;
            for (std::uint64_t first = 0; first < tiling.tiles(); first += window) {
                const std::vector<StoredChunk> stored =
                    read_stored(journal, layout, first, std::min(window, tiling.tiles() - first));
                for (std::uint64_t i = 0; i < stored.size(); ++i) {
                    const Box box = tiling.box(first + i);
                    origin.assign(box.start.begin(), box.start.end());
                    const StoredChunk& s = stored[i];
                    file.add(counts, origin, s.address, s.counts_bytes);
                    file.add(outcomes, origin, s.address + s.counts_bytes, s.outcomes_bytes);
                }
            }
        }
        h5::write_attribute(file.file(), layout::kind_attribute, layout::kind_result);
        write_run_figures(file.file(), run);
        h5::delete_attribute(file.file(), layout::attr::tile_shape);
        h5::unlink(file.file(), "/progress");
        file.close();
    }
    // The result takes its name only now, whole; then the undo log goes.
    std::error_code ec;
    fs::rename(partial, output, ec);
    if (ec) throw std::runtime_error(fmt::format("renaming {} to {} failed ({})", partial.string(), output.string(), ec.message()));
    PlacedChunks::discard_undo(partial);

    FinishReport report;
    report.file_bytes = size_of(output);
    report.raw_bytes = tiling.points() * (layout.count_bytes + 1);
    // The result is complete whatever happens to its sidecar: a failure here is a note.
    try {
        const fs::path xmf = write_xdmf(output, info);
        report.sidecar_note = xmf.empty() ? "no XDMF sidecar: " + xdmf_unsupported(output, info) : "sidecar: " + xmf.string();
    } catch (const std::exception& e) {
        report.sidecar_note = std::string("no XDMF sidecar: writing it failed (") + e.what() + ")";
    }
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return report;
}

}  // namespace superball
