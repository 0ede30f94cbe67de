// Chunks written past an HDF5 file's end, then indexed where they lie
// (io/placed_chunks.hpp): HDF5 reads them back through the dataset's own filters (shuffle,
// deflate: zlib's inflate, not libdeflate's), no chunk byte is written twice, the undo log
// gives back the file as it was, and a tool that opens the file for writing afterwards
// keeps the chunks.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "io/chunk_codec.hpp"
#include "io/hdf5.hpp"
#include "io/placed_chunks.hpp"
#include "job/tiles.hpp"
#include "../temp_dir.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

using test_support::TempDir;

std::string bytes_of(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

// A 61 x 47 dataset of 16-bit values in chunks of 16 x 12 (edge chunks on both axes),
// shuffle + deflate, nothing allocated; the values to store in it.
struct Fixture {
    Extent shape{61, 47}, chunk{16, 12};
    std::vector<std::uint32_t> values;

    explicit Fixture(const fs::path& path)
    {
        values.resize(shape[0] * shape[1]);
        for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<std::uint32_t>((i * 7919) % 3000);
        h5::silence_errors();
        const h5::Id file = h5::create_file(path, h5::file_access(0));
        const h5::Id space = h5::simple_space({shape[0], shape[1]});
        const h5::Id dcpl = h5::plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
        const hsize_t c[2] = {chunk[0], chunk[1]};
        h5::check(H5Pset_chunk(dcpl, 2, c), "H5Pset_chunk");
        h5::check(H5Pset_shuffle(dcpl), "H5Pset_shuffle");
        h5::check(H5Pset_deflate(dcpl, 4), "H5Pset_deflate");
        h5::check(H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_INCR), "H5Pset_alloc_time");
        h5::check(H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER), "H5Pset_fill_time");
        h5::dataset_id(H5Dcreate2(file, "/data", H5T_STD_U16LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), "create");
        h5::create_group(file, "/scratch");
        h5::write_attribute(file, "note", "before");
    }

    // Each chunk's stored form appended to the file: (origin, address, bytes) per chunk.
    struct Placed {
        std::vector<hsize_t> origin;
        std::uint64_t address, bytes;
    };
    std::vector<Placed> append_chunks(const fs::path& path) const
    {
        const Tiling tiling(shape, chunk);
        ChunkEncoder encoder(4);
        std::vector<Placed> placed;
        std::uint64_t at = fs::file_size(path);
        std::ofstream out(path, std::ios::binary | std::ios::app);
        std::vector<std::uint32_t> c(tiling.tile_points());
        for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
            const Box b = tiling.box(t);
            std::fill(c.begin(), c.end(), 0u);
            copy_box(b, reinterpret_cast<const std::byte*>(values.data()), {0, 0}, shape, reinterpret_cast<std::byte*>(c.data()),
                     b.start, chunk, 4);
            std::vector<std::byte> stored;
            encoder.counts(c, 2, stored);
            out.write(reinterpret_cast<const char*>(stored.data()), static_cast<std::streamsize>(stored.size()));
            placed.push_back({{b.start[0], b.start[1]}, at, stored.size()});
            at += stored.size();
        }
        return placed;
    }
};

// A fixture file with its chunks appended, not yet indexed.
class PlacedChunksTest : public ::testing::Test {
protected:
    const TempDir dir{"superball-placed"};
    const fs::path path = dir / "f.h5";
    const Fixture fixture{path};
    const std::vector<Fixture::Placed> placed = fixture.append_chunks(path);

    void index_all(PlacedChunks& file) const
    {
        const h5::Id d = h5::open_dataset(file.file(), "/data");
        for (const auto& p : placed) file.add(d, p.origin, p.address, p.bytes);
    }
};

