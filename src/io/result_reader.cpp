#include "result_reader.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <tuple>
#include <set>
#include <system_error>

#include "job/job.hpp"
#include "chunk_codec.hpp"
#include "file_identity.hpp"
#include "hdf5.hpp"
#include "layout.hpp"
#include "stored_tiles.hpp"
#include "result_schema.hpp"

namespace superball {

namespace fs = std::filesystem;
using namespace schema;

std::uint64_t ResultInfo::points() const
{
    std::uint64_t n = 1;
    for (const std::uint64_t s : shape) n *= s;
    return n;
}

ResultReader::ResultReader(const fs::path& path) : path_(path), file_(open_hdf5(path))
{
    try {
        validate();
    } catch (const h5::Error& e) {
        // A structure HDF5 itself cannot read (checksums of its metadata, broken links).
        throw FormatError(path.string() + " is damaged: " + e.what());
    }
}

std::vector<double> ResultReader::axis(std::size_t k) const
{
    const std::string name = "/" + info_.axis_names.at(k);
    const Checker check(file_, path_);
    try {
        const h5::Id d = check.dataset(name);
        const h5::Shape s = h5::dataset_shape_of(d);
        if (s.type != h5::TypeClass::floating || s.dims != std::vector<hsize_t>{info_.shape[k]}) {
            check.fail(fmt::format("{} holds {}, not {} floating-point samples (dimension {} of the data)", name,
                                   shape_text(s), info_.shape[k], k));
        }
        check.allocated(d, name);
        std::vector<double> v(info_.shape[k]);
        h5::read(d, std::span(v), name);
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (!std::isfinite(v[i])) check.fail(fmt::format("{} holds {} at {}: samples must be finite", name, v[i], i));
            if (i > 0 && !(v[i] > v[i - 1])) {
                check.fail(fmt::format("{} is not increasing at {} ({} after {})", name, i, v[i], v[i - 1]));
            }
        }
        return v;
    } catch (const h5::Error& e) {
        throw FormatError(path_.string() + ": " + name + " cannot be read (" + e.what() + "); the file is damaged");
    }
}

std::vector<std::uint8_t> ResultReader::tiles_done() const { return done_; }

void ResultReader::load_journal() const
{
    if (journal_loaded_) return;
    sums_.resize(info_.tiles);
    h5::read_rows(h5::open_dataset(file_, layout::tile_checksum), 0, info_.tiles, sums_, layout::tile_checksum);
    if (compressed_) {
        // A window of rows at a time: the places are held once, not twice (24 bytes a tile).
        const h5::Id set = h5::open_dataset(file_, layout::tile_stored);
        constexpr std::uint64_t window = 65536;
        std::vector<std::uint64_t> words;
        stored_.resize(info_.tiles);
        for (std::uint64_t first = 0; first < info_.tiles; first += window) {
            const std::uint64_t n = std::min(window, info_.tiles - first);
            words.resize(3 * n);
            h5::read_rows(set, first, n, words, layout::tile_stored);
            for (std::uint64_t i = 0; i < n; ++i) stored_[first + i] = {words[3 * i], words[3 * i + 1], words[3 * i + 2]};
        }
    }
    journal_loaded_ = true;
}

const PosixFile& ResultReader::raw() const
{
    if (!raw_) raw_.emplace(path_, false);
    return *raw_;
}

