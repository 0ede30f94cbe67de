// Reading the reference tables of tests/reference (copies of ../shared/reference) and
// small helpers shared by the core tests. Header only: every test file includes it.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <ostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/count.hpp"
#include "core/model.hpp"
#include "core/state.hpp"

namespace superball::test {

inline std::string reference_dir() { return SUPERBALL_REFERENCE_DIR; }
inline std::string shared_reference_dir() { return SUPERBALL_SHARED_REFERENCE; }

// The whole file as bytes; nullopt when it cannot be opened.
inline std::optional<std::string> read_bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::vector<std::string> split_commas(const std::string& line)
{
    std::vector<std::string> fields;
    std::string field;
    std::istringstream in(line);
    while (std::getline(in, field, ',')) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    return fields;
}

// strtod accepts "nan", "inf" and every shortest round-trip spelling; the whole field
// must be consumed.
inline double parse_double(const std::string& text)
{
    if (text.empty()) throw std::runtime_error("empty number field");
    char* end = nullptr;
    const double x = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size()) throw std::runtime_error("not a number: '" + text + "'");
    return x;
}

// Data lines of a CSV file: '#' comment lines and blank lines skipped, the first
// remaining line is the header and must equal `header`. Each entry keeps the 1-based
// line number and the text, for failure messages.
struct CsvLine {
    int line_number;
    std::string text;
    std::vector<std::string> fields;
};

inline std::vector<CsvLine> read_csv(const std::string& path, const std::string& header)
{
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::vector<CsvLine> lines;
    std::string text;
    int number = 0;
    bool header_seen = false;
    while (std::getline(in, text)) {
        ++number;
        if (!text.empty() && text.back() == '\r') text.pop_back();
        if (text.empty() || text.front() == '#') continue;
        if (!header_seen) {
            if (text != header) throw std::runtime_error(path + ": unexpected header '" + text + "'");
            header_seen = true;
            continue;
        }
        lines.push_back({number, text, split_commas(text)});
    }
    if (!header_seen) throw std::runtime_error(path + ": no header");
    return lines;
}

// ---------------------------------------------------------------- canonical_counts.csv

struct CountRow {
    int line_number = 0;
    std::string text;  // the CSV line as written, for failure messages
    Model model{};
    CanonicalState<double> start{};
    std::uint32_t wall_bounces = 0;
    Outcome outcome = Outcome::invalid;
};

inline std::ostream& operator<<(std::ostream& os, const CountRow& r)
{
    return os << "canonical_counts.csv line " << r.line_number << ": " << r.text;
}

inline const char* canonical_counts_header = "e_wall,alpha_wall,e_floor,alpha_floor,xi,U,W,wall_bounces,outcome";

inline std::vector<CountRow> read_count_rows(const std::string& path)
{
    std::vector<CountRow> rows;
    for (const CsvLine& l : read_csv(path, canonical_counts_header)) {
        if (l.fields.size() != 9) throw std::runtime_error(path + ": line " + std::to_string(l.line_number) + " has " +
                                                           std::to_string(l.fields.size()) + " fields");
        CountRow r;
        r.line_number = l.line_number;
        r.text = l.text;
        r.model = {{parse_double(l.fields[0]), parse_double(l.fields[1])},
                   {parse_double(l.fields[2]), parse_double(l.fields[3])}};
        r.start = {parse_double(l.fields[4]), parse_double(l.fields[5]), parse_double(l.fields[6])};
        const double n = parse_double(l.fields[7]);
        if (!(n >= 0.0 && n == std::floor(n))) throw std::runtime_error("bad wall_bounces " + l.fields[7]);
        r.wall_bounces = static_cast<std::uint32_t>(n);
        const auto o = outcome_from_name(l.fields[8]);
        if (!o) throw std::runtime_error("bad outcome " + l.fields[8]);
        r.outcome = *o;
        rows.push_back(r);
    }
    return rows;
}