std::vector<std::uint32_t> read_all(const fs::path& path, std::size_t n)
{
    const h5::Id file = h5::open_file(path, false);
    const h5::Id d = h5::open_dataset(file, "/data");
    std::vector<std::uint32_t> v(n);
    h5::check(H5Dread(d, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "read");
    return v;
}

TEST_F(PlacedChunksTest, HdfFiveReadsTheChunksWhereTheyLie)
{
    const std::string before = bytes_of(path);
    {
        PlacedChunks file(path);
        index_all(file);
        file.close();
    }
    PlacedChunks::discard_undo(path);
    EXPECT_EQ(read_all(path, fixture.values.size()), fixture.values);
    // Not a byte of the chunks moved or was written again; the index came after them.
    const std::string after = bytes_of(path);
    const std::uint64_t first = placed.front().address, end = placed.back().address + placed.back().bytes;
    EXPECT_EQ(after.substr(first, end - first), before.substr(first, end - first));
    EXPECT_GT(after.size(), end);
    EXPECT_LT(after.size() - before.size(), 4096u);  // metadata only
    const h5::Id file = h5::open_file(path, false);
    EXPECT_TRUE(h5::dataset_storage(h5::open_dataset(file, "/data")).allocated);
}

TEST_F(PlacedChunksTest, AChunkHdfFiveWouldPutElsewhereIsRefused)
{
    PlacedChunks file(path);
    const h5::Id d = h5::open_dataset(file.file(), "/data");
    file.add(d, placed[0].origin, placed[0].address, placed[0].bytes);
    // The same chunk again, of the same size: HDF5 would write it over the space it has
    // instead of indexing the bytes announced, and no byte may be written from the
    // placeholder buffer.
    EXPECT_THROW(file.add(d, placed[0].origin, placed[1].address, placed[0].bytes), h5::Error);
}

TEST_F(PlacedChunksTest, TheUndoLogGivesBackTheFileAsItWas)
{
    const std::string before = bytes_of(path);
    EXPECT_FALSE(PlacedChunks::undo_interrupted_changes(path));  // no log: nothing to do
    {
        PlacedChunks file(path);
        index_all(file);
        h5::write_attribute(file.file(), "note", "after, and longer than before");
        h5::check(H5Ldelete(file.file(), "/scratch", H5P_DEFAULT), "H5Ldelete");
        file.close();
    }
    ASSERT_NE(bytes_of(path), before);
    ASSERT_TRUE(PlacedChunks::is_undo_log(PlacedChunks::undo_path(path)));
    EXPECT_TRUE(PlacedChunks::undo_interrupted_changes(path));
    EXPECT_EQ(bytes_of(path), before);
    EXPECT_FALSE(fs::exists(PlacedChunks::undo_path(path)));
    // A file of the log's name that is not one is never taken for one.
    std::ofstream(PlacedChunks::undo_path(path)) << "my notes\n";
    EXPECT_FALSE(PlacedChunks::is_undo_log(PlacedChunks::undo_path(path)));
}

// A run killed while writing the log's header: the header is written under another name and
// renamed into place, so the log is whole or absent; a log with the magic alone (what a run
// killed between the header's two writes left before that, found by explore.test_writers,
// rank 0 killed mid-checkpoint) is one written before any change: it is discarded and the
// file is left as it is, where it stopped the resume ("cannot be applied").
TEST_F(PlacedChunksTest, ALogCutWithinItsHeaderChangedNothingAndIsDiscarded)
{
    PlacedChunks::cover(path);
    EXPECT_FALSE(fs::exists(PlacedChunks::undo_path(path)));
    EXPECT_FALSE(fs::exists(PlacedChunks::unfinished_undo_path(path)));
    std::ofstream(PlacedChunks::undo_path(path), std::ios::binary) << "SBUNDO01";
    ASSERT_TRUE(PlacedChunks::is_undo_log(PlacedChunks::undo_path(path)));
    const std::string covered = bytes_of(path);
    EXPECT_FALSE(PlacedChunks::undo_interrupted_changes(path));
    EXPECT_EQ(bytes_of(path), covered);
    EXPECT_FALSE(fs::exists(PlacedChunks::undo_path(path)));
}

TEST_F(PlacedChunksTest, CoveredChunksSurviveAWriterThatCutsTheFileToItsEnd)
{
    const auto size = fs::file_size(path);
    PlacedChunks::cover(path);
    EXPECT_FALSE(fs::exists(PlacedChunks::undo_path(path)));
    {
        // HDF5's own driver, as h5py's "r+": it cuts the file to the end it records.
        const h5::Id file = h5::open_file(path, true);
        h5::write_attribute(file, "note", "changed");
    }
    EXPECT_GE(fs::file_size(path), size);
}

// Writes past `bytes` fail (EFBIG, as a full file system fails them with ENOSPC) while it lives.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes)
    {
        getrlimit(RLIMIT_FSIZE, &old_);
        const rlimit lower{bytes, old_.rlim_max};
        setrlimit(RLIMIT_FSIZE, &lower);
        old_handler_ = std::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of killing the process
    }
    ~FileSizeLimit()
    {
        setrlimit(RLIMIT_FSIZE, &old_);
        std::signal(SIGXFSZ, old_handler_);
    }
    FileSizeLimit(const FileSizeLimit&) = delete;
    FileSizeLimit& operator=(const FileSizeLimit&) = delete;

private:
    rlimit old_{};
    void (*old_handler_)(int) = SIG_DFL;
};

// A checkpoint that cannot write its undo log (the file system full at that moment) changes
// nothing, leaves no log that would stand in a resume's way, and says, as a failed append
// does, that the tiles recorded are kept and --resume goes on.
TEST_F(PlacedChunksTest, ACheckpointThatCannotWriteLeavesTheFileAndSaysResume)
{
    const std::string before = bytes_of(path);
    std::string message;
    {
        const FileSizeLimit limit(0);
        try {
            PlacedChunks::cover(path);
        } catch (const std::exception& e) {
            message = e.what();
        }
    }
    EXPECT_NE(message.find("writing the checkpoint of " + path.string()), std::string::npos) << message;
    EXPECT_NE(message.find("--resume"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(PlacedChunks::undo_path(path)));
    EXPECT_EQ(bytes_of(path), before);
}

}  // namespace
}  // namespace superball
