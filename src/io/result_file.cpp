#include "result_file.hpp"

#include <fmt/core.h>
#include <sys/statvfs.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <initializer_list>

#include "superball/version.hpp"

namespace superball {

namespace {

h5::Id mpio_access(const mpi::Comm& comm)
{
    h5::Id fapl = h5::plist_id(H5Pcreate(H5P_FILE_ACCESS), "H5Pcreate");
    h5::check(H5Pset_fapl_mpio(fapl, comm.get(), MPI_INFO_NULL), "H5Pset_fapl_mpio");
    // Metadata written by one rank, read by one rank and broadcast: the file's metadata
    // is small and every rank touches the same.
    h5::check(H5Pset_coll_metadata_write(fapl, true), "H5Pset_coll_metadata_write");
    // HDF5 1.10 format: chunks of a fixed-size dataset are indexed by a fixed array
    // instead of a B-tree, whose in-memory cost grew with the number of tiles (measured:
    // +12 MiB per rank for 16384 tiles). h5py, h5dump and ParaView read it.
    h5::check(H5Pset_libver_bounds(fapl, H5F_LIBVER_V110, H5F_LIBVER_LATEST), "H5Pset_libver_bounds");
    return fapl;
}

std::vector<hsize_t> to_hsize(const Extent& e) { return {e.begin(), e.end()}; }

// A dataset whose chunks are the tiles, all allocated at creation (required for
// independent parallel writes, and what keeps the metadata fixed during the run). No
// fill: tile_done says which values are meaningful.
h5::Id create_tiled(hid_t file, const char* name, hid_t type, const Tiling& tiling)
{
    const auto dims = to_hsize(tiling.shape());
    const auto chunk = to_hsize(tiling.tile_shape());
    const h5::Id space = h5::space_id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), "H5Screate");
    const h5::Id dcpl = h5::plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
    h5::check(H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data()), "H5Pset_chunk");
    h5::check(H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY), "H5Pset_alloc_time");
    h5::check(H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER), "H5Pset_fill_time");
    return h5::dataset_id(H5Dcreate2(file, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), name);
}

h5::Id create_1d(hid_t loc, const char* name, hid_t type, hsize_t n)
{
    const h5::Id space = h5::space_id(H5Screate_simple(1, &n, nullptr), "H5Screate");
    const h5::Id dcpl = h5::plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
    h5::check(H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY), "H5Pset_alloc_time");
    h5::check(H5Pset_fill_time(dcpl, H5D_FILL_TIME_ALLOC), "H5Pset_fill_time");  // zeros: no tile done yet
    return h5::dataset_id(H5Dcreate2(loc, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), name);
}

// Writes `data` over the hyperslab `box` of `dataset` (independent transfer).
template <class T>
void write_box(hid_t dataset, hid_t memtype, const Box& box, std::span<const T> data)
{
    const auto start = to_hsize(box.start);
    const auto count = to_hsize(box.count);
    const int rank = static_cast<int>(count.size());
    const h5::Id mem = h5::space_id(H5Screate_simple(rank, count.data(), nullptr), "H5Screate");
    const h5::Id file = h5::space_id(H5Dget_space(dataset), "H5Dget_space");
    h5::check(H5Sselect_hyperslab(file, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), "H5Sselect_hyperslab");
    h5::check(H5Dwrite(dataset, memtype, mem, file, H5P_DEFAULT, data.data()), "H5Dwrite");
}

// Reads the hyperslab `box` of `dataset` into `data`, converted to `memtype`.
template <class T>
void read_box(hid_t dataset, hid_t memtype, const Box& box, std::vector<T>& data)
{
    const auto start = to_hsize(box.start);
    const auto count = to_hsize(box.count);
    data.resize(box.points());
    const h5::Id mem = h5::space_id(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), "H5Screate");
    const h5::Id file = h5::space_id(H5Dget_space(dataset), "H5Dget_space");
    h5::check(H5Sselect_hyperslab(file, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), "H5Sselect_hyperslab");
    h5::check(H5Dread(dataset, memtype, mem, file, H5P_DEFAULT, data.data()), "H5Dread");
}

