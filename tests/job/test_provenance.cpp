// Provenance of runs (job/provenance.hpp): the texts written into result files, the
// continuation CSV and exported jobs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>

#include "job/provenance.hpp"

namespace superball {
namespace {

// `text` has the shape of `pattern`, where '#' stands for a decimal digit and 'x' for a
// lower-case hexadecimal one. (Not std::regex: GCC 12's regex headers warn under the
// sanitizers' -O1, -Wmaybe-uninitialized in std::function.)
bool shaped(std::string_view text, std::string_view pattern)
{
    if (text.size() != pattern.size()) return false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        const bool ok = pattern[i] == '#'   ? std::isdigit(c) != 0
                        : pattern[i] == 'x' ? std::isdigit(c) != 0 || (c >= 'a' && c <= 'f')
                                            : text[i] == pattern[i];
        if (!ok) return false;
    }
    return true;
}

// "superball X.Y.Z (git COMMIT[, dirty])", COMMIT 12 hexadecimal digits or "unknown".
bool is_source_text(std::string_view s)
{
    constexpr std::string_view head = "superball ", git = " (git ";
    if (!s.starts_with(head) || !s.ends_with(")")) return false;
    s.remove_prefix(head.size());
    const std::size_t at = s.find(git);
    if (at == std::string_view::npos) return false;
    const std::string_view version = s.substr(0, at);
    if (std::count(version.begin(), version.end(), '.') != 2 || version.front() == '.' || version.back() == '.' ||
        version.find("..") != std::string_view::npos ||
        !std::all_of(version.begin(), version.end(), [](char c) { return c == '.' || std::isdigit(static_cast<unsigned char>(c)); })) {
        return false;
    }
    std::string_view commit = s.substr(at + git.size());
    commit.remove_suffix(1);
    if (commit.ends_with(", dirty")) commit.remove_suffix(7);
    return commit == "unknown" || shaped(commit, "xxxxxxxxxxxx");
}

TEST(Provenance, ShellQuoteReadsBackInAPosixShell)
{
    EXPECT_EQ(shell_quote("jobs/quickstart.toml"), "jobs/quickstart.toml");
    EXPECT_EQ(shell_quote("--max-bounces=10"), "--max-bounces=10");
    EXPECT_EQ(shell_quote("my results/a.h5"), "'my results/a.h5'");
    EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
    EXPECT_EQ(shell_quote(""), "''");
    EXPECT_EQ(shell_quote("$HOME"), "'$HOME'");
}

TEST(Provenance, ProcessCommandLineNamesThisTest)
{
    // /proc/self/cmdline of the test binary: its path comes first.
    const std::string line = process_command_line();
    EXPECT_NE(line.find("test_job"), std::string::npos) << line;
}

TEST(Provenance, UtcNowIsIso8601ToTheSecond)
{
    EXPECT_TRUE(shaped(utc_now(), "####-##-##T##:##:##Z")) << utc_now();
    EXPECT_FALSE(shaped("2026-11-28 17:26:27Z", "####-##-##T##:##:##Z"));
}

TEST(Provenance, SourceNamesVersionAndCommit)
{
    const std::string s = software_source();
    // A build from a git checkout names 12 hex digits of its commit; "dirty" when the tree
    // had changes.
    EXPECT_TRUE(is_source_text(s)) << s;
    EXPECT_TRUE(is_source_text("superball 0.1.0 (git 0123456789ab, dirty)"));
    EXPECT_TRUE(is_source_text("superball 10.2.33 (git unknown)"));
    EXPECT_FALSE(is_source_text("superball 0.1 (git 0123456789ab)"));
    EXPECT_FALSE(is_source_text("superball 0.1.0 (git 0123456789AB)"));
    EXPECT_FALSE(is_source_text("superball 0.1.0 (git 0123456789ab, clean)"));
    if (!git_commit().empty()) {
        EXPECT_EQ(git_commit().size(), 40u);
        EXPECT_NE(s.find(std::string(git_commit().substr(0, 12))), std::string::npos);
    }
    EXPECT_EQ(s.find("dirty") != std::string::npos, git_dirty());
}

TEST(Provenance, BuildNamesCompilerAndKernels)
{
    const std::string b = software_build();
    EXPECT_TRUE(b.rfind("GCC ", 0) == 0 || b.rfind("Clang ", 0) == 0) << b;
    EXPECT_NE(b.find("(kernels: "), std::string::npos) << b;
}

TEST(Provenance, HistoryLineSaysWhenWhatWhereAndHow)
{
    const Provenance p{"superball explore 'my job.toml'", "2026-11-25T06:12:15Z", 4, 2, 1, "avx2 (AVX2+FMA, 4 lanes)"};
    const std::string line = history_line(p);
    EXPECT_EQ(line, "2026-11-25T06:12:15Z superball explore 'my job.toml' [" + software_source() +
                        "; 4 MPI ranks on 2 hosts, 1 thread each; kernel avx2 (AVX2+FMA, 4 lanes)]");
    const Provenance threads{"superball.explore('a.toml')", "2026-11-25T06:12:15Z", 1, 1, 8, ""};
    EXPECT_EQ(history_line(threads),
              "2026-11-25T06:12:15Z superball.explore('a.toml') [" + software_source() + "; 1 MPI rank on 1 host, 8 threads]");
    // A line break in a command would make two lines of history.
    const Provenance broken{"a\nb", "2026-11-25T06:12:15Z", 1, 1, 1, ""};
    EXPECT_EQ(history_line(broken).find('\n'), std::string::npos);
}

TEST(Provenance, HistoryGetsALineOncePerRun)
{
    EXPECT_EQ(append_history("", "first"), "first");
    EXPECT_EQ(append_history("first", "first"), "first");  // the run records its figures again at its end
    EXPECT_EQ(append_history("first", "second"), "first\nsecond");
    EXPECT_EQ(append_history("first\nsecond", "second"), "first\nsecond");
    EXPECT_EQ(append_history("first\nsecond", "first"), "first\nsecond\nfirst");  // an older line is another run's
}

TEST(Provenance, CommentLinesCarryTheAttributes)
{
    const Provenance p{"superball continue --e 0.9", "2026-11-25T06:12:15Z", 2, 1, 1, ""};
    const std::string c = provenance_comment(p, "# ");
    EXPECT_EQ(c, "# history: " + history_line(p) + "\n# source: " + software_source() +
                     "\n# date_created: 2026-11-25T06:12:15Z\n# build: " + software_build() + "\n");
}

}  // namespace
}  // namespace superball
