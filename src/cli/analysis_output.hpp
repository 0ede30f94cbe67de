// The output of superball analyse: a report for people, or JSON (nlohmann-json; JSON has no
// NaN: an estimate that could not be made is null).
#pragma once

#include <optional>
#include <string>

#include "run/analyse.hpp"

namespace superball::cli {

void print_analysis_report(const std::string& file, const Analysis& a, const std::optional<Slice>& slice);
void print_analysis_json(const std::string& file, const Analysis& a, const std::optional<Slice>& slice);

}  // namespace superball::cli