// Lets a parallel file go unclosed when an exception leaves the scope (see ~ResultFile).
struct ReleaseOnThrow {
    h5::Id& id;
    int exceptions = std::uncaught_exceptions();
    explicit ReleaseOnThrow(h5::Id& file) : id(file) {}
    ReleaseOnThrow(const ReleaseOnThrow&) = delete;
    ReleaseOnThrow& operator=(const ReleaseOnThrow&) = delete;
    ~ReleaseOnThrow()
    {
        if (std::uncaught_exceptions() > exceptions) id.release();
    }
};

bool has_link(hid_t loc, const char* name) { return h5::check(H5Lexists(loc, name, H5P_DEFAULT), name) > 0; }

// Why a write may have failed, when the file system can tell: "" or "; only N bytes free ...".
std::string free_space_note(const std::filesystem::path& path)
{
    struct statvfs fs{};
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    if (statvfs(dir.c_str(), &fs) != 0) return "";
    if (fs.f_flag & ST_RDONLY) return "; the file system holding it is read-only";
    const auto free_bytes = static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize;
    if (free_bytes >= (1ull << 20)) return "";
    return fmt::format("; the file system holding it is full ({} bytes free)", free_bytes);
}

Tiling tiling_of(hid_t file)
{
    const h5::Id d = h5::dataset_id(H5Dopen2(file, "/wall_bounces", H5P_DEFAULT), "open /wall_bounces");
    const auto dims = h5::dataset_shape(d);
    return Tiling(Extent(dims.begin(), dims.end()), h5::read_u64_vector_attribute(file, "tile_shape"));
}

}  // namespace

std::uint64_t tile_checksum(std::uint64_t tile, std::span<const std::uint32_t> counts,
                            std::span<const std::uint8_t> outcomes)
{
    constexpr std::uint64_t k = 0x9E3779B97F4A7C15ull;
    const auto step = [](std::uint64_t h, std::uint64_t word) {
        h = (h ^ word) * k;
        return h ^ (h >> 29);
    };
    // Word j of the stream (counts two to a word, then outcomes eight to a word) goes to
    // lane j mod 4; blocks of four words keep the lanes in registers.
    std::uint64_t l0 = tile, l1 = counts.size(), l2 = outcomes.size(), l3 = 0x243F6A8885A308D3ull;
    std::size_t w = 0;
    const auto mix = [&](std::uint64_t word) {
        switch (w++ & 3) {
            case 0: l0 = step(l0, word); break;
            case 1: l1 = step(l1, word); break;
            case 2: l2 = step(l2, word); break;
            default: l3 = step(l3, word); break;
        }
    };
    const auto pair = [&](std::size_t i) { return counts[i] | std::uint64_t{counts[i + 1]} << 32; };
    std::size_t i = 0;
    for (; i + 8 <= counts.size(); i += 8, w += 4) {
        l0 = step(l0, pair(i));
        l1 = step(l1, pair(i + 2));
        l2 = step(l2, pair(i + 4));
        l3 = step(l3, pair(i + 6));
    }
    for (; i + 2 <= counts.size(); i += 2) mix(pair(i));
    if (i < counts.size()) mix(counts[i]);
    const auto octet = [&](std::size_t j) {
        std::uint64_t word;
        std::memcpy(&word, outcomes.data() + j, sizeof word);
        return word;
    };
    for (i = 0; i + 8 <= outcomes.size() && (w & 3) != 0; i += 8) mix(octet(i));
    for (; i + 32 <= outcomes.size(); i += 32, w += 4) {
        l0 = step(l0, octet(i));
        l1 = step(l1, octet(i + 8));
        l2 = step(l2, octet(i + 16));
        l3 = step(l3, octet(i + 24));
    }
    for (; i + 8 <= outcomes.size(); i += 8) mix(octet(i));
    for (; i < outcomes.size(); ++i) mix(outcomes[i]);
    std::uint64_t h = 0;
    for (const std::uint64_t l : {l0, l1, l2, l3}) h = step(h, l);
    return h;
}