inline std::string canonical_counts_path() { return reference_dir() + "/canonical_counts.csv"; }

// For INSTANTIATE_TEST_SUITE_P, which runs before any test: never throws (a broken file
// yields no rows, and the test ReferenceFiles.CanonicalCountsParse reports why).
inline std::vector<CountRow> count_rows_or_empty()
{
    try {
        return read_count_rows(canonical_counts_path());
    } catch (const std::exception&) {
        return {};
    }
}

// ---------------------------------------------------------------- trajectory_example.csv

// The model and start of trajectory_example.csv (given in its comment lines).
inline constexpr double example_g = 9.81;
inline constexpr double example_radius = 0.025;
inline constexpr Model example_model = Model::uniform(0.9, 0.9);
inline constexpr std::uint32_t example_wall_bounces = 12;
inline constexpr Outcome example_outcome = Outcome::left;

// State just after the n-th floor bounce and height of the centre at the next wall impact
// (NaN after the last bounce: the ball leaves).
struct TrajectoryRow {
    int line_number = 0;
    int n = 0;
    double x, u, v, omega, y;
};

inline const char* trajectory_example_header = "n,x_n,u_n,v_n,omega_n,y_n";

inline std::vector<TrajectoryRow> read_trajectory_rows(const std::string& path)
{
    std::vector<TrajectoryRow> rows;
    for (const CsvLine& l : read_csv(path, trajectory_example_header)) {
        if (l.fields.size() != 6) throw std::runtime_error(path + ": line " + std::to_string(l.line_number) + " has " +
                                                           std::to_string(l.fields.size()) + " fields");
        rows.push_back({l.line_number, static_cast<int>(parse_double(l.fields[0])), parse_double(l.fields[1]),
                        parse_double(l.fields[2]), parse_double(l.fields[3]), parse_double(l.fields[4]),
                        parse_double(l.fields[5])});
    }
    return rows;
}

inline std::string trajectory_example_path() { return reference_dir() + "/trajectory_example.csv"; }

// ---------------------------------------------------------------- comparisons

// |a - b| <= tol * max(|a|, |b|): relative agreement (both zero compares equal).
inline bool rel_near(double a, double b, double tol)
{
    return std::fabs(a - b) <= tol * std::fmax(std::fabs(a), std::fabs(b));
}

// |a - b| <= tol * scale: agreement relative to the size of the terms a and b were
// computed from (for quantities that may cancel to near zero).
inline bool scaled_near(double a, double b, double scale, double tol) { return std::fabs(a - b) <= tol * scale; }

inline std::string full(double x)
{
    std::ostringstream os;
    os.precision(17);
    os << x;
    return os.str();
}

