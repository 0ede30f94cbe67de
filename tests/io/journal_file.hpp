// A file of zeros holding only a journal, laid out as a partial file's /progress
// (io/partial_file.hpp PartialLayout): what the journal's test and its benchmark
// (tests/scale/bench_journal.cpp) write to.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>

#include "io/partial_file.hpp"

namespace superball::test_support {

inline PartialLayout journal_file(const std::filesystem::path& path, std::uint64_t tiles, bool compressed)
{
    PartialLayout l;
    l.compressed = compressed;
    l.tiles = tiles;
    l.done_at = 4096;
    l.checksums_at = l.done_at + tiles;
    l.stored_at = l.checksums_at + 8 * tiles;
    std::ofstream(path, std::ios::binary).close();
    std::filesystem::resize_file(path, l.stored_at + (compressed ? 24 * tiles : 0));
    return l;
}

}  // namespace superball::test_support