ResultFile::ResultFile(h5::Id file, Tiling tiling, std::filesystem::path path)
    : file_(std::move(file)),
      wall_bounces_(h5::dataset_id(H5Dopen2(file_, "/wall_bounces", H5P_DEFAULT), "open /wall_bounces")),
      outcome_(h5::dataset_id(H5Dopen2(file_, "/outcome", H5P_DEFAULT), "open /outcome")),
      tile_done_(h5::dataset_id(H5Dopen2(file_, "/progress/tile_done", H5P_DEFAULT), "open /progress/tile_done")),
      tiling_(std::move(tiling)),
      path_(std::move(path))
{
    if (has_link(file_, "/progress/tile_checksum")) {
        tile_checksum_ = h5::dataset_id(H5Dopen2(file_, "/progress/tile_checksum", H5P_DEFAULT), "open /progress/tile_checksum");
    }
    const h5::Id type = h5::type_id(H5Dget_type(wall_bounces_), "H5Dget_type");
    narrow_counts_ = H5Tget_size(type) == 2;
}

ResultFile::~ResultFile()
{
    if (std::uncaught_exceptions() == 0) return;  // closed by finish(), or closing normally
    for (h5::Id* id : {&tile_checksum_, &tile_done_, &outcome_, &wall_bounces_, &file_}) id->release();
}

ResultFile ResultFile::create(const std::filesystem::path& path, const mpi::Comm& comm, const Job& job, const Grid& grid,
                              const Tiling& tiling)
try {
    const h5::Id fapl = mpio_access(comm);
    h5::Id file = h5::file_id(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), "create " + path.string());
    const ReleaseOnThrow release_on_throw{file};

    // Counts never exceed max_bounces: 16 bits unless that is too few.
    const hid_t count_type = job.max_bounces > 65535 ? H5T_STD_U32LE : H5T_STD_U16LE;
    create_tiled(file, "/wall_bounces", count_type, tiling);
    create_tiled(file, "/outcome", H5T_STD_U8LE, tiling);
    {
        const h5::Id progress = h5::group_id(H5Gcreate2(file, "/progress", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/progress");
        create_1d(progress, "tile_done", H5T_STD_U8LE, tiling.tiles());
        create_1d(progress, "tile_checksum", H5T_STD_U64LE, tiling.tiles());
    }

    const h5::Id axes = h5::group_id(H5Gcreate2(file, "/axes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/axes");
    for (const Coordinate& c : job.grid) {
        if (!c.is_range()) h5::write_attribute(file, "fixed_" + c.name, *c.fixed);
    }
    std::vector<std::string> axis_names;
    const std::vector<const Coordinate*> ranges = job.range_axes();
    for (std::size_t k = 0; k < ranges.size(); ++k) {
        const std::string& name = ranges[k]->name;
        axis_names.push_back(name);
        const std::vector<double>& s = grid.samples(k);
        const h5::Id d = create_1d(axes, name.c_str(), H5T_IEEE_F64LE, s.size());
        // Raw data: one rank writes it, the others take part in nothing.
        if (comm.is_root()) {
            h5::check(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data()), "write axis " + name);
        }
    }

    h5::write_attribute(file, "coordinates", std::string(name(job.coordinates)));
    h5::write_attribute(file, "axis_names", axis_names);
    // A swept coefficient has no single value: its attribute names the axis instead
    // ("axis:e"), and `swept` lists the coefficient axes.
    const std::pair<const char*, double> coefficients[] = {{"e_wall", job.model.wall.e},
                                                           {"alpha_wall", job.model.wall.alpha},
                                                           {"e_floor", job.model.floor.e},
                                                           {"alpha_floor", job.model.floor.alpha}};
    for (std::size_t c = 0; c < 4; ++c) {
        const auto [key, value] = coefficients[c];
        if (job.swept[c] < 0) {
            h5::write_attribute(file, key, value);
        } else {
            h5::write_attribute(file, key, "axis:" + job.parameters[static_cast<std::size_t>(job.swept[c])].name);
        }
    }
    if (!job.parameters.empty()) {
        std::vector<std::string> swept;
        for (const Coordinate& p : job.parameters) swept.push_back(p.name);
        h5::write_attribute(file, "swept", swept);
    }
    if (job.coordinates == Coordinates::physical) {
        h5::write_attribute(file, "g", job.frame.g);
        h5::write_attribute(file, "radius", job.frame.radius);
    }
    h5::write_attribute(file, "max_bounces", static_cast<std::int64_t>(job.max_bounces));
    // 0: every point computed; s: adaptive refinement from every s-th point.
    h5::write_attribute(file, "refine", static_cast<std::int64_t>(job.refine));
    h5::write_attribute(file, "job_toml", job.text);
    h5::write_attribute(file, "job_fingerprint", fingerprint(job));
    h5::write_attribute(file, "software_version", std::string(software_version));
    h5::write_attribute(file, "tile_shape", tiling.tile_shape());
    h5::write_attribute(file, "mpi_ranks", static_cast<std::int64_t>(comm.size()));
    h5::write_attribute(file, "wall_seconds", 0.0);
    h5::write_attribute(file, "complete", std::int64_t{0});
    // From here on the metadata is final until finish(): make it durable before any tile.
    h5::check(H5Fflush(file, H5F_SCOPE_GLOBAL), "H5Fflush");
    return ResultFile(std::move(file), tiling, path);
} catch (const h5::Error& e) {
    throw h5::Error(fmt::format("creating {} failed ({}){}", path.string(), e.what(), free_space_note(path)));
}

ResultFile ResultFile::open(const std::filesystem::path& path, const mpi::Comm& comm)
{
    const h5::Id fapl = mpio_access(comm);
    h5::Id file = h5::file_id(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl), "open " + path.string());
    const ReleaseOnThrow release_on_throw{file};
    Tiling tiling = tiling_of(file);
    return ResultFile(std::move(file), std::move(tiling), path);
}

