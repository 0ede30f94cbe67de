// How fast rank 0 copies the compressed tiles it receives (tests/scale/calibrate.sh:
// COPY_GBPS of the scaling simulation): explore's on_done unpacks each payload
// (TileBatch::unpack, a copy into a vector of its own) and ChunkAppender::add copies it into
// an 8 MiB append buffer. Batches of 64 KiB, 1 MiB and 4 MiB, 2 GiB of payload each, the
// best of 5 passes; prints GB/s of payload (both copies) for each, then the slowest of them.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

int main()
{
    double slowest = 1e300;
    for (const std::size_t batch : {std::size_t{64} << 10, std::size_t{1} << 20, std::size_t{4} << 20}) {
        const std::vector<char> message(batch, 1);
        std::vector<char> buffer(std::size_t{8} << 20);
        double best = 1e300;
        constexpr std::size_t total = std::size_t{2} << 30;
        for (int pass = 0; pass < 5; ++pass) {
            const auto start = std::chrono::steady_clock::now();
            std::size_t at = 0;
            for (std::size_t done = 0; done < total; done += batch) {
                const std::vector<char> unpacked(message.begin(), message.end());
                if (at + batch > buffer.size()) at = 0;
                std::memcpy(buffer.data() + at, unpacked.data(), batch);
                at += batch;
            }
            best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
            volatile char sink = buffer[at / 2];
            (void)sink;
        }
        const double gbps = static_cast<double>(total) / best / 1e9;
        std::printf("batch %zu bytes: %.2f GB/s of payload\n", batch, gbps);
        slowest = std::min(slowest, gbps);
    }
    std::printf("%.2f\n", slowest);
}
