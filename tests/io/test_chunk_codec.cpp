// The chunks' stored form (io/chunk_codec.hpp): what the encoder writes decodes to the
// values, for 16- and 32-bit counts and outcome codes; a chunk of equal values (kept after
// its first encoding) is the same stream a fresh encoder writes; damaged or short streams
// are refused. That HDF5 itself reads the stream through its filters: test_placed_chunks.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "io/chunk_codec.hpp"

namespace superball {
namespace {

std::vector<std::uint32_t> banded(std::size_t n, std::uint32_t top, std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::vector<std::uint32_t> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint32_t>((i / 37 + rng() % 3) % (top + 1));
    return v;
}

TEST(ChunkCodec, CountsRoundTripAtEveryWidthAndLevel)
{
    for (const int level : {1, 4, 9}) {
        ChunkEncoder encoder(level);
        ChunkDecoder decoder;
        for (const std::size_t bytes : {std::size_t{2}, std::size_t{4}}) {
            const std::vector<std::uint32_t> values = banded(4096, bytes == 2 ? 65535 : 4000000000u, 7);
            std::vector<std::byte> stored(3, std::byte{0x55});  // appended after what is there
            const std::size_t n = encoder.counts(values, bytes, stored);
            ASSERT_EQ(stored.size(), 3 + n);
            EXPECT_LT(n, values.size() * bytes);
            std::vector<std::uint32_t> back(values.size(), 1);
            ASSERT_TRUE(decoder.counts(std::span(stored).subspan(3), bytes, back)) << level << " " << bytes;
            EXPECT_EQ(back, values);
        }
    }
}

TEST(ChunkCodec, OutcomesRoundTrip)
{
    ChunkEncoder encoder(4);
    ChunkDecoder decoder;
    std::vector<std::uint8_t> codes(1000);
    for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = static_cast<std::uint8_t>((i * i / 91) % 4);
    std::vector<std::byte> stored;
    encoder.outcomes(codes, stored);
    std::vector<std::uint8_t> back(codes.size());
    ASSERT_TRUE(decoder.outcomes(stored, back));
    EXPECT_EQ(back, codes);
}

TEST(ChunkCodec, EqualValuesGiveTheStreamAFreshEncoderWrites)
{
    ChunkEncoder kept(4);
    std::vector<std::byte> first, again, other;
    const std::vector<std::uint32_t> zeros(1024, 0), sevens(1024, 7);
    kept.counts(zeros, 2, first);
    kept.counts(sevens, 2, other);
    kept.counts(zeros, 2, again);  // from what was kept
    EXPECT_EQ(first, again);
    ChunkEncoder fresh(4);
    std::vector<std::byte> sevens_fresh;
    fresh.counts(sevens, 2, sevens_fresh);
    EXPECT_EQ(other, sevens_fresh);
    // The same value at another width or length is another stream.
    std::vector<std::byte> wide, shorter;
    kept.counts(zeros, 4, wide);
    kept.counts(std::vector<std::uint32_t>(512, 0), 2, shorter);
    ChunkDecoder decoder;
    std::vector<std::uint32_t> back(1024, 9);
    ASSERT_TRUE(decoder.counts(wide, 4, back));
    EXPECT_EQ(back, zeros);
    EXPECT_FALSE(decoder.counts(shorter, 2, back)) << "512 values are not 1024";
}

TEST(ChunkCodec, DamagedOrShortStreamsAreRefused)
{
    ChunkEncoder encoder(4);
    ChunkDecoder decoder;
    const std::vector<std::uint32_t> values = banded(2048, 1000, 3);
    std::vector<std::byte> stored;
    encoder.counts(values, 2, stored);
    std::vector<std::uint32_t> back(values.size());
    EXPECT_FALSE(decoder.counts(std::span(stored).first(stored.size() / 2), 2, back));
    std::vector<std::byte> flipped = stored;
    flipped[flipped.size() / 2] ^= std::byte{0x40};
    EXPECT_FALSE(decoder.counts(flipped, 2, back));  // the zlib stream's Adler-32 or its codes
    EXPECT_FALSE(decoder.counts(stored, 2, std::span(back).first(1000)));  // more values than asked for
    EXPECT_THROW(ChunkEncoder(0), std::invalid_argument);
    EXPECT_THROW(ChunkEncoder(10), std::invalid_argument);
}

}  // namespace
}  // namespace superball
