// Rank 0's time to record a run of consecutive compressed tiles in the journal
// (tests/scale/calibrate.sh: JOURNAL_US_PER_RUN of the scaling simulation): Journal::record
// writes the tiles' places and checksums into the partial file as they are recorded, one
// write each per run of consecutive tiles. The worst case: 1,048,576 tiles of a 4,194,304-tile file recorded in
// random order (every tile a run of its own), in batches of 16 as the appender's writes
// return them, in a file of the system's temporary directory; the best of 3 passes. Prints
// microseconds a tile (here a run).
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "../io/journal_file.hpp"
#include "io/partial_file.hpp"

int main()
{
    using namespace superball;
    namespace fs = std::filesystem;
    constexpr std::uint64_t tiles = std::uint64_t{1} << 22, recorded = std::uint64_t{1} << 20, batch = 16;
    std::string dir = (fs::temp_directory_path() / "superball-bench-journal-XXXXXX").string();
    if (!mkdtemp(dir.data())) return 1;
    const fs::path path = fs::path(dir) / "partial.h5";
    const PartialLayout layout = test_support::journal_file(path, tiles, true);
    std::vector<AppendedTile> order(tiles);
    for (std::uint64_t t = 0; t < tiles; ++t) order[t] = {t, t * 0x9e3779b97f4a7c15u, {8 * t, 1000, 200}};
    std::shuffle(order.begin(), order.end(), std::mt19937_64(1));
    double best = 1e300;
    {
        PartialFile file(path, Tiling({tiles}, {1}), layout);
        for (int pass = 0; pass < 3; ++pass) {
            Journal journal(file, std::vector<std::uint8_t>(tiles, 0), std::chrono::hours(1));
            const auto start = std::chrono::steady_clock::now();
            for (std::uint64_t i = 0; i < recorded; i += batch) {
                journal.record(std::span<const AppendedTile>(order.data() + (pass * recorded + i) % tiles, batch));
            }
            best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
    }
    fs::remove_all(dir);
    std::printf("%.2f\n", best / static_cast<double>(recorded) * 1e6);
}
