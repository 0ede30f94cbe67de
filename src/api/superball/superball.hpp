// superball's public C++ API: what an installed superball offers a program of its own
// (find_package(superball), target superball::api). Count launches, run a job, read a
// result. Everything else the library is made of is internal and not installed.
//
// Bad input (a coefficient out of its range, a start that is not a launch, a job file with
// a bad key) throws std::invalid_argument whose message names the input, in the words the
// command line uses; a file that cannot be read or written throws std::runtime_error naming
// it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace superball {
class ResultReader;  // the implementation of api::Result
}

namespace superball::api {

// The library's version ("0.1.0") and where it was built from (its git commit).
std::string version();

// The impact law's coefficients (SPEC.md sections 1 and 1b): e and alpha for both surfaces,
// or each surface's own (e_wall, alpha_wall, e_floor, alpha_floor take precedence); the
// Coulomb friction coefficient mu likewise (default infinite: the Cross model) and the
// ball's moment of inertia over m a^2 (default 0.4, a solid ball).
struct Coefficients {
    std::optional<double> e, alpha, e_wall, alpha_wall, e_floor, alpha_floor;
    // Initialised, so that aggregates written before them ({e, alpha}) need not name them.
    std::optional<double> mu = std::nullopt, mu_wall = std::nullopt, mu_floor = std::nullopt, inertia = std::nullopt;
};

// How a launch's motion ended (SPEC.md section 3).
enum class Outcome : std::uint8_t { invalid = 0, left = 1, missed = 2, capped = 3 };

struct Count {
    std::uint32_t wall_bounces = 0;
    Outcome outcome = Outcome::invalid;
};

// One launch in canonical coordinates (xi, U, W), counted up to max_bounces wall bounces.
Count count(double xi, double U, double W, const Coefficients& model, std::uint32_t max_bounces = 1000);

// Launches i < xi.size() (U and W as long; wall_bounces and outcomes too) on `threads`
// threads (0: every core this process may use), with the fastest kernel of this processor:
// the same values as count() one by one, bit for bit.
void count(std::span<const double> xi, std::span<const double> U, std::span<const double> W, const Coefficients& model,
           std::uint32_t max_bounces, std::span<std::uint32_t> wall_bounces, std::span<Outcome> outcomes,
           unsigned threads = 0);

// A job file run in this process, on threads, as `superball explore` runs it under mpirun:
// the result written while the tiles are counted, resumable, never overwritten unless asked.
struct RunOptions {
    std::filesystem::path output;  // empty: the job's [run] output
    bool resume = false;           // finish an interrupted run of the same job
    bool overwrite = false;        // replace what is there
    unsigned threads = 0;          // 0: every core this process may use
};
struct RunResult {
    std::filesystem::path output;
    bool complete = false;             // false: stopped; the partial file is kept
    std::uint64_t points_this_run = 0;
    double compute_seconds = 0;
};
RunResult run_job(const std::filesystem::path& job_file, const RunOptions& options = {});

// A result file (or an interrupted run's partial file), validated when opened.
class Result {
public:
    explicit Result(const std::filesystem::path& path);

    bool complete() const;                              // a result, not a partial file
    const std::vector<std::string>& axis_names() const;  // the grid's axes, in the data's order
    std::vector<std::uint64_t> shape() const;           // samples along each axis
    std::vector<double> axis(std::size_t k) const;      // the samples of axis k
    std::string job_toml() const;                       // the job that made it
    // The values of the box [start, start + count) of the grid, row-major. Points a partial
    // file has not counted yet read as 0 bounces, outcome invalid.
    void read(const std::vector<std::uint64_t>& start, const std::vector<std::uint64_t>& count,
              std::span<std::uint32_t> wall_bounces, std::span<Outcome> outcomes) const;

private:
    std::shared_ptr<const ResultReader> reader_;
};

}  // namespace superball::api
