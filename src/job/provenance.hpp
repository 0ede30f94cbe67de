// Where a result comes from: the software (version, git commit, compiler, kernel) and the run
// (when, the exact command or API call, how many processes on how many hosts). Written into
// result files as CF/ACDD attributes (history, source, date_created, build), into the header
// of the continuation CSV and into the viewer's exported jobs, so that a figure can be traced
// back to the code and the command that made it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace superball {

struct Provenance {
    std::string command;        // the exact command line, or the Python call
    std::string date;           // when the run started: UTC, ISO 8601 ("2026-11-25T06:12:15Z")
    std::int64_t mpi_ranks = 1;
    std::int64_t hosts = 1;     // distinct hosts of the ranks
    std::int64_t threads = 1;   // counting threads per rank
    std::string kernel;         // the counting kernel, as core/kernels.hpp describe() names it
};

// The git commit the build was made from (40 hex digits; empty outside a git checkout) and
// whether the working tree had changes then: generated at every build
// (cmake/git_revision.cmake).
std::string_view git_commit();
bool git_dirty();

// "superball 0.1.0 (git 0123456789ab, dirty)": the version and the commit (12 digits), "dirty"
// when the tree had changes not committed; "(git unknown)" outside a checkout.
std::string software_source();

// "GCC 12.2.0, Release, portable (kernels: baseline, avx2, avx512)": the compiler, the
// build type and the counting kernels compiled in.
std::string software_build();

// Now, UTC, ISO 8601 to the second ("2026-11-25T06:12:15Z").
std::string utc_now();

// `arg` as a POSIX shell reads it back: bare when it holds only safe characters, else in
// single quotes.
std::string shell_quote(std::string_view arg);

// This process's command line, each argument shell_quote()d (Linux: /proc/self/cmdline);
// empty where it cannot be read. Under mpirun it is the rank's command, without mpirun's.
std::string process_command_line();

// One line of CF's `history` attribute: "2026-11-25T06:12:15Z superball explore job.toml
// [superball 0.1.0 (git 0123456789ab); 2 MPI ranks on 1 host, 1 thread each; kernel avx512
// (AVX-512, 8 lanes)]". A run appends one line; resumes append theirs.
std::string history_line(const Provenance& p);

// `text` with `line` added as its last line, unless it is its last line already (a run that
// records its line at the start and again at the end writes it once).
std::string append_history(std::string_view text, std::string_view line);

// The provenance as comment lines, each beginning with `prefix` (e.g. "# "): history,
// source, date_created and build, as the attributes of a result say them. For the
// continuation CSV and exported job files.
std::string provenance_comment(const Provenance& p, std::string_view prefix);

}  // namespace superball
