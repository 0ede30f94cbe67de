#include "files_there.hpp"

#include <fstream>
#include <system_error>

#include "core/input.hpp"
#include "io/layout.hpp"
#include "io/placed_chunks.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {

bool something_at(const fs::path& path)
{
    std::error_code ec;
    return fs::exists(path, ec) || fs::is_symlink(path, ec);
}

// Whether `path` is an XDMF sidecar as superball writes them (io/xdmf.cpp): XML naming a
// result's /wall_bounces. A sidecar is small; the first 64 KiB say.
bool is_superball_sidecar(const fs::path& path)
{
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return false;
    std::ifstream in(path, std::ios::binary);
    std::string head(std::size_t{64} * 1024, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    return head.rfind("<?xml", 0) == 0 && head.find("<Xdmf") != std::string::npos &&
           head.find(":/wall_bounces</DataItem>") != std::string::npos;
}

template <class IsOurs>
Companion companion(const fs::path& path, IsOurs is_ours)
{
    Companion c{path, something_at(path), false, {}};
    if (!c.exists) return c;
    c.ours = is_ours(path);
    if (!c.ours) c.identity = identify_file(path);
    return c;
}

}  // namespace

FoundFile look_at(const fs::path& path)
{
    FoundFile f{path, something_at(path), std::nullopt, {}, {}};
    if (!f.exists) return f;
    try {
        f.info = ResultReader(path).info();
    } catch (const InputError& e) {
        f.problem = e.what();
        f.identity = identify_file(path);
    }
    return f;
}

FilesThere look_at_files(const fs::path& output)
{
    FilesThere files;
    const fs::path partial = layout::partial_path(output);
    files.partial = look_at(partial);
    files.output = look_at(output);
    files.undo_log = companion(PlacedChunks::undo_path(partial), PlacedChunks::is_undo_log);
    const fs::path sidecar = layout::sidecar_path(output);
    files.gets_sidecar = sidecar != output && output.filename().string().find(':') == std::string::npos;
    files.sidecar = companion(sidecar, is_superball_sidecar);
    return files;
}

}  // namespace superball
