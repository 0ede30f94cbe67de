// What is at a run's paths before it starts, each looked at once and nothing changed: the
// result OUTPUT, its partial file OUTPUT.partial (a run in progress or interrupted), the undo
// log OUTPUT.partial.undo (io/placed_chunks.hpp) and the ParaView sidecar OUTPUT.xmf. The
// plan decides from this description (plan_explore) and `explore --dry-run` prints it.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "io/result_reader.hpp"

namespace superball {

// The output or the partial file.
struct FoundFile {
    std::filesystem::path path;
    bool exists = false;             // anything at the path, a dangling symbolic link included
    std::optional<ResultInfo> info;  // it reads as a superball file (a result or a partial file)
    std::string problem;             // else why not (the reader's words)
    FileIdentity identity;           // else what it is: a damaged superball file, a directory, ...
};

// The undo log or the sidecar: superball's own (`ours`), or something else a run must not
// replace.
struct Companion {
    std::filesystem::path path;
    bool exists = false;
    bool ours = false;
    FileIdentity identity;  // when it exists and is not ours
};

struct FilesThere {
    FoundFile output;
    FoundFile partial;
    Companion undo_log;
    Companion sidecar;
    bool gets_sidecar = true;  // a result named *.xmf, or with a colon in its name, gets none
};

FilesThere look_at_files(const std::filesystem::path& output);
// The output or the partial file at `path`, looked at again (after an undo log changed it).
FoundFile look_at(const std::filesystem::path& path);

}  // namespace superball
