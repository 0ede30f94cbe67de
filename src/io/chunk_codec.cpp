#include "chunk_codec.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <new>
#include <string>
#include <stdexcept>

namespace superball {

namespace {

// Shuffles `n` values of `bytes` bytes each (little-endian, as the file stores them) into
// `out`: byte k of value i goes to out[k n + i]. Written from the values, not from their
// bytes in memory, so the stored form does not depend on the host's byte order.
void shuffle(std::span<const std::uint32_t> values, std::size_t bytes, std::uint8_t* out)
{
    const std::size_t n = values.size();
    for (std::size_t k = 0; k < bytes; ++k) {
        std::uint8_t* o = out + k * n;
        const unsigned shift = 8 * static_cast<unsigned>(k);
        for (std::size_t i = 0; i < n; ++i) o[i] = static_cast<std::uint8_t>(values[i] >> shift);
    }
}

}  // namespace

void ChunkEncoder::Free::operator()(void* c) const noexcept { libdeflate_free_compressor(static_cast<libdeflate_compressor*>(c)); }
void ChunkDecoder::Free::operator()(void* d) const noexcept
{
    libdeflate_free_decompressor(static_cast<libdeflate_decompressor*>(d));
}

ChunkEncoder::ChunkEncoder(int level)
{
    if (level < 1 || level > 9) throw std::invalid_argument("ChunkEncoder: deflate level " + std::to_string(level));
    compressor_.reset(libdeflate_alloc_compressor(level));
    if (!compressor_) throw std::bad_alloc();
}

std::size_t ChunkEncoder::deflate(std::span<const std::uint8_t> in, std::vector<std::byte>& out)
{
    auto* c = static_cast<libdeflate_compressor*>(compressor_.get());
    // Into a buffer kept between chunks, then only the stream's bytes onto `out`: growing
    // `out` by the bound would zero it for every chunk (about 3 % of counting's time).
    const std::size_t bound = libdeflate_zlib_compress_bound(c, in.size());
    if (stream_.size() < bound) stream_.resize(bound);
    const std::size_t n = libdeflate_zlib_compress(c, in.data(), in.size(), stream_.data(), stream_.size());
    // The bound is libdeflate's own: a chunk always fits it.
    if (n == 0) throw std::logic_error("libdeflate_zlib_compress: the output did not fit its own bound");
    out.insert(out.end(), stream_.begin(), stream_.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
}

std::size_t ChunkEncoder::constant(std::uint32_t value, std::size_t n, std::size_t value_bytes,
                                   std::span<const std::uint8_t> shuffled, std::vector<std::byte>& out)
{
    const auto key = std::tuple{value, n, value_bytes};
    auto it = constants_.find(key);
    if (it == constants_.end()) {
        if (constants_.size() >= 64) constants_.clear();  // a bound; real runs see a handful
        std::vector<std::byte> stored;
        deflate(shuffled, stored);
        it = constants_.emplace(key, std::move(stored)).first;
    }
    out.insert(out.end(), it->second.begin(), it->second.end());
    return it->second.size();
}

std::size_t ChunkEncoder::counts(std::span<const std::uint32_t> values, std::size_t count_bytes, std::vector<std::byte>& out)
{
    const std::size_t n = values.size();
    shuffled_.resize(n * count_bytes);
    const bool flat = n > 0 && std::all_of(values.begin(), values.end(), [v = values[0]](std::uint32_t x) { return x == v; });
    if (flat) {
        for (std::size_t k = 0; k < count_bytes; ++k) {
            std::fill_n(shuffled_.begin() + static_cast<std::ptrdiff_t>(k * n), n, static_cast<std::uint8_t>(values[0] >> (8 * k)));
        }
        return constant(values[0], n, count_bytes, shuffled_, out);
    }
    shuffle(values, count_bytes, shuffled_.data());
    return deflate(shuffled_, out);
}

std::size_t ChunkEncoder::outcomes(std::span<const std::uint8_t> values, std::vector<std::byte>& out)
{
    if (!values.empty() && std::all_of(values.begin(), values.end(), [v = values[0]](std::uint8_t x) { return x == v; })) {
        return constant(values[0], values.size(), 1, values, out);
    }
    return deflate(values, out);
}

ChunkDecoder::ChunkDecoder() : decompressor_(libdeflate_alloc_decompressor())
{
    if (!decompressor_) throw std::bad_alloc();
}

bool ChunkDecoder::inflate(std::span<const std::byte> stored, std::span<std::uint8_t> out)
{
    std::size_t n = 0;
    const libdeflate_result r = libdeflate_zlib_decompress(static_cast<libdeflate_decompressor*>(decompressor_.get()),
                                                           stored.data(), stored.size(), out.data(), out.size(), &n);
    return r == LIBDEFLATE_SUCCESS && n == out.size();
}

bool ChunkDecoder::counts(std::span<const std::byte> stored, std::size_t count_bytes, std::span<std::uint32_t> values)
{
    const std::size_t n = values.size();
    shuffled_.resize(n * count_bytes);
    if (!inflate(stored, shuffled_)) return false;
    std::fill(values.begin(), values.end(), 0u);
    for (std::size_t k = 0; k < count_bytes; ++k) {
        const std::uint8_t* in = shuffled_.data() + k * n;
        const unsigned shift = 8 * static_cast<unsigned>(k);
        for (std::size_t i = 0; i < n; ++i) values[i] |= static_cast<std::uint32_t>(in[i]) << shift;
    }
    return true;
}

bool ChunkDecoder::outcomes(std::span<const std::byte> stored, std::span<std::uint8_t> values) { return inflate(stored, values); }

}  // namespace superball
