// Suggestions for misspelt names: job-file keys, command-line flags and commands.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace superball {

// Levenshtein distance, ignoring case (so "w" is close to "W").
std::size_t edit_distance(std::string_view a, std::string_view b);

// The known name closest to `name`, if close enough to be a plausible typo (distance
// below 3). A suggestion must keep part of the candidate: "a" is not a misspelling of "U".
std::optional<std::string> suggestion(std::string_view name, const std::vector<std::string>& known);

}  // namespace superball
