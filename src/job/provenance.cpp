#include "provenance.hpp"

#include <ctime>
#include <fstream>
#include <iterator>

#include "superball/version.hpp"

namespace superball {

std::string software_source()
{
    const std::string_view commit = git_commit();
    std::string s = std::string("superball ") + software_version + " (git ";
    s += commit.empty() ? std::string("unknown") : std::string(commit.substr(0, 12));
    if (git_dirty()) s += ", dirty";
    return s + ")";
}

std::string software_build()
{
#if defined(__clang__)
    std::string s = "Clang " __clang_version__;
#elif defined(__GNUC__)
    std::string s = "GCC " __VERSION__;
#else
    std::string s = "an unknown compiler";
#endif
    // Set by src/CMakeLists.txt: the build type, portable or -march=native, the kernels.
    return s + ", " SUPERBALL_BUILD_DESCRIPTION;
}

std::string utc_now()
{
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    const std::size_t n = std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return {text, n};
}

std::string shell_quote(std::string_view arg)
{
    const auto safe = [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               std::string_view("-_./=:,+@%").find(c) != std::string_view::npos;
    };
    bool bare = !arg.empty();
    for (const char c : arg) bare = bare && safe(c);
    if (bare) return std::string(arg);
    std::string q = "'";
    for (const char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

std::string process_command_line()
{
    std::ifstream in("/proc/self/cmdline", std::ios::binary);
    const std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string out;
    std::size_t from = 0;
    while (from < raw.size()) {
        const std::size_t end = std::min(raw.find('\0', from), raw.size());
        // Two appends: GCC 12 warns (-Wrestrict, a false positive, GCC bug 105329) on
        // `"literal" + std::string` inlined here.
        if (!out.empty()) out += ' ';
        out += shell_quote(std::string_view(raw).substr(from, end - from));
        from = end + 1;
    }
    return out;
}

std::string history_line(const Provenance& p)
{
    const auto plural = [](std::int64_t n, const char* word) {
        return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
    };
    std::string line = p.date + " " + (p.command.empty() ? std::string("(command unknown)") : p.command) + " [" +
                       software_source() + "; " + plural(p.mpi_ranks, "MPI rank") + " on " + plural(p.hosts, "host") +
                       ", " + plural(p.threads, "thread") + (p.mpi_ranks == 1 ? "" : " each");
    if (!p.kernel.empty()) line += "; kernel " + p.kernel;
    // One line per run: a command with a line break would read as two.
    for (char& c : line) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    return line + "]";
}

std::string append_history(std::string_view text, std::string_view line)
{
    const std::size_t last = text.rfind('\n');
    const std::string_view tail = last == std::string_view::npos ? text : text.substr(last + 1);
    if (tail == line) return std::string(text);
    if (text.empty()) return std::string(line);
    return std::string(text) + "\n" + std::string(line);
}

std::string provenance_comment(const Provenance& p, std::string_view prefix)
{
    const std::string pre(prefix);
    std::string build = software_build();
    if (!p.kernel.empty()) build += "; counting kernel " + p.kernel;
    return pre + "history: " + history_line(p) + "\n" + pre + "source: " + software_source() + "\n" + pre +
           "date_created: " + p.date + "\n" + pre + "build: " + build + "\n";
}

}  // namespace superball
