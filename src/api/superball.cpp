#include "superball/superball.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <stdexcept>
#include <string_view>

#include "core/count.hpp"
#include "core/input.hpp"
#include "core/kernels.hpp"
#include "io/result_reader.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "run/count_threads.hpp"
#include "run/explore.hpp"
#include "run/explore_threads.hpp"
#include "run/progress.hpp"
#include "superball/version.hpp"

namespace superball::api {

namespace {

// Keys as this API spells them: its members' names.
std::string api_key(std::string_view key) { return std::string(key); }

Model model_of(const Coefficients& c)
{
    return resolve_model({c.e, c.alpha, c.e_wall, c.alpha_wall, c.e_floor, c.alpha_floor, c.mu, c.mu_wall, c.mu_floor,
                          c.inertia},
                         api_key);
}

std::uint32_t checked_max_bounces(std::uint32_t max_bounces)
{
    return resolve_max_bounces(std::to_string(max_bounces), api_key);
}

static_assert(static_cast<int>(Outcome::left) == static_cast<int>(superball::Outcome::left) &&
              static_cast<int>(Outcome::missed) == static_cast<int>(superball::Outcome::missed) &&
              static_cast<int>(Outcome::capped) == static_cast<int>(superball::Outcome::capped) &&
              sizeof(Outcome) == sizeof(superball::Outcome));

// run_job reports nothing while it runs.
struct Quiet final : RunObserver {};

}  // namespace

std::string version() { return std::string(software_version) + " (" + software_source() + ")"; }

Count count(double xi, double U, double W, const Coefficients& model, std::uint32_t max_bounces)
{
    const Model m = model_of(model);
    const std::uint32_t limit = checked_max_bounces(max_bounces);
    const Start start = resolve_start({xi, U, W, {}, {}, {}, {}, {}, {}}, api_key);
    const BounceCount c = superball::count(start.canonical, m, limit);
    return {c.wall_bounces, static_cast<Outcome>(c.outcome)};
}

void count(std::span<const double> xi, std::span<const double> U, std::span<const double> W, const Coefficients& model,
           std::uint32_t max_bounces, std::span<std::uint32_t> wall_bounces, std::span<Outcome> outcomes, unsigned threads)
{
    const std::size_t n = xi.size();
    if (U.size() != n || W.size() != n || wall_bounces.size() != n || outcomes.size() != n) {
        throw std::invalid_argument(fmt::format("count: xi, U, W, wall_bounces and outcomes hold {}, {}, {}, {} and {} "
                                                "values: accepted as many each",
                                                n, U.size(), W.size(), wall_bounces.size(), outcomes.size()));
    }
    const Model m = model_of(model);
    const std::uint32_t limit = checked_max_bounces(max_bounces);
    const StartsView all{xi, U, W};
    // Outcome is a byte (std::uint8_t underneath), which the kernel writes as one.
    const std::span<std::uint8_t> codes(reinterpret_cast<std::uint8_t*>(outcomes.data()), n);
    count_on_threads([&](std::size_t first, std::size_t k, Starts&) { return all.subview(first, k); }, ModelMatrices::of(m),
                     limit, wall_bounces, codes, {best_kernel().count, threads});
}

RunResult run_job(const std::filesystem::path& job_file, const RunOptions& options)
{
    const Job job = load_job(job_file);
    ExploreSettings settings;
    settings.output = options.output;
    settings.resume = options.resume;
    settings.overwrite = options.overwrite;
    settings.command = "superball::api::run_job(" + job_file.string() + ")";
    Quiet quiet;
    const RunSummary r = run_explore_threads(job, settings, options.threads, quiet, [] { return false; });
    return {r.output, r.complete, r.points_this_run, r.compute_seconds};
}

Result::Result(const std::filesystem::path& path) : reader_(std::make_shared<const ResultReader>(path)) {}

bool Result::complete() const { return reader_->info().complete; }

const std::vector<std::string>& Result::axis_names() const { return reader_->info().axis_names; }

std::vector<std::uint64_t> Result::shape() const
{
    const Extent& e = reader_->info().shape;
    return {e.begin(), e.end()};
}

std::vector<double> Result::axis(std::size_t k) const { return reader_->axis(k); }

std::string Result::job_toml() const { return reader_->info().job_toml; }

void Result::read(const std::vector<std::uint64_t>& start, const std::vector<std::uint64_t>& count,
                  std::span<std::uint32_t> wall_bounces, std::span<Outcome> outcomes) const
{
    const Extent& shape = reader_->info().shape;
    std::uint64_t points = count.size() == shape.size() ? 1 : 0;
    for (std::size_t k = 0; k < count.size() && k < shape.size(); ++k) {
        if (k >= start.size() || start[k] > shape[k] || count[k] > shape[k] - start[k]) points = 0;
        points *= count[k];
    }
    if (start.size() != shape.size() || points == 0 || wall_bounces.size() != points || outcomes.size() != points) {
        throw std::invalid_argument(fmt::format("Result::read: the box at ({}) of ({}) points, into {} and {} values, "
                                                "does not fit a grid of ({}) or is empty",
                                                fmt::join(start, ", "), fmt::join(count, ", "), wall_bounces.size(),
                                                outcomes.size(), fmt::join(shape, ", ")));
    }
    const Box box{Extent(start.begin(), start.end()), Extent(count.begin(), count.end())};
    reader_->read(box, wall_bounces, std::span<std::uint8_t>(reinterpret_cast<std::uint8_t*>(outcomes.data()), points));
}

}  // namespace superball::api