std::vector<std::uint8_t> ResultFile::tiles_done() const
{
    std::vector<std::uint8_t> done(tiling_.tiles());
    h5::check(H5Dread(tile_done_, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, done.data()), "read tile_done");
    return done;
}

void ResultFile::write_tile(std::uint64_t tile, std::span<const std::uint32_t> wall_bounces,
                            std::span<const std::uint8_t> outcomes)
{
    const Box box = tiling_.box(tile);
    try {
        if (narrow_counts_) {
            // Counts never exceed max_bounces <= 65535 in a 16-bit file.
            narrow_.assign(wall_bounces.begin(), wall_bounces.end());
            write_box(wall_bounces_, H5T_NATIVE_UINT16, box, std::span<const std::uint16_t>(narrow_));
        } else {
            write_box(wall_bounces_, H5T_NATIVE_UINT32, box, wall_bounces);
        }
        write_box(outcome_, H5T_NATIVE_UINT8, box, outcomes);
        if (tile_checksum_.valid()) {
            const std::uint64_t sum = tile_checksum(tile, wall_bounces, outcomes);
            write_box(tile_checksum_, H5T_NATIVE_UINT64, Box{{tile}, {1}}, std::span<const std::uint64_t>(&sum, 1));
        }
        const std::uint8_t one = 1;
        write_box(tile_done_, H5T_NATIVE_UINT8, Box{{tile}, {1}}, std::span<const std::uint8_t>(&one, 1));
    } catch (const h5::Error& e) {
        throw h5::Error(fmt::format("writing tile {} to {} failed ({}){}; the tiles marked done are on disk: run the same "
                                    "command with --resume once the cause is fixed",
                                    tile, path_.string(), e.what(), free_space_note(path_)));
    }
}

void ResultFile::finish(double run_seconds, int ranks, bool complete)
{
    const double before = h5::read_double_attribute(file_, "wall_seconds");
    h5::write_attribute(file_, "wall_seconds", before + run_seconds);
    h5::write_attribute(file_, "mpi_ranks", static_cast<std::int64_t>(ranks));
    h5::write_attribute(file_, "complete", std::int64_t{complete ? 1 : 0});
    wall_bounces_.close();
    outcome_.close();
    tile_done_.close();
    tile_checksum_.close();
    file_.close();
}

