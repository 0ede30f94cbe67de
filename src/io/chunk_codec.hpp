// A chunk of the result as HDF5's filter pipeline stores it: the shuffle filter (the
// bytes of the values grouped by significance: every value's lowest byte, then every
// value's next byte...), then the deflate filter (a zlib stream, RFC 1950). A chunk so
// encoded is written as it is (io/placed_chunks.hpp) and read back by every HDF5 reader
// (h5py, netCDF-4, ParaView) through the pipeline the dataset declares, with no plugin.
//
// The encoder is libdeflate (Debian's libdeflate-dev): it writes the standard zlib stream
// that zlib's inflate reads, three to four times faster than zlib's own deflate at the
// levels a result uses (tests/bench: 650 against 210-300 MB/s of raw data on the benchmark
// slice), so a rank compresses each tile from memory as it is counted instead of a
// closing pass reading the whole result back.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

namespace superball {

class ChunkEncoder {
public:
    // level: the deflate level, 1 (fastest) to 9 (smallest), as HDF5's deflate filter and
    // `[run] compression` count them.
    explicit ChunkEncoder(int level);

    // Appends the stored form of a chunk of counts (`count_bytes` 2 or 4 per value in the
    // file, little-endian, shuffled, deflated) to `out`; returns its size in bytes. Values
    // must fit `count_bytes`.
    std::size_t counts(std::span<const std::uint32_t> values, std::size_t count_bytes, std::vector<std::byte>& out);
    // Likewise for a chunk of outcome codes (one byte each: the shuffle leaves them as
    // they are).
    std::size_t outcomes(std::span<const std::uint8_t> values, std::vector<std::byte>& out);

private:
    std::size_t deflate(std::span<const std::uint8_t> in, std::vector<std::byte>& out);
    // A chunk whose values are all equal (a region of one outcome: every launch beyond the
    // wall misses it) compresses to the same bytes every time: kept after the first, so
    // a run of 1024-point tiles over such a region costs a lookup per tile, not a deflate.
    std::size_t constant(std::uint32_t value, std::size_t n, std::size_t value_bytes, std::span<const std::uint8_t> shuffled,
                         std::vector<std::byte>& out);

    struct Free {
        void operator()(void* c) const noexcept;
    };
    std::unique_ptr<void, Free> compressor_;  // a libdeflate_compressor
    std::vector<std::uint8_t> shuffled_;
    std::vector<std::byte> stream_;
    // (value, points, bytes per value) -> stored chunk; a few entries at most in practice,
    // bounded below.
    std::map<std::tuple<std::uint32_t, std::size_t, std::size_t>, std::vector<std::byte>> constants_;
};

class ChunkDecoder {
public:
    ChunkDecoder();

    // Decodes a stored chunk of counts into `values` (its size is the chunk's points);
    // false if the bytes are not a zlib stream of exactly that many values.
    bool counts(std::span<const std::byte> stored, std::size_t count_bytes, std::span<std::uint32_t> values);
    bool outcomes(std::span<const std::byte> stored, std::span<std::uint8_t> values);

private:
    bool inflate(std::span<const std::byte> stored, std::span<std::uint8_t> out);

    struct Free {
        void operator()(void* d) const noexcept;
    };
    std::unique_ptr<void, Free> decompressor_;  // a libdeflate_decompressor
    std::vector<std::uint8_t> shuffled_;
};

}  // namespace superball
