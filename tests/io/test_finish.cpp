// A run's partial file made its result (io/final_result.hpp), in one process, through the
// writer's own path (create_partial, ChunkAppender, Journal): the result reads back every
// tile's values, the partial file is gone and the sidecar written; tiles recorded in an
// order other than the file's, in several writes, change nothing; a tile not done is
// refused and the partial file left whole.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "io/chunk_codec.hpp"
#include "io/final_result.hpp"
#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/result_metadata.hpp"
#include "io/result_reader.hpp"
#include "io/stored_tiles.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "../temp_dir.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

Job small_job()
{
    return parse_job("[model]\ne = 0.9\nalpha = 0.9\n[grid]\ncoordinates = \"canonical\"\n"
                     "xi = { min = 0.1, max = 0.9, n = 21 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 13 }\n"
                     "[run]\nmax_bounces = 500\ntile_points = 16\n",
                     "test.toml");
}

// The values of tile t's points, row-major over its box: a pattern of its own.
void values_of(const Tiling& tiling, std::uint64_t t, std::vector<std::uint32_t>& counts, std::vector<std::uint8_t>& outcomes)
{
    const std::uint64_t n = tiling.box(t).points();
    counts.resize(n);
    outcomes.resize(n);
    for (std::uint64_t i = 0; i < n; ++i) {
        counts[i] = static_cast<std::uint32_t>((t * 37 + i * 11) % 400 + 1);
        outcomes[i] = i % 5 == 0 ? 2 : 1;  // missed or left: any count up to max_bounces
    }
}

struct Made {
    Tiling tiling;
    PartialLayout layout;
    std::vector<std::uint8_t> done;
};

// The partial file at `partial` with the tiles `order` written (in writes of `per_write`
// tiles) and recorded as rank 0 does.
Made write_partial(const fs::path& partial, const Job& job, const std::vector<std::uint64_t>& order, std::size_t per_write)
{
    const Grid grid(job);
    Made m{default_tiling(job, 1), {}, {}};
    Provenance run;
    run.command = "test";
    m.layout = create_partial(partial, job, grid, m.tiling, run);
    EXPECT_TRUE(m.layout.compressed);
    PartialFile file(partial, m.tiling, m.layout);
    ChunkAppender appender(file, file.file().size(), 1 << 20);
    Journal journal(file, std::vector<std::uint8_t>(m.tiling.tiles(), 0), std::chrono::hours(1));
    ChunkEncoder encoder(static_cast<int>(m.layout.level));
    std::vector<std::uint32_t> counts, padded_counts;
    std::vector<std::uint8_t> outcomes, padded_outcomes;
    for (std::size_t first = 0; first < order.size(); first += per_write) {
        TileBatch batch;
        for (std::size_t k = first; k < std::min(order.size(), first + per_write); ++k) {
            const std::uint64_t t = order[k];
            values_of(m.tiling, t, counts, outcomes);
            const auto c = in_chunk_layout<std::uint32_t>(m.tiling, t, counts, padded_counts);
            const auto o = in_chunk_layout<std::uint8_t>(m.tiling, t, outcomes, padded_outcomes);
            const std::size_t at = batch.data.size();
            const std::size_t cb = encoder.counts(c, m.layout.count_bytes, batch.data);
            const std::size_t ob = encoder.outcomes(o, batch.data);
            const std::span<const std::byte> stored(batch.data.data() + at, cb + ob);
            batch.entries.insert(batch.entries.end(), {t, tile_checksum(t, stored.first(cb), stored.subspan(cb)), cb, ob});
        }
        appender.add(batch);
        journal.record(appender.flush());
    }
    journal.checkpoint(true);
    file.close();
    m.done.assign(journal.done().begin(), journal.done().end());
    return m;
}

void expect_values(const fs::path& result, const Tiling& tiling)
{
    const ResultReader reader(result);
    ASSERT_TRUE(reader.info().complete);
    std::vector<std::uint32_t> counts, want_counts;
    std::vector<std::uint8_t> outcomes, want_outcomes;
    for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
        const Box box = tiling.box(t);
        counts.assign(box.points(), 0);
        outcomes.assign(box.points(), 0);
        reader.read(box, counts, outcomes);
        values_of(tiling, t, want_counts, want_outcomes);
        ASSERT_EQ(counts, want_counts) << "tile " << t;
        ASSERT_EQ(outcomes, want_outcomes) << "tile " << t;
    }
}

TEST(FinishResult, EveryTileReadsBackWhereverAndHoweverItWasWritten)
{
    const Job job = small_job();
    const Grid grid(job);
    const Tiling tiling = default_tiling(job, 1);
    ASSERT_GT(tiling.tiles(), 8u);
    std::vector<std::uint64_t> in_order(tiling.tiles()), reversed(tiling.tiles());
    std::iota(in_order.begin(), in_order.end(), 0);
    std::iota(reversed.rbegin(), reversed.rend(), 0);
    for (const auto& [order, per_write] : {std::pair{in_order, std::size_t{1000}}, std::pair{reversed, std::size_t{3}}}) {
        const test_support::TempDir dir("superball-finish");
        const fs::path output = dir / "result.h5", partial = layout::partial_path(output);
        const Made m = write_partial(partial, job, order, per_write);
        Provenance run;
        run.command = "test";
        const FinishReport r = finish_result(partial, output, result_info(job, grid), m.tiling, m.layout, m.done, {run, 1.5, true});
        EXPECT_FALSE(fs::exists(partial));
        EXPECT_TRUE(fs::exists(output));
        EXPECT_EQ(r.file_bytes, fs::file_size(output));
        EXPECT_EQ(r.raw_bytes, grid.shape()[0] * grid.shape()[1] * 3);
        EXPECT_NE(r.sidecar_note.find("sidecar: "), std::string::npos) << r.sidecar_note;
        EXPECT_TRUE(fs::exists(layout::sidecar_path(output)));
        expect_values(output, m.tiling);
        EXPECT_DOUBLE_EQ(ResultReader(output).info().wall_seconds, 1.5);
    }
}

TEST(FinishResult, ATileNotDoneIsRefusedAndThePartialFileKept)
{
    const Job job = small_job();
    const Grid grid(job);
    const test_support::TempDir dir("superball-finish");
    const fs::path output = dir / "result.h5", partial = layout::partial_path(output);
    const Tiling tiling = default_tiling(job, 1);
    std::vector<std::uint64_t> all_but_one;
    for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
        if (t != 5) all_but_one.push_back(t);
    }
    const Made m = write_partial(partial, job, all_but_one, 4);
    const auto bytes = fs::file_size(partial);
    Provenance run;
    try {
        finish_result(partial, output, result_info(job, grid), m.tiling, m.layout, m.done, {run, 1.0, true});
        FAIL() << "finished with tile 5 not done";
    } catch (const std::logic_error& e) {
        EXPECT_NE(std::string(e.what()).find("tile 5 is not done"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(output));
    EXPECT_EQ(fs::file_size(partial), bytes);
    EXPECT_EQ(ResultReader(partial).info().tiles_done, tiling.tiles() - 1);
}

}  // namespace
}  // namespace superball