ResultInfo read_result_info(const std::filesystem::path& path)
{
    const h5::Id file = h5::file_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open " + path.string());
    ResultInfo info;
    info.coordinates = h5::read_string_attribute(file, "coordinates");
    info.job_toml = h5::read_string_attribute(file, "job_toml");
    info.job_fingerprint = h5::read_string_attribute(file, "job_fingerprint");
    info.software_version = h5::read_string_attribute(file, "software_version");
    info.max_bounces = h5::read_int_attribute(file, "max_bounces");
    info.mpi_ranks = h5::read_int_attribute(file, "mpi_ranks");
    info.wall_seconds = h5::read_double_attribute(file, "wall_seconds");
    info.complete = h5::read_int_attribute(file, "complete") != 0;
    const Tiling tiling = tiling_of(file);
    {
        // Opened here too, so that a file whose /outcome is damaged is refused before a run.
        const h5::Id d = h5::dataset_id(H5Dopen2(file, "/outcome", H5P_DEFAULT), "open /outcome");
        if (h5::dataset_shape(d) != to_hsize(tiling.shape())) throw h5::Error("/outcome and /wall_bounces differ in shape");
    }
    info.shape = tiling.shape();
    info.tile_shape = tiling.tile_shape();
    info.tiles = tiling.tiles();
    {
        const h5::Id d = h5::dataset_id(H5Dopen2(file, "/progress/tile_done", H5P_DEFAULT), "open /progress/tile_done");
        std::vector<std::uint8_t> done(info.tiles);
        h5::check(H5Dread(d, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, done.data()), "read tile_done");
        info.tiles_done = static_cast<std::uint64_t>(std::count(done.begin(), done.end(), std::uint8_t{1}));
    }
    info.axis_names = h5::read_string_vector_attribute(file, "axis_names");
    return info;
}

std::vector<std::uint64_t> damaged_tiles(const std::filesystem::path& path)
{
    const h5::Id file = h5::file_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open " + path.string());
    std::vector<std::uint64_t> damaged;
    if (!has_link(file, "/progress/tile_checksum")) return damaged;
    const Tiling tiling = tiling_of(file);
    const auto read_1d = [&](const char* name, hid_t type, auto& out) {
        const h5::Id d = h5::dataset_id(H5Dopen2(file, name, H5P_DEFAULT), name);
        out.resize(tiling.tiles());
        if (h5::dataset_shape(d) != std::vector<hsize_t>{tiling.tiles()}) throw h5::Error(std::string(name) + ": wrong size");
        h5::check(H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), name);
    };
    std::vector<std::uint8_t> done;
    std::vector<std::uint64_t> sums;
    read_1d("/progress/tile_done", H5T_NATIVE_UINT8, done);
    read_1d("/progress/tile_checksum", H5T_NATIVE_UINT64, sums);
    const h5::Id wall_bounces = h5::dataset_id(H5Dopen2(file, "/wall_bounces", H5P_DEFAULT), "open /wall_bounces");
    const h5::Id outcome = h5::dataset_id(H5Dopen2(file, "/outcome", H5P_DEFAULT), "open /outcome");
    std::vector<std::uint32_t> counts;
    std::vector<std::uint8_t> outcomes;
    for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
        if (done[t] == 0) continue;
        const Box box = tiling.box(t);
        read_box(wall_bounces, H5T_NATIVE_UINT32, box, counts);
        read_box(outcome, H5T_NATIVE_UINT8, box, outcomes);
        if (done[t] != 1 || tile_checksum(t, counts, outcomes) != sums[t]) damaged.push_back(t);
    }
    return damaged;
}

std::vector<std::uint64_t> outcome_histogram(const std::filesystem::path& path)
{
    const h5::Id file = h5::file_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open " + path.string());
    const h5::Id d = h5::dataset_id(H5Dopen2(file, "/outcome", H5P_DEFAULT), "open /outcome");
    const auto dims = h5::dataset_shape(d);
    hsize_t row = 1;
    for (std::size_t k = 1; k < dims.size(); ++k) row *= dims[k];
    // About 16 MiB at a time, whole rows along the first axis.
    const hsize_t rows_per_block = std::max<hsize_t>(1, (hsize_t{1} << 24) / std::max<hsize_t>(row, 1));
    std::vector<std::uint64_t> histogram(256, 0);
    std::vector<std::uint8_t> buf;
    const h5::Id file_space = h5::space_id(H5Dget_space(d), "H5Dget_space");
    for (hsize_t first = 0; first < dims[0]; first += rows_per_block) {
        std::vector<hsize_t> start(dims.size(), 0), count = dims;
        start[0] = first;
        count[0] = std::min(rows_per_block, dims[0] - first);
        buf.resize(count[0] * row);
        h5::check(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), "select");
        const h5::Id mem = h5::space_id(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), "mem");
        h5::check(H5Dread(d, H5T_NATIVE_UINT8, mem, file_space, H5P_DEFAULT, buf.data()), "read /outcome");
        for (const std::uint8_t o : buf) ++histogram[o];
    }
    return histogram;
}

}  // namespace superball
