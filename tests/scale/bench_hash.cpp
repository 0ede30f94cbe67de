// How fast a rank checks done tiles on a resume (tests/scale/calibrate.sh: HASH_GBPS of the
// scaling simulation): PartialFile::damaged reads each done tile's stored chunks and hashes
// them (tile_checksum, XXH3). Chunks of 4 KiB, 16 KiB and 64 KiB (compressed tiles of the
// cluster jobs), 1 GiB of them each, the best of 5 passes; prints GB/s for each, then the
// slowest of them.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "io/stored_tiles.hpp"

int main()
{
    double slowest = 1e300;
    for (const std::size_t chunk : {std::size_t{4} << 10, std::size_t{16} << 10, std::size_t{64} << 10}) {
        std::vector<std::byte> data(std::size_t{64} << 20);
        for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::byte>(i * 2654435761u >> 13);
        constexpr std::size_t total = std::size_t{1} << 30;
        double best = 1e300;
        std::uint64_t sum = 0;
        for (int pass = 0; pass < 5; ++pass) {
            const auto start = std::chrono::steady_clock::now();
            std::size_t at = 0;
            for (std::size_t done = 0, tile = 0; done < total; done += chunk, ++tile) {
                if (at + chunk > data.size()) at = 0;
                const std::span<const std::byte> c(data.data() + at, chunk);
                sum += superball::tile_checksum(tile, c.first(chunk / 2), c.subspan(chunk / 2));
                at += chunk;
            }
            best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
        const double gbps = static_cast<double>(total) / best / 1e9;
        std::printf("chunk %zu bytes: %.2f GB/s (checksums %llx)\n", chunk, gbps, static_cast<unsigned long long>(sum));
        slowest = std::min(slowest, gbps);
    }
    std::printf("%.2f\n", slowest);
}