// For EXPECT_PRED_FORMAT3(RelNear, a, b, tol): prints both values in full and the
// relative difference.
inline ::testing::AssertionResult RelNear(const char* a_expr, const char* b_expr, const char*, double a, double b,
                                          double tol)
{
    if (rel_near(a, b, tol)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << a_expr << " = " << full(a) << " and " << b_expr << " = " << full(b)
                                         << " differ by " << full(std::fabs(a - b) / std::fmax(std::fabs(a), std::fabs(b)))
                                         << " relative (allowed " << tol << ")";
}

// For EXPECT_PRED_FORMAT4(ScaledNear, a, b, scale, tol).
inline ::testing::AssertionResult ScaledNear(const char* a_expr, const char* b_expr, const char*, const char*, double a,
                                             double b, double scale, double tol)
{
    if (scaled_near(a, b, scale, tol)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << a_expr << " = " << full(a) << " and " << b_expr << " = " << full(b)
                                         << " differ by " << full(std::fabs(a - b)) << " > " << tol << " * scale "
                                         << full(scale);
}

// ---------------------------------------------------------------- random states and models

// Fixed models every property is checked on: the published materials, per-surface
// different coefficients, and the extremes of the accepted ranges.
inline std::vector<Model> fixed_models()
{
    return {
        Model::uniform(0.9, 0.9),
        Model::uniform(0.95, 0.95),
        Model::uniform(0.7, 0.3),
        {{0.8, 0.6}, {0.85, 0.7}},
        {{1.0, -0.5}, {0.6, 0.95}},
        {{0.35, 1.0}, {1.0, -1.0}},
        Model::uniform(0.5, -1.0),
        Model::uniform(0.2, 0.0),
        Model::uniform(1.0, 1.0),   // Garwin: conservative
        Model::uniform(1.0, -1.0),  // smooth elastic: conservative
    };
}

// Fixed-seed generator of admissible models and launches, so every run tests the same
// states and a failure can be reproduced from its message.
class Sampler {
public:
    explicit Sampler(std::uint64_t seed) : rng_(seed) {}

    double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
    double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
    bool chance(double p) { return uniform(0.0, 1.0) < p; }

    // e in (0, 1], alpha in [-1, 1], with the endpoints e = 1, alpha = +-1 now and then.
    Surface surface()
    {
        const double e = chance(0.1) ? 1.0 : 1.0 - uniform(0.0, 1.0);
        const double r = uniform(0.0, 1.0);
        const double alpha = r < 0.05 ? -1.0 : r < 0.1 ? 1.0 : uniform(-1.0, 1.0);
        return {e, alpha};
    }
    // Half the time one material for both surfaces.
    Model model()
    {
        const Surface wall = surface();
        return chance(0.5) ? Model{wall, wall} : Model{wall, surface()};
    }

    // SPEC.md 1b: mu from 0.05 to 5 (log-uniform), now and then 0 or infinite; inertia in
    // (0, 2/3], now and then 2/5 or 2/3 exactly.
    double mu()
    {
        const double r = uniform(0.0, 1.0);
        return r < 0.05 ? 0.0 : r < 0.1 ? std::numeric_limits<double>::infinity() : log_uniform(0.05, 5.0);
    }
    double inertia()
    {
        const double r = uniform(0.0, 1.0);
        if (r < 0.1) return solid_ball_inertia;
        if (r < 0.2) return thin_shell_inertia;
        double k = 0.0;
        while (!(k > 0.0)) k = uniform(0.0, thin_shell_inertia);
        return k;
    }
    Model walton_model()
    {
        Model m = model();
        m.wall.mu = mu();
        m.floor.mu = chance(0.5) ? m.wall.mu : mu();
        m.inertia = inertia();
        return m;
    }

    // A canonical launch with 0 < xi < xi_max, U from -0.02 to -20 (log-uniform) and
    // |W| <= 5.
    CanonicalState<double> launch(double xi_min = 0.0, double xi_max = 1.0)
    {
        double xi = 0.0;
        while (!(xi > 0.0)) xi = uniform(xi_min, xi_max);
        return {xi, -log_uniform(0.02, 20.0), uniform(-5.0, 5.0)};
    }

    double gravity() { return log_uniform(0.5, 30.0); }
    double speed() { return log_uniform(0.01, 100.0); }

private:
    std::mt19937_64 rng_;
};

inline std::string describe(const Model& m)
{
    return "{e_wall " + full(m.wall.e) + ", alpha_wall " + full(m.wall.alpha) + ", mu_wall " + full(m.wall.mu) +
           ", e_floor " + full(m.floor.e) + ", alpha_floor " + full(m.floor.alpha) + ", mu_floor " + full(m.floor.mu) +
           ", inertia " + full(m.inertia) + "}";
}

inline std::string describe(const CanonicalState<double>& c)
{
    return "(xi " + full(c.xi) + ", U " + full(c.U) + ", W " + full(c.W) + ")";
}

inline std::string describe(const PhysicalState<double>& s)
{
    return "(x " + full(s.x) + ", u " + full(s.u) + ", v " + full(s.v) + ", W " + full(s.W) + ")";
}

}  // namespace superball::test