void ResultReader::read_stored(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const
{
    const Extent& ts = info_.tile_shape;
    const std::uint64_t n = tiling_->tile_points();
    std::vector<std::uint32_t> chunk_counts(n);
    std::vector<std::uint8_t> chunk_outcomes(n);
    std::vector<std::byte> bytes;
    ChunkDecoder decoder;
    load_journal();
    tiling_->for_each_meeting(box, [&](std::uint64_t t) {
        const Box tb = tiling_->box(t);
        const Box part = intersect(tb, box);
        if (done_[t] == 0) return;  // masked by the caller
        const StoredChunk& c = stored_[t];
        bytes.resize(c.counts_bytes + c.outcomes_bytes);
        raw().read_at(c.address, bytes.data(), bytes.size());
        const std::span<const std::byte> all(bytes);
        if (!decoder.counts(all.first(c.counts_bytes), info_.count_bytes, chunk_counts) ||
            !decoder.outcomes(all.subspan(c.counts_bytes), chunk_outcomes)) {
            throw FormatError(fmt::format("{}: tile {} is recorded done in {}, but its stored chunks (at byte {}) do not "
                                          "decompress to one tile: the file is damaged",
                                          path_.string(), t, layout::tile_done, c.address));
        }
        copy_box(part, reinterpret_cast<const std::byte*>(chunk_counts.data()), tb.start, ts,
                 reinterpret_cast<std::byte*>(counts.data()), box.start, box.count, sizeof(std::uint32_t));
        copy_box(part, reinterpret_cast<const std::byte*>(chunk_outcomes.data()), tb.start, ts,
                 reinterpret_cast<std::byte*>(outcomes.data()), box.start, box.count, 1);
    });
}

bool ResultReader::tile_intact(std::uint64_t t) const
{
    load_journal();
    if (compressed_) {
        const StoredChunk& c = stored_[t];
        std::vector<std::byte> bytes(c.counts_bytes + c.outcomes_bytes);
        try {
            raw().read_at(c.address, bytes.data(), bytes.size());
        } catch (const std::exception&) {
            return false;
        }
        const std::span<const std::byte> all(bytes);
        return tile_checksum(t, all.first(c.counts_bytes), all.subspan(c.counts_bytes)) == sums_[t];
    }
    // The chunks as stored, the bytes the checksum was taken of.
    const std::vector<hsize_t> origin = h5::to_hsize(tiling_->box(t).start);
    std::uint64_t chunk_points = 1;
    for (const std::uint64_t n : info_.tile_shape) chunk_points *= n;
    const std::optional<std::vector<std::byte>> counts = h5::read_raw_chunk(counts_.get(), origin, chunk_points * info_.count_bytes);
    const std::optional<std::vector<std::byte>> outcomes = h5::read_raw_chunk(outcomes_.get(), origin, chunk_points);
    return counts && outcomes && tile_checksum(t, *counts, *outcomes) == sums_[t];
}

std::vector<std::uint64_t> ResultReader::damaged_tiles() const
{
    std::vector<std::uint64_t> bad;
    if (info_.kind != FileKind::partial) return bad;
    for (std::uint64_t t = 0; t < info_.tiles; ++t) {
        if (done_[t] == 0) continue;
        if (tile_intact(t)) {
            verified_[t] = 1;
        } else {
            bad.push_back(t);
        }
    }
    return bad;
}

void ResultReader::verify_tiles(const Box& box) const
{
    if (info_.kind != FileKind::partial || info_.tiles_done == 0) return;
    const std::size_t d = box.count.size();
    const Extent& ts = info_.tile_shape;
    // The tiles the box meets: a box of tile indices.
    Extent first(d), last(d), per_axis(d), index(d);
    for (std::size_t k = 0; k < d; ++k) {
        first[k] = box.start[k] / ts[k];
        last[k] = (box.start[k] + box.count[k] - 1) / ts[k];
        per_axis[k] = (info_.shape[k] + ts[k] - 1) / ts[k];
        index[k] = first[k];
    }
    for (;;) {
        std::uint64_t t = 0;
        for (std::size_t k = 0; k < d; ++k) t = t * per_axis[k] + index[k];
        if (done_[t] != 0 && verified_[t] == 0) {
            if (!tile_intact(t)) {
                const Box b = tiling_->box(t);
                std::vector<std::string> span;
                for (std::size_t k = 0; k < d; ++k) {
                    span.push_back(fmt::format("{} {}..{}", info_.axis_names[k], b.start[k], b.start[k] + b.count[k] - 1));
                }
                throw FormatError(fmt::format(
                    "{}: tile {} ({}) is recorded done in {}, but its data in /wall_bounces and /outcome no longer match {}: "
                    "the file is damaged",
                    path_.string(), t, fmt::join(span, ", "), layout::tile_done, layout::tile_checksum));
            }
            verified_[t] = 1;
        }
        std::size_t k = d;
        while (k-- > 0) {
            if (++index[k] <= last[k]) break;
            index[k] = first[k];
        }
        if (k == static_cast<std::size_t>(-1)) return;
    }
}

std::uint64_t ResultReader::read(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const
{
    // The caller's box: a programming error, not a damaged file.
    bool fits = box.start.size() == info_.shape.size() && box.count.size() == info_.shape.size();
    for (std::size_t k = 0; fits && k < info_.shape.size(); ++k) {
        fits = box.count[k] >= 1 && box.start[k] < info_.shape[k] && box.count[k] <= info_.shape[k] - box.start[k];
    }
    if (!fits || counts.size() != box.points() || outcomes.size() != box.points()) {
        throw std::invalid_argument("ResultReader::read: the box does not fit the data or the buffers");
    }
    try {
        verify_tiles(box);
        return read_checked(box, counts, outcomes);
    } catch (const h5::Error& e) {
        throw FormatError(path_.string() + " cannot be read: " + e.what() + "; the file is damaged");
    }
}

std::uint64_t ResultReader::read_checked(const Box& box, std::span<std::uint32_t> counts,
                                         std::span<std::uint8_t> outcomes) const
{
    const std::vector<hsize_t> start = h5::to_hsize(box.start), count = h5::to_hsize(box.count);
    if (compressed_) {
        read_stored(box, counts, outcomes);
    } else {
        h5::read_box(counts_.get(), start, count, counts, layout::wall_bounces);
        h5::read_box(outcomes_.get(), start, count, outcomes, layout::outcome);
    }
    // Points of tiles not done hold whatever the disk held: mask them, a run of a row at a
    // time (a row of the box crosses a tile every tile_shape.back() points).
    std::vector<std::uint8_t> computed;
    std::uint64_t missing = 0;
    if (info_.kind == FileKind::partial && info_.tiles_done < info_.tiles) {
        const std::size_t d = box.count.size();
        computed.assign(box.points(), 1);
        Extent per_axis(d);
        for (std::size_t k = 0; k < d; ++k) per_axis[k] = (info_.shape[k] + info_.tile_shape[k] - 1) / info_.tile_shape[k];
        const std::uint64_t row = box.count[d - 1], width = info_.tile_shape[d - 1];
        Extent index(d, 0);
        for (std::uint64_t p = 0; p < box.points(); p += row) {
            std::uint64_t prefix = 0;  // the tile's index without its last coordinate
            for (std::size_t k = 0; k + 1 < d; ++k) prefix = prefix * per_axis[k] + (box.start[k] + index[k]) / info_.tile_shape[k];
            for (std::uint64_t j = 0; j < row;) {
                const std::uint64_t column = box.start[d - 1] + j;
                const std::uint64_t end = std::min(row, j + width - column % width);
                if (done_[prefix * per_axis[d - 1] + column / width] == 0) {
                    std::fill(computed.begin() + static_cast<std::ptrdiff_t>(p + j), computed.begin() + static_cast<std::ptrdiff_t>(p + end), 0);
                    std::fill(counts.begin() + static_cast<std::ptrdiff_t>(p + j), counts.begin() + static_cast<std::ptrdiff_t>(p + end), 0u);
                    std::fill(outcomes.begin() + static_cast<std::ptrdiff_t>(p + j), outcomes.begin() + static_cast<std::ptrdiff_t>(p + end), 0);
                    missing += end - j;
                }
                j = end;
            }
            for (std::size_t k = d - 1; k-- > 0;) {
                if (++index[k] < box.count[k]) break;
                index[k] = 0;
            }
        }
    }
    validate_values(box, counts, outcomes, computed);
    return missing;
}

void ResultReader::validate_values(const Box& box, std::span<const std::uint32_t> counts,
                                   std::span<const std::uint8_t> outcomes, std::span<const std::uint8_t> computed) const
{
    const auto max = static_cast<std::uint64_t>(info_.max_bounces);
    for (std::size_t p = 0; p < outcomes.size(); ++p) {
        if (!computed.empty() && computed[p] == 0) continue;
        const std::uint8_t o = outcomes[p];
        const std::uint32_t n = counts[p];
        const bool bad_outcome = o > 3;
        const bool bad_count = o == 0 ? n != 0 : o == 3 ? n != max : n > max;
        if (!bad_outcome && !bad_count) continue;
        // The point's index, for the message.
        Extent at(box.count.size());
        std::uint64_t rest = p;
        for (std::size_t k = box.count.size(); k-- > 0;) {
            at[k] = box.start[k] + rest % box.count[k];
            rest /= box.count[k];
        }
        const std::string where = fmt::format("at ({})", fmt::join(at, ", "));
        if (bad_outcome) {
            throw FormatError(fmt::format("{}: /outcome holds {} {}: outcome codes are 0 to 3 ({}); the file is damaged",
                                          path_.string(), o, where, layout::outcome_meanings));
        }
        throw FormatError(fmt::format("{}: /wall_bounces holds {} {} with outcome {} ({}), which allows {}; the file is damaged",
                                      path_.string(), n, where, o, o == 0 ? "invalid" : o == 3 ? "capped" : o == 1 ? "left" : "missed",
                                      o == 0 ? std::string("0") : o == 3 ? fmt::format("exactly max_bounces = {}", max)
                                                                         : fmt::format("at most max_bounces = {}", max)));
    }
}

OutcomeCounts ResultReader::outcome_counts() const
{
    OutcomeCounts out;
    std::vector<std::uint32_t> counts;
    std::vector<std::uint8_t> outcomes;
    const auto add = [&](const Box& box) {
        counts.resize(box.points());
        outcomes.resize(box.points());
        read(box, counts, outcomes);
        for (const std::uint8_t o : outcomes) ++out.by_outcome[o];
    };
    if (info_.kind == FileKind::partial) {
        // Only the tiles done: an interrupted run of 10^10 points may have done few.
        std::uint64_t computed = 0;
        for (std::uint64_t t = 0; t < info_.tiles; ++t) {
            if (done_[t] == 0) continue;
            const Box box = tiling_->box(t);
            add(box);
            computed += box.points();
        }
        out.not_computed = info_.points() - computed;
        return out;
    }
    // A result: about 16 Mi points at a time.
    for_each_block(info_.shape, std::uint64_t{1} << 24, add);
    return out;
}

void for_each_block(const Extent& shape, std::uint64_t max_points, const std::function<void(const Box&)>& f)
{
    const std::size_t d = shape.size();
    max_points = std::max<std::uint64_t>(1, max_points);
    // Trailing axes whole while they fit, then runs along the next one, leading axes one
    // index at a time: blocks in storage order.
    std::size_t cut = d;
    std::uint64_t whole = 1;
    while (cut > 0 && whole * shape[cut - 1] <= max_points) whole *= shape[--cut];
    if (cut == 0) {
        f(Box{Extent(d, 0), shape});
        return;
    }
    const std::size_t axis = cut - 1;
    const std::uint64_t run = std::max<std::uint64_t>(1, max_points / whole);
    Box box{Extent(d, 0), shape};
    for (std::size_t k = 0; k < axis; ++k) box.count[k] = 1;
    for (;;) {
        for (std::uint64_t first = 0; first < shape[axis]; first += run) {
            box.start[axis] = first;
            box.count[axis] = std::min(run, shape[axis] - first);
            f(box);
        }
        std::size_t k = axis;
        while (k-- > 0) {
            if (++box.start[k] < shape[k]) break;
            box.start[k] = 0;
        }
        if (k == static_cast<std::size_t>(-1)) return;
    }
}

}  // namespace superball
