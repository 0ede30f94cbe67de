// The output of superball continue: the branches (or, with --curve, the event curves) as
// CSV with # comment lines (continuation_csv.cpp), or everything as JSON (nlohmann-json,
// continuation_json.cpp). Doubles are written as the
// shortest text that reads back to the same value.
#pragma once

#include <cstdio>
#include <string>

#include "job/provenance.hpp"
#include "run/continuation.hpp"

namespace superball::cli {

void write_branches_csv(std::FILE* f, const ContinuationResult& result, const ContinuationRun& run, const Provenance& prov);
void write_curves_csv(std::FILE* f, const ContinuationResult& result, const ContinuationRun& run, const Provenance& prov);
// One line on an event curve: where it starts, its points and how it ends.
std::string curve_text(const ContinuedCurve& c, const ContinuationResult& result, const ContinuationRun& run);
// The run's settings, its branches with every point, and its event curves (with --curve).
std::string continuation_json(const ContinuationResult& result, const ContinuationRun& run, int ranks);

}  // namespace superball::cli
