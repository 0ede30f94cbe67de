// What is at a path, for messages and for the writer's decision to replace it (a result may
// replace only superball's own files), and how a file's texts are shown in messages.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace superball {

struct FileIdentity {
    // A superball file (result or partial, any version), readable or not: one that
    // `explore --overwrite` may replace.
    bool superball = false;
    // "a directory", "a text file of 120 bytes, beginning ...", "a superball file", "a
    // damaged superball file (...)", "an HDF5 file that is not superball's", ...
    std::string description;
};
FileIdentity identify_file(const std::filesystem::path& path);

// identify_file(path).description.
std::string describe_file(const std::filesystem::path& path);

// A text of a file, for a message: at most 60 characters, with control characters and bytes
// that are not UTF-8 escaped (\xNN), so that a damaged file's bytes can neither garble a
// terminal nor make the message unreadable.
std::string printable(std::string_view text);
std::vector<std::string> printable(const std::vector<std::string>& texts);
// Whether `text` is UTF-8 with no control characters but line breaks: text a reader may
// print as it is.
bool printable_lines(std::string_view text);

}  // namespace superball
