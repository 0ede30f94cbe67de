// Adding chunks to an HDF5 file without copying them: the chunks of a compressed result
// are written while the run counts, one after the other past the end of the file's HDF5
// objects (rank 0's ChunkAppender, io/partial_file.hpp); once every tile is done, this
// opens the file and inserts each chunk into its dataset's chunk index at the address
// where it already lies. HDF5 has no call that indexes bytes already in a file, so this
// is done with a file driver of our own (HDF5's public virtual file layer, H5FDpublic.h,
// as h5py's file-object driver is): H5Dwrite_chunk asks the driver for room for the
// chunk, the driver answers with the chunk's address, and the write of bytes that are
// already there is skipped. Everything else (object headers, the chunk index,
// attributes) is allocated after the chunks and written as usual. Direct chunk writes are
// serial in HDF5 1.10: one process does this, after every other has closed the file.
// The cost is the index's, about half a microsecond per chunk, not the data's.
//
// A process killed while HDF5 rewrites the file's metadata would leave a file HDF5 cannot
// open, and a run's tiles with it. So every byte HDF5 overwrites is first copied to an undo
// log (OUTPUT.partial.undo), removed once the file is closed and renamed; a run that finds
// one puts the bytes back (undo_interrupted_changes) and has the file as it was before.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "hdf5.hpp"

namespace superball {

class PlacedChunks {
public:
    // Opens `path` (an HDF5 file) for writing. Its bytes up to `data_end` (its size) are
    // kept: HDF5 allocates nothing below it, whatever its own records say of the file's end
    // (chunks written past them are not free space). The bytes it overwrites go to the undo
    // log `undo_path(path)` first.
    explicit PlacedChunks(const std::filesystem::path& path);
    ~PlacedChunks();
    PlacedChunks(const PlacedChunks&) = delete;
    PlacedChunks& operator=(const PlacedChunks&) = delete;

    hid_t file() const { return file_.get(); }

    // Indexes the chunk of `dataset` whose first element is at `origin` as the `bytes`
    // bytes at `address` (its stored form, every filter of the dataset applied). h5::Error
    // if HDF5 does not place it there (the file or this driver is not what it assumes).
    void add(hid_t dataset, const std::vector<hsize_t>& origin, std::uint64_t address, std::uint64_t bytes);

    // Closes the file, writing its metadata; h5::Error on failure. The undo log stays until
    // discard_undo(): the caller removes it once the file is what it should be (renamed).
    void close();
    // Makes the HDF5 file at `path` end past all its bytes (its superblock's end of file
    // address), so that a tool opening it for writing (h5py's "r+") keeps the chunks
    // appended so far instead of cutting the file to HDF5's own end, and allocates what it
    // adds after them.
    static void cover(const std::filesystem::path& path);
    static std::filesystem::path undo_path(const std::filesystem::path& path);
    // Where the log's header is written before the log is renamed to undo_path (a run killed
    // in between may leave it; discard_undo removes it too).
    static std::filesystem::path unfinished_undo_path(const std::filesystem::path& path);
    static void discard_undo(const std::filesystem::path& path);
    // Whether `path` is an undo log (its first bytes say so).
    static bool is_undo_log(const std::filesystem::path& path);
    // Puts back the bytes an interrupted PlacedChunks overwrote in `path` and cuts what it
    // appended, if its undo log is there: true if it was. std::runtime_error (naming the
    // file) if the log cannot be applied.
    static bool undo_interrupted_changes(const std::filesystem::path& path);

    // The driver's state, shared with its callbacks (placed_chunks.cpp).
    struct State;

private:
    std::unique_ptr<State> state_;
    h5::Id file_;
};

}  // namespace superball
