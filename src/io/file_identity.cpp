// What is at a path, told for messages and for the writer's decision to replace it.
#include "file_identity.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <system_error>

#include "hdf5.hpp"
#include "layout.hpp"

namespace superball {

namespace fs = std::filesystem;
namespace attr = layout::attr;

namespace {

// Whether the bytes at the beginning or end of a file HDF5 cannot read name superball's
// two datasets, wall_bounces and outcome: the root group's links, in the first few KiB of
// every superball file (its attributes may lie past a truncation). Only a file HDF5 cannot
// open is judged so; one it opens is superball's by its attributes.
bool has_superball_marks(const fs::path& path, std::uint64_t size)
{
    constexpr std::uint64_t span = std::uint64_t{64} * 1024;
    std::ifstream in(path, std::ios::binary);
    std::string bytes;
    for (const std::uint64_t at : {std::uint64_t{0}, size > span ? size - span : std::uint64_t{0}}) {
        std::string part(static_cast<std::size_t>(std::min(span, size)), '\0');
        in.seekg(static_cast<std::streamoff>(at));
        in.read(part.data(), static_cast<std::streamsize>(part.size()));
        part.resize(static_cast<std::size_t>(std::max<std::streamsize>(0, in.gcount())));
        in.clear();
        bytes += part;
    }
    const auto has = [&](std::string_view s) { return bytes.find(s) != std::string::npos; };
    return has("wall_bounces") && has("outcome");
}

// Length of the UTF-8 sequence at text[i], 0 if none begins there.
std::size_t utf8_sequence(std::string_view text, std::size_t i)
{
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t n = c < 0x80 ? 1 : c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
    bool valid = n > 0 && i + n <= text.size();
    for (std::size_t k = 1; valid && k < n; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
    return valid ? n : 0;
}

}  // namespace

// Whether `text` is UTF-8 with no control characters but line breaks: text a reader may
// print as it is.
bool printable_lines(std::string_view text)
{
    for (std::size_t i = 0; i < text.size();) {
        const std::size_t n = utf8_sequence(text, i);
        const auto c = static_cast<unsigned char>(text[i]);
        if (n == 0 || (n == 1 && ((c < 0x20 && c != '\n') || c == 0x7f))) return false;
        i += n;
    }
    return true;
}

std::string printable(std::string_view text)
{
    std::string out;
    std::size_t i = 0;
    for (std::size_t shown = 0; i < text.size() && shown < 60; ++shown) {
        const auto c = static_cast<unsigned char>(text[i]);
        const std::size_t n = utf8_sequence(text, i);
        if (n == 1 && c >= 0x20 && c != 0x7f) {
            out += static_cast<char>(c);
        } else if (n > 1) {
            out.append(text.substr(i, n));
            i += n - 1;
        } else {
            out += fmt::format("\\x{:02x}", c);
        }
        ++i;
    }
    if (i < text.size()) out += "...";
    return out;
}

std::vector<std::string> printable(const std::vector<std::string>& texts)
{
    std::vector<std::string> out;
    for (const std::string& t : texts) out.push_back(printable(t));
    return out;
}

FileIdentity identify_file(const fs::path& path)
{
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) return {false, "nothing (no such file)"};
    if (fs::is_directory(st)) return {false, "a directory"};
    if (!fs::is_regular_file(st)) return {false, "not a regular file"};
    const auto size = fs::file_size(path, ec);
    if (!ec && size == 0) return {false, "an empty file"};
    std::ifstream in(path, std::ios::binary);
    if (!in) return {false, "a file that cannot be read (" + std::error_code(errno, std::generic_category()).message() + ")"};
    if (h5::is_hdf5(path)) {
        std::string why;
        try {
            const h5::Id f = h5::open_file(path, false);
            if (h5::has_attribute(f, layout::kind_attribute) || h5::has_attribute(f, attr::job_toml)) {
                return {true, "a superball file"};
            }
            why = "it opens, but has none of superball's attributes";
        } catch (const h5::Error& e) {
            why = e.what();
        }
        if (has_superball_marks(path, size)) return {true, "a damaged superball file (" + why + ")"};
        if (why.rfind("it opens", 0) == 0) return {false, "an HDF5 file that is not superball's"};
        return {false, "an HDF5 file that cannot be opened (damaged or truncated) and shows nothing of superball's"};
    }
    std::string head(512, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    const bool text = std::all_of(head.begin(), head.end(), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return u >= 0x20 || c == '\n' || c == '\r' || c == '\t';
    });
    if (!text) return {false, fmt::format("a binary file of {} bytes", size)};
    const std::string first = head.substr(0, head.find('\n')).substr(0, 40);
    return {false, fmt::format("a text file of {} bytes, beginning \"{}\"", size, printable(first))};
}

std::string describe_file(const fs::path& path) { return identify_file(path).description; }

}  // namespace superball
