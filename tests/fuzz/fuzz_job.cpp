// libFuzzer target for the job-file parser and validator (tests/fuzz/run.sh builds and
// runs it). Any text must either give a valid Job or throw InputError: another exception,
// a crash, a sanitizer report, or a "valid" job that breaks the invariants validation
// promises is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "job/job.hpp"

namespace {

void require(bool ok, const char* what)
{
    if (!ok) {
        std::fprintf(stderr, "fuzz_job: accepted job breaks an invariant: %s\n", what);
        std::abort();
    }
}

// What validation promises of every job it accepts (SPEC.md section 4).
void check_invariants(const superball::Job& job)
{
    using superball::Coordinates;
    const auto names = superball::coordinate_names(job.coordinates);
    require(job.grid.size() == names.size(), "one coordinate per name");
    std::size_t ranges = 0;
    for (std::size_t k = 0; k < job.grid.size(); ++k) {
        const superball::Coordinate& c = job.grid[k];
        require(c.name == names[k], "coordinates in order");
        require(c.fixed.has_value() != c.range.has_value(), "fixed xor range");
        if (c.fixed) require(std::isfinite(*c.fixed), "finite fixed value");
        if (c.range) {
            ++ranges;
            require(std::isfinite(c.range->min) && std::isfinite(c.range->max), "finite range ends");
            require(c.range->min < c.range->max, "min < max");
            require(std::isfinite(c.range->max - c.range->min), "finite width");
            require(c.range->n >= 1, "n >= 1");
            require(std::isfinite(c.range->sample(0)) && std::isfinite(c.range->sample(c.range->n - 1)),
                    "finite samples");
        }
    }
    require(ranges <= 3, "at most 3 coordinate ranges");
    // Swept coefficients: ranges too, and the model is valid at both ends of each.
    std::vector<double> first, last;
    for (const superball::Coordinate& p : job.parameters) {
        require(p.range.has_value() && !p.fixed.has_value(), "a swept coefficient is a range");
        require(std::isfinite(p.range->min) && std::isfinite(p.range->max) && p.range->min < p.range->max,
                "finite swept range, min < max");
        require(p.range->n >= 1, "n >= 1");
        first.push_back(p.range->sample(0));
        last.push_back(p.range->sample(p.range->n - 1));
    }
    for (const int index : job.swept) require(index >= -1 && index < static_cast<int>(job.parameters.size()), "swept index");
    const std::size_t axes = job.range_axes().size();
    require(axes >= 1 && axes <= 4, "1 to 4 range axes");
    require(job.points() >= 1 && job.points() <= (std::uint64_t{1} << 40), "1 <= points <= 2^40");
    require(job.max_bounces >= 1, "max_bounces >= 1");
    for (const superball::Model& m : {job.model, job.model_at(first), job.model_at(last)}) {
        require(superball::in_range(m), "coefficients in range");
    }
    if (job.coordinates == Coordinates::physical) {
        require(job.frame.g > 0 && std::isfinite(job.frame.g), "g > 0");
        require(job.frame.radius > 0 && std::isfinite(job.frame.radius), "radius > 0");
    }
    require(job.refine == 0 || (job.refine >= 2 && job.refine <= 64 && (job.refine & (job.refine - 1)) == 0),
            "refine 0 or a power of two <= 64");
    require(!superball::fingerprint(job).empty(), "fingerprint");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        check_invariants(superball::parse_job(text, "fuzz"));
    } catch (const superball::InputError&) {
        // The one accepted way to refuse a job.
    }
    // Anything else propagates: libFuzzer reports an uncaught exception as a crash.
    return 0;
}
