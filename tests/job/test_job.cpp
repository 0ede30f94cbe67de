// Job files (SPEC.md section 4): parsing, validation messages and fingerprints.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "job/job.hpp"

namespace superball {
namespace {

constexpr const char* source = "jobs/test.toml";

const std::string model_section = R"(
[model]
e = 0.9
alpha = 0.8
)";

// A canonical job with the given [grid] body (after coordinates) and the default model.
std::string canonical_job(const std::string& grid_body, const std::string& extra = "")
{
    return model_section + "\n[grid]\n" + grid_body + "\n" + extra;
}

std::string error_of(const std::string& text)
{
    try {
        parse_job(text, source);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

// --- Valid jobs ----------------------------------------------------------------------------

TEST(Job, CanonicalTwoAxes)
{
    const std::string text = R"(
[model]                 # e and alpha set both surfaces
e = 0.9
alpha = 0.9

[grid]
coordinates = "canonical"
xi = { min = 0.0, max = 1.0, n = 2048 }
U  = -1.0
W  = { min = -3.0, max = 3.0, n = 1024 }

[run]
max_bounces = 500
output = "results/slice.h5"
)";
    const Job job = parse_job(text, source);
    EXPECT_EQ(job.coordinates, Coordinates::canonical);
    EXPECT_EQ(job.model.wall.e, 0.9);
    EXPECT_EQ(job.model.wall.alpha, 0.9);
    EXPECT_EQ(job.model.floor.e, 0.9);
    EXPECT_EQ(job.model.floor.alpha, 0.9);
    ASSERT_EQ(job.grid.size(), 3u);
    EXPECT_EQ(job.grid[0], (Coordinate{"xi", std::nullopt, Range{0.0, 1.0, 2048}}));
    EXPECT_EQ(job.grid[1], (Coordinate{"U", -1.0, std::nullopt}));
    EXPECT_EQ(job.grid[2], (Coordinate{"W", std::nullopt, Range{-3.0, 3.0, 1024}}));
    EXPECT_EQ(job.max_bounces, 500u);
    EXPECT_EQ(job.output, "results/slice.h5");
    EXPECT_FALSE(job.tile_points.has_value());
    EXPECT_EQ(job.text, text);
    ASSERT_EQ(job.range_axes().size(), 2u);
    EXPECT_EQ(job.range_axes()[0]->name, "xi");
    EXPECT_EQ(job.range_axes()[1]->name, "W");
    EXPECT_EQ(job.points(), 2048u * 1024u);
}

TEST(Job, OneAxisWithDefaults)
{
    // coordinates defaults to canonical, max_bounces to 1000, output to unset; an
    // integer is accepted where a number is expected.
    const Job job = parse_job(canonical_job("xi = 0.25\nU = -1\nW = { min = -1, max = 1, n = 7 }"), source);
    EXPECT_EQ(job.coordinates, Coordinates::canonical);
    EXPECT_EQ(job.grid[0].fixed, 0.25);
    EXPECT_EQ(job.grid[1].fixed, -1.0);
    EXPECT_EQ(job.grid[2].range, (Range{-1.0, 1.0, 7}));
    EXPECT_EQ(job.range_axes().size(), 1u);
    EXPECT_EQ(job.points(), 7u);
    EXPECT_EQ(job.max_bounces, 1000u);
    EXPECT_TRUE(job.output.empty());
}

TEST(Job, ThreeAxesAsTablesWithTilePoints)
{
    const std::string text = model_section + R"(
[grid.xi]
min = 0
max = 1
n = 4
[grid.U]
min = -2
max = -0.5
n = 3
[grid.W]
min = -1
max = 1
n = 5
[run]
tile_points = 4096
max_bounces = 4294967295
)";
    const Job job = parse_job(text, source);
    EXPECT_EQ(job.range_axes().size(), 3u);
    EXPECT_EQ(job.points(), 60u);
    EXPECT_EQ(job.tile_points, 4096u);
    EXPECT_EQ(job.max_bounces, 4294967295u);
}

// [run] writers: a count or "auto" (0), the default; the same words as explore --writers.
TEST(Job, Writers)
{
    const auto writers_of = [](const std::string& run) {
        return parse_job(model_section + "[grid]\nxi = { min = 0, max = 1, n = 4 }\nU = -1\nW = 0\n" + run, source).writers;
    };
    EXPECT_EQ(writers_of(""), 0u);
    EXPECT_EQ(writers_of("[run]\nwriters = \"auto\"\n"), 0u);
    EXPECT_EQ(writers_of("[run]\nwriters = 128\n"), 128u);
    EXPECT_EQ(writers_from_text("auto", "--writers"), 0u);
    EXPECT_EQ(writers_from_text("4", "--writers"), 4u);
    for (const char* bad : {"0", "-1", "4x", "", "65537", "many"}) {
        EXPECT_THROW(writers_from_text(bad, "--writers"), InputError) << bad;
    }
    // Who writes changes no count: not part of the fingerprint.
    EXPECT_EQ(fingerprint(parse_job(model_section + "[grid]\nxi = { min = 0, max = 1, n = 4 }\nU = -1\nW = 0\n", source)),
              fingerprint(parse_job(model_section + "[grid]\nxi = { min = 0, max = 1, n = 4 }\nU = -1\nW = 0\n[run]\nwriters = 8\n",
                                    source)));
}

TEST(Job, PhysicalWithDefaultFrame)
{
    const std::string text = model_section + R"(
[grid]
coordinates = "physical"
x = 0.1
u = { min = -5, max = -1, n = 10 }
v = 3
omega = { min = -100, max = 100, n = 20 }
)";
    const Job job = parse_job(text, source);
    EXPECT_EQ(job.coordinates, Coordinates::physical);
    EXPECT_EQ(job.frame.g, 9.81);
    EXPECT_EQ(job.frame.radius, 0.025);
    ASSERT_EQ(job.grid.size(), 4u);
    EXPECT_EQ(job.grid[0].name, "x");
    EXPECT_EQ(job.grid[3].name, "omega");
    EXPECT_EQ(job.points(), 200u);
}

TEST(Job, PhysicalWithFrameAndPerSurfaceOverrides)
{
    const std::string text = R"(
[model]
e = 0.9
alpha = 0.5
e_wall = 0.7
alpha_floor = -0.25
g = 1.62
radius = 1
[grid]
coordinates = "physical"
x = { min = 0, max = 1, n = 2 }
u = { min = -5, max = -1, n = 2 }
v = { min = 1, max = 2, n = 2 }
omega = 0
)";
    const Job job = parse_job(text, source);
    EXPECT_EQ(job.model.wall.e, 0.7);
    EXPECT_EQ(job.model.wall.alpha, 0.5);
    EXPECT_EQ(job.model.floor.e, 0.9);
    EXPECT_EQ(job.model.floor.alpha, -0.25);
    EXPECT_EQ(job.frame.g, 1.62);
    EXPECT_EQ(job.frame.radius, 1.0);
    EXPECT_EQ(job.points(), 8u);
}

TEST(Job, PerSurfaceKeysWithoutSharedOnes)
{
    const Job job = parse_job(R"(
[model]
e_wall = 1
alpha_wall = 1
e_floor = 0.5
alpha_floor = -1
[grid]
xi = { min = 0, max = 1, n = 2 }
U = -1
W = 0
)",
                              source);
    EXPECT_EQ(job.model.wall.e, 1.0);
    EXPECT_EQ(job.model.wall.alpha, 1.0);
    EXPECT_EQ(job.model.floor.e, 0.5);
    EXPECT_EQ(job.model.floor.alpha, -1.0);
}

TEST(Job, FixedValuesNeedNotBeLaunches)
{
    // A non-launch point is outcome invalid, not a bad job.
    const Job job = parse_job(canonical_job("xi = -3\nU = 2\nW = { min = 0, max = 1, n = 1 }"), source);
    EXPECT_EQ(job.grid[0].fixed, -3.0);
    EXPECT_EQ(job.grid[1].fixed, 2.0);
}

TEST(Job, LargestAcceptedGrid)
{
    const Job job = parse_job(canonical_job("xi = { min = 0, max = 1, n = 1048576 }\nU = -1\n"
                                            "W = { min = 0, max = 1, n = 1048576 }"),
                              source);
    EXPECT_EQ(job.points(), std::uint64_t{1} << 40);
}

TEST(Range, SamplesAreCellCentres)
{
    const Range r{0.0, 1.0, 4};
    EXPECT_DOUBLE_EQ(r.sample(0), 0.125);
    EXPECT_DOUBLE_EQ(r.sample(1), 0.375);
    EXPECT_DOUBLE_EQ(r.sample(2), 0.625);
    EXPECT_DOUBLE_EQ(r.sample(3), 0.875);
    const Range one{-3.0, 3.0, 1};
    EXPECT_DOUBLE_EQ(one.sample(0), 0.0);
}

// --- Errors --------------------------------------------------------------------------------

struct ErrorCase {
    const char* name;
    std::string text;
    std::vector<std::string> expected;  // substrings of the message
};

void PrintTo(const ErrorCase& c, std::ostream* os) { *os << c.name; }

class JobError : public testing::TestWithParam<ErrorCase> {};

TEST_P(JobError, IsInputErrorNamingTheKey)
{
    const ErrorCase& c = GetParam();
    const std::string message = error_of(c.text);
    ASSERT_FALSE(message.empty()) << "no InputError for:\n" << c.text;
    EXPECT_EQ(message.rfind(std::string(source), 0), 0u) << message;
    for (const std::string& part : c.expected) EXPECT_NE(message.find(part), std::string::npos) << message << "\nlacks: " << part;
}

const std::string xi_range = "xi = { min = 0, max = 1, n = 8 }\n";
const std::string fixed_u_w = "U = -1\nW = 0\n";

std::string physical_job(const std::string& model_extra, const std::string& grid_body)
{
    return model_section + model_extra + "\n[grid]\ncoordinates = \"physical\"\n" + grid_body;
}

const std::string physical_grid = "x = 1\nu = { min = -2, max = -1, n = 3 }\nv = 1\nomega = 0\n";

INSTANTIATE_TEST_SUITE_P(
    Cases, JobError,
    testing::Values(
        ErrorCase{"UnknownTable", canonical_job(xi_range + fixed_u_w, "[gird]\nx = 1\n"),
                  {"unknown table [gird]", "did you mean [grid]?"}},
        ErrorCase{"UnknownTableNoSuggestion", canonical_job(xi_range + fixed_u_w, "[plot]\nx = 1\n"),
                  {"unknown table [plot]", "[model], [grid], [run]"}},
        ErrorCase{"KeyOutsideTables", "e = 0.9\n" + canonical_job(xi_range + fixed_u_w), {"key e", "[model]"}},
        ErrorCase{"TableGivenAsValue", "run = 3\n" + canonical_job(xi_range + fixed_u_w), {"run = 3", "table"}},
        ErrorCase{"UnknownGridKey", canonical_job("xii = { min = 0, max = 1, n = 8 }\n" + fixed_u_w),
                  {"unknown key [grid] xii (did you mean xi?)"}},
        ErrorCase{"UnknownGridKeyNoSuggestion", canonical_job(xi_range + fixed_u_w + "colour = 1\n"),
                  {"unknown key [grid] colour", "accepted: coordinates, xi, U, W"}},
        ErrorCase{"WrongCaseGridKey", canonical_job(xi_range + "U = -1\nw = 0\n"), {"[grid] w", "did you mean W?"}},
        ErrorCase{"PhysicalKeyOnCanonicalGrid", canonical_job(xi_range + fixed_u_w + "omega = 1\n"),
                  {"[grid] omega", "physical", "canonical"}},
        ErrorCase{"UnknownModelKey", "[model]\ne = 0.9\nalpha = 0.9\nspin = 1\n[grid]\n" + xi_range + fixed_u_w,
                  {"unknown key [model] spin", "accepted: e, alpha"}},
        ErrorCase{"ModelSubtable", canonical_job(xi_range + fixed_u_w, "[model.wall]\ne = 1\n"), {"unknown key [model] wall"}},
        ErrorCase{"UnknownModelKeySuggestion",
                  "[model]\ne = 0.9\nalpha = 0.9\ne_wal = 0.5\n[grid]\n" + xi_range + fixed_u_w,
                  {"unknown key [model] e_wal (did you mean e_wall?)"}},
        ErrorCase{"UnknownRunKey", canonical_job(xi_range + fixed_u_w, "[run]\nmax_bounce = 10\n"),
                  {"unknown key [run] max_bounce (did you mean max_bounces?)"}},
        ErrorCase{"UnknownRangeKey", canonical_job("xi = { min = 0, max = 1, n = 8, step = 2 }\n" + fixed_u_w),
                  {"unknown key [grid] xi.step", "min, max, n"}},
        ErrorCase{"MissingRangeKey", canonical_job("xi = { min = 0, n = 8 }\n" + fixed_u_w), {"[grid] xi.max", "not set"}},
        ErrorCase{"MissingCoordinate", canonical_job(xi_range + "U = -1\n"), {"[grid] W", "not set"}},
        ErrorCase{"MissingPhysicalCoordinate", physical_job("", "x = 1\nu = { min = -2, max = -1, n = 3 }\nv = 1\n"),
                  {"[grid] omega", "not set"}},
        ErrorCase{"StringCoordinate", canonical_job(xi_range + "U = \"-1\"\nW = 0\n"),
                  {"[grid] U = \"-1\"", "a string", "expected a number"}},
        ErrorCase{"BooleanCoordinate", canonical_job(xi_range + "U = true\nW = 0\n"), {"[grid] U = true", "a boolean"}},
        ErrorCase{"ArrayCoordinate", canonical_job(xi_range + "U = [-1, 0]\nW = 0\n"), {"[grid] U", "an array"}},
        ErrorCase{"StringRangeBound", canonical_job("xi = { min = \"0\", max = 1, n = 8 }\n" + fixed_u_w),
                  {"[grid] xi.min = \"0\"", "a string", "expected a number"}},
        ErrorCase{"CoefficientAsString", "[model]\ne = \"0.9\"\nalpha = 0.9\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] e = \"0.9\"", "a string", "expected a number"}},
        ErrorCase{"NanFixed", canonical_job(xi_range + "U = nan\nW = 0\n"), {"[grid] U = nan", "not finite"}},
        ErrorCase{"InfRangeBound", canonical_job("xi = { min = 0, max = inf, n = 8 }\n" + fixed_u_w),
                  {"[grid] xi.max = inf", "not finite"}},
        ErrorCase{"NegativeInfFixed", canonical_job(xi_range + "U = -inf\nW = 0\n"), {"[grid] U = -inf", "not finite"}},
        ErrorCase{"MinEqualsMax", canonical_job("xi = { min = 1, max = 1, n = 8 }\n" + fixed_u_w),
                  {"[grid] xi", "min = 1", "max = 1", "min < max"}},
        ErrorCase{"MinAboveMax", canonical_job("xi = { min = 2, max = 1, n = 8 }\n" + fixed_u_w),
                  {"[grid] xi", "min = 2", "max = 1", "min < max"}},
        ErrorCase{"NZero", canonical_job("xi = { min = 0, max = 1, n = 0 }\n" + fixed_u_w),
                  {"[grid] xi.n = 0 is out of range: accepted n >= 1"}},
        ErrorCase{"NNegative", canonical_job("xi = { min = 0, max = 1, n = -4 }\n" + fixed_u_w), {"[grid] xi.n = -4", "n >= 1"}},
        ErrorCase{"NFractional", canonical_job("xi = { min = 0, max = 1, n = 2.5 }\n" + fixed_u_w),
                  {"[grid] xi.n = 2.5", "floating-point", "expected an integer"}},
        ErrorCase{"NWholeFloat", canonical_job("xi = { min = 0, max = 1, n = 2.0 }\n" + fixed_u_w),
                  {"[grid] xi.n = 2.0", "expected an integer"}},
        ErrorCase{"EOutOfRange", "[model]\ne = 0.9\nalpha = 0.9\ne_wall = 1.5\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] e_wall = 1.5 is out of range", "0 < e <= 1"}},
        ErrorCase{"EZero", "[model]\ne = 0\nalpha = 0.9\n[grid]\n" + xi_range + fixed_u_w, {"[model] e = 0", "0 < e <= 1"}},
        ErrorCase{"AlphaOutOfRange", "[model]\ne = 0.9\nalpha = -1.5\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] alpha = -1.5", "-1 <= alpha <= 1"}},
        ErrorCase{"NanCoefficient", "[model]\ne = nan\nalpha = 0.9\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] e = nan", "out of range"}},
        ErrorCase{"MissingCoefficient", "[model]\ne = 0.9\nalpha_wall = 0.9\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] alpha_floor", "not set"}},
        ErrorCase{"MissingModel", "[grid]\n" + xi_range + fixed_u_w, {"[model] e_wall", "not set"}},
        ErrorCase{"NoRange", canonical_job("xi = 0.5\n" + fixed_u_w), {"[grid]", "no range", "1 to 3"}},
        ErrorCase{"FourRanges",
                  physical_job("", "x = { min = 0, max = 1, n = 2 }\nu = { min = -2, max = -1, n = 2 }\n"
                                   "v = { min = 1, max = 2, n = 2 }\nomega = { min = -1, max = 1, n = 2 }\n"),
                  {"[grid] has 4 ranges", "x, u, v, omega", "1 to 3"}},
        ErrorCase{"GOnCanonical", "[model]\ne = 0.9\nalpha = 0.9\ng = 9.81\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] g applies to physical grids only"}},
        ErrorCase{"RadiusOnCanonical", "[model]\ne = 0.9\nalpha = 0.9\nradius = 0.1\n[grid]\n" + xi_range + fixed_u_w,
                  {"[model] radius applies to physical grids only"}},
        ErrorCase{"GNegative", physical_job("g = -9.81\n", physical_grid), {"[model] g = -9.81", "g > 0"}},
        ErrorCase{"RadiusInfinite", physical_job("radius = inf\n", physical_grid), {"[model] radius = inf", "radius > 0"}},
        ErrorCase{"GString", physical_job("g = \"earth\"\n", physical_grid), {"[model] g = \"earth\"", "a number"}},
        ErrorCase{"BadCoordinatesString", canonical_job("coordinates = \"polar\"\n" + xi_range + fixed_u_w),
                  {"[grid] coordinates = \"polar\"", "\"canonical\" or \"physical\""}},
        ErrorCase{"CoordinatesNotString", canonical_job("coordinates = 3\n" + xi_range + fixed_u_w),
                  {"[grid] coordinates = 3", "an integer", "\"canonical\" or \"physical\""}},
        ErrorCase{"MaxBouncesZero", canonical_job(xi_range + fixed_u_w, "[run]\nmax_bounces = 0\n"),
                  {"[run] max_bounces = 0 is out of range", "1 <= max_bounces <= 4294967295"}},
        ErrorCase{"MaxBouncesTooLarge", canonical_job(xi_range + fixed_u_w, "[run]\nmax_bounces = 4294967296\n"),
                  {"[run] max_bounces = 4294967296", "4294967295"}},
        ErrorCase{"MaxBouncesFloat", canonical_job(xi_range + fixed_u_w, "[run]\nmax_bounces = 1e3\n"),
                  {"[run] max_bounces = 1000.0", "floating-point", "expected an integer"}},
        ErrorCase{"OutputNotString", canonical_job(xi_range + fixed_u_w, "[run]\noutput = 5\n"),
                  {"[run] output = 5", "expected a string"}},
        ErrorCase{"OutputEmpty", canonical_job(xi_range + fixed_u_w, "[run]\noutput = \"\"\n"), {"[run] output", "empty"}},
        ErrorCase{"WritersZero", canonical_job(xi_range + fixed_u_w, "[run]\nwriters = 0\n"),
                  {"[run] writers = 0 is out of range", "\"auto\" or a count of writers from 1 to 65536"}},
        ErrorCase{"WritersWord", canonical_job(xi_range + fixed_u_w, "[run]\nwriters = \"all\"\n"),
                  {"[run] writers = \"all\"", "\"auto\" or a count"}},
        ErrorCase{"WritersFloat", canonical_job(xi_range + fixed_u_w, "[run]\nwriters = 4.0\n"), {"[run] writers", "integer"}},
        ErrorCase{"TilePointsZero", canonical_job(xi_range + fixed_u_w, "[run]\ntile_points = 0\n"),
                  {"[run] tile_points = 0", "1 <= tile_points <= 16777216"}},
        ErrorCase{"TilePointsTooLarge", canonical_job(xi_range + fixed_u_w, "[run]\ntile_points = 16777217\n"),
                  {"[run] tile_points = 16777217", "16777216"}},
        ErrorCase{"SyntaxError", canonical_job(xi_range + "U = -1\nW = = 0\n"), {"jobs/test.toml:", "syntax error"}},
        ErrorCase{"DuplicateKey", canonical_job(xi_range + fixed_u_w + "U = -2\n"), {"syntax error", "U"}},
        ErrorCase{"DuplicateTable", canonical_job(xi_range + fixed_u_w, "[model]\ne = 1\n"), {"syntax error", "model"}},
        ErrorCase{"EmptyText", "", {"not set"}},
        ErrorCase{"HugeGrid",
                  canonical_job("xi = { min = 0, max = 1, n = 1048576 }\nU = { min = -1, max = 0, n = 2 }\n"
                                "W = { min = 0, max = 1, n = 1048576 }"),
                  {"[grid] has 1048576 x 2 x 1048576 = 2199023255552 points", "2^40"}},
        ErrorCase{"OverflowingGrid",
                  canonical_job("xi = { min = 0, max = 1, n = 9223372036854775807 }\nU = { min = -1, max = 0, n = 4 }\n"
                                "W = { min = 0, max = 1, n = 9223372036854775807 }"),
                  {"[grid] has 9223372036854775807 x 4 x 9223372036854775807 = more than 2^64 points"}},
        ErrorCase{"RangeWidthOverflows", canonical_job("xi = { min = -1e308, max = 1e308, n = 8 }\n" + fixed_u_w),
                  {"[grid] xi", "min = -1e+308", "max = 1e+308", "overflows"}},
        ErrorCase{"SamplesOverflow", canonical_job("xi = { min = 0, max = 1.7e308, n = 2 }\n" + fixed_u_w),
                  {"[grid] xi", "n = 2", "the samples overflow"}},
        ErrorCase{"BinaryGarbage", std::string("\x7f" "ELF\x02\x01\x01\0\0\xff\xfe[[", 13), {"jobs/test.toml:", "syntax error"}},
        ErrorCase{"RefineNotPowerOfTwo", canonical_job(xi_range + fixed_u_w, "[run]\nrefine = 6\n"),
                  {"[run] refine = 6 is out of range"}},
        ErrorCase{"RefineString", canonical_job(xi_range + fixed_u_w, "[run]\nrefine = \"yes\"\n"),
                  {"[run] refine = \"yes\"", "expected an integer"}},
        ErrorCase{"MisspelledCoordinatesString", canonical_job("coordinates = \"Physical\"\n" + xi_range + fixed_u_w),
                  {"[grid] coordinates = \"Physical\"", "did you mean \"physical\"?"}}),
    [](const testing::TestParamInfo<ErrorCase>& info) { return std::string(info.param.name); });

// The syntax error message places the error in the file.
TEST(JobSyntax, MessageHasLineAndColumn)
{
    const std::string message = error_of("[model]\ne = 0.9\nalpha = 0.9 0.8\n");
    EXPECT_EQ(message.rfind("jobs/test.toml:3:", 0), 0u) << message;
}

// --- load_job --------------------------------------------------------------------------------

std::filesystem::path temp_path(const std::string& stem)
{
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    return std::filesystem::path(testing::TempDir()) / (std::string(info->name()) + "_" + stem);
}

TEST(LoadJob, ReadsFileAndKeepsText)
{
    const std::string text = canonical_job(xi_range + fixed_u_w);
    const auto path = temp_path("job.toml");
    {
        std::ofstream out(path, std::ios::binary);
        out << text;
    }
    const Job job = load_job(path);
    EXPECT_EQ(job.text, text);
    EXPECT_EQ(job.points(), 8u);
    std::filesystem::remove(path);
}

TEST(LoadJob, ErrorsNameTheFile)
{
    const auto path = temp_path("bad.toml");
    {
        std::ofstream out(path, std::ios::binary);
        out << canonical_job("xi = { min = 0, max = 1, n = 0 }\n" + fixed_u_w);
    }
    try {
        load_job(path);
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": [grid] xi.n = 0", 0), 0u) << e.what();
    }
    std::filesystem::remove(path);
}

TEST(LoadJob, MissingFile)
{
    const auto path = temp_path("does-not-exist.toml");
    try {
        load_job(path);
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("cannot read job file " + path.string()), std::string::npos) << message;
        EXPECT_NE(message.find("No such file"), std::string::npos) << message;
    }
}

TEST(LoadJob, Directory)
{
    try {
        load_job(testing::TempDir());
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot read job file"), std::string::npos) << e.what();
    }
}

// --- Fingerprints ----------------------------------------------------------------------------

const std::string base_job = R"(
[model]
e = 0.9
alpha = 0.9
[grid]
xi = { min = 0.0, max = 1.0, n = 64 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 64 }
[run]
max_bounces = 1000
output = "a.h5"
)";

std::string fingerprint_of(const std::string& text) { return fingerprint(parse_job(text, source)); }

TEST(Fingerprint, IgnoresCommentsOrderOutputAndTiling)
{
    const std::string reordered = R"(
# the same job, written differently
[run]
output = "elsewhere/b.h5"   # another place
tile_points = 1024
[grid]
W = { n = 64, min = -3, max = 3 }
U = -1
coordinates = "canonical"
xi = { max = 1, min = 0, n = 64 }
[model]
alpha_wall = 0.9
alpha = 0.9
e = 0.9
)";
    EXPECT_EQ(fingerprint_of(base_job), fingerprint_of(reordered));
    // max_bounces = 1000 is the default.
    EXPECT_EQ(fingerprint_of(base_job), fingerprint_of(R"(
[model]
e = 0.9
alpha = 0.9
[grid]
xi = { min = 0.0, max = 1.0, n = 64 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 64 }
)"));
}

struct FingerprintChange {
    const char* name;
    std::string from;
    std::string to;
};

void PrintTo(const FingerprintChange& c, std::ostream* os) { *os << c.name; }

class FingerprintDiffers : public testing::TestWithParam<FingerprintChange> {};

TEST_P(FingerprintDiffers, WhenResultsWouldDiffer)
{
    const FingerprintChange& c = GetParam();
    std::string changed = base_job;
    const auto at = changed.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    changed.replace(at, c.from.size(), c.to);
    EXPECT_NE(fingerprint_of(base_job), fingerprint_of(changed)) << changed;
}

INSTANTIATE_TEST_SUITE_P(Cases, FingerprintDiffers,
                         testing::Values(FingerprintChange{"RangeSize", "n = 64 }\nU", "n = 65 }\nU"},
                                         FingerprintChange{"RangeMin", "min = 0.0", "min = 0.001"},
                                         FingerprintChange{"FixedValue", "U = -1.0", "U = -1.0000000000000002"},
                                         FingerprintChange{"FixedBecomesRange", "U = -1.0",
                                                           "U = { min = -2, max = -1, n = 1 }"},
                                         FingerprintChange{"SharedE", "e = 0.9", "e = 0.8"},
                                         FingerprintChange{"WallOverride", "alpha = 0.9", "alpha = 0.9\nalpha_wall = 0.5"},
                                         FingerprintChange{"MaxBounces", "max_bounces = 1000", "max_bounces = 999"}),
                         [](const testing::TestParamInfo<FingerprintChange>& info) { return std::string(info.param.name); });

TEST(Fingerprint, PhysicalIncludesFrame)
{
    const std::string job = model_section + "[grid]\ncoordinates = \"physical\"\n" + physical_grid;
    const std::string with_g = model_section + "g = 1.62\n[grid]\ncoordinates = \"physical\"\n" + physical_grid;
    const std::string with_radius = model_section + "radius = 0.03\n[grid]\ncoordinates = \"physical\"\n" + physical_grid;
    const std::string with_default_g = model_section + "g = 9.81\n[grid]\ncoordinates = \"physical\"\n" + physical_grid;
    EXPECT_NE(fingerprint_of(job), fingerprint_of(with_g));
    EXPECT_NE(fingerprint_of(job), fingerprint_of(with_radius));
    EXPECT_EQ(fingerprint_of(job), fingerprint_of(with_default_g));
    EXPECT_NE(fingerprint_of(job).find("g = 9.81"), std::string::npos);
}

TEST(Fingerprint, CanonicalOmitsFrame)
{
    const std::string fp = fingerprint_of(base_job);
    EXPECT_EQ(fp.find("g = "), std::string::npos) << fp;
    EXPECT_EQ(fp.find("radius"), std::string::npos) << fp;
    EXPECT_NE(fp.find("coordinates = canonical"), std::string::npos) << fp;
}

}  // namespace
// --- Swept coefficients (issue 6) --------------------------------------------------------

namespace {

std::string sweep_job(const std::string& model, const std::string& grid)
{
    return "[model]\n" + model + "\n[grid]\n" + grid;
}

const std::string one_coordinate_range = "xi = { min = 0, max = 1, n = 8 }\nU = -1\nW = 0\n";

}  // namespace

TEST(Sweep, CoefficientRangeIsAnAxisBeforeTheCoordinates)
{
    const Job job = parse_job(sweep_job("e = 0.9\nalpha = { min = 0.5, max = 1, n = 4 }\ne_floor = 0.8\n", one_coordinate_range),
                              source);
    ASSERT_EQ(job.parameters.size(), 1u);
    EXPECT_EQ(job.parameters[0].name, "alpha");
    const auto axes = job.range_axes();
    ASSERT_EQ(axes.size(), 2u);
    EXPECT_EQ(axes[0]->name, "alpha");
    EXPECT_EQ(axes[1]->name, "xi");
    EXPECT_EQ(job.points(), 32u);
    // alpha sets both surfaces' alpha; e_wall comes from e, e_floor is fixed.
    EXPECT_EQ(job.swept, (std::array<int, swept_coefficients>{-1, 0, -1, 0, -1, -1, -1}));
    const double value[] = {0.7};
    const Model m = job.model_at(value);
    EXPECT_EQ(m.wall.alpha, 0.7);
    EXPECT_EQ(m.floor.alpha, 0.7);
    EXPECT_EQ(m.wall.e, 0.9);
    EXPECT_EQ(m.floor.e, 0.8);
}

TEST(Sweep, PerSurfaceRangeOverridesSharedValue)
{
    const Job job = parse_job(
        sweep_job("e = 0.9\nalpha = 0.9\ne_wall = { min = 0.2, max = 0.4, n = 3 }\n", one_coordinate_range), source);
    EXPECT_EQ(job.swept, (std::array<int, swept_coefficients>{0, -1, -1, -1, -1, -1, -1}));
    const double value[] = {0.3};
    EXPECT_EQ(job.model_at(value).wall.e, 0.3);
    EXPECT_EQ(job.model_at(value).floor.e, 0.9);
}

TEST(Sweep, OnlyCoefficientAxes)
{
    const Job job = parse_job(sweep_job("e = { min = 0.5, max = 1, n = 3 }\nalpha = { min = 0, max = 1, n = 5 }\n",
                                        "xi = 0.05\nU = -1\nW = -2\n"),
                              source);
    EXPECT_EQ(job.points(), 15u);
    EXPECT_EQ(job.range_axes().size(), 2u);
}

TEST(Sweep, FingerprintIncludesTheSweep)
{
    const std::string a = sweep_job("e = 0.9\nalpha = { min = 0.5, max = 1, n = 4 }\n", one_coordinate_range);
    const std::string b = sweep_job("e = 0.9\nalpha = { min = 0.5, max = 1, n = 5 }\n", one_coordinate_range);
    EXPECT_NE(fingerprint(parse_job(a, source)), fingerprint(parse_job(b, source)));
}

// SPEC.md 1b: mu (both surfaces, per-surface keys override) and inertia, each a value or a
// swept axis like e and alpha; absent, the Cross model of a solid ball.
TEST(Friction, DefaultsAreTheCrossModelOfASolidBall)
{
    const Job job = parse_job(sweep_job("e = 0.9\nalpha = 0.9\n", one_coordinate_range), source);
    EXPECT_EQ(job.model.wall.mu, std::numeric_limits<double>::infinity());
    EXPECT_EQ(job.model.floor.mu, std::numeric_limits<double>::infinity());
    EXPECT_EQ(job.model.inertia, 0.4);
    // The fingerprint of such a job is the one it had before mu and inertia existed.
    EXPECT_EQ(fingerprint(job).find("mu"), std::string::npos);
    EXPECT_EQ(fingerprint(job).find("inertia"), std::string::npos);
}

TEST(Friction, ValuesAndPerSurfaceOverrides)
{
    const Job job =
        parse_job(sweep_job("e = 0.9\nalpha = 0.9\nmu = 1.5\nmu_floor = 0.3\ninertia = 0.6\n", one_coordinate_range), source);
    EXPECT_EQ(job.model.wall.mu, 1.5);
    EXPECT_EQ(job.model.floor.mu, 0.3);
    EXPECT_EQ(job.model.inertia, 0.6);
    EXPECT_NE(fingerprint(job).find("mu_wall = 1.5\nmu_floor = 0.3\ninertia = 0.6\n"), std::string::npos) << fingerprint(job);
    const Job infinite = parse_job(sweep_job("e = 0.9\nalpha = 0.9\nmu = inf\n", one_coordinate_range), source);
    EXPECT_EQ(infinite.model.wall.mu, std::numeric_limits<double>::infinity());
    EXPECT_EQ(fingerprint(infinite), fingerprint(parse_job(sweep_job("e = 0.9\nalpha = 0.9\n", one_coordinate_range), source)));
}

TEST(Friction, MuAndInertiaSweep)
{
    const Job job = parse_job(sweep_job("e = 0.9\nalpha = 0.9\nmu = { min = 0.5, max = 3, n = 6 }\n"
                                        "inertia = { min = 0.3, max = 0.6, n = 4 }\n",
                                        one_coordinate_range),
                              source);
    ASSERT_EQ(job.parameters.size(), 2u);
    EXPECT_EQ(job.parameters[0].name, "mu");
    EXPECT_EQ(job.parameters[1].name, "inertia");
    EXPECT_EQ(job.swept, (std::array<int, swept_coefficients>{-1, -1, -1, -1, 0, 0, 1}));
    const double values[] = {2.0, 0.5};
    const Model m = job.model_at(values);
    EXPECT_EQ(m.wall.mu, 2.0);
    EXPECT_EQ(m.floor.mu, 2.0);
    EXPECT_EQ(m.inertia, 0.5);
    EXPECT_EQ(job.points(), 6u * 4u * 8u);
}

TEST(Friction, BadValuesNameKeyValueAndRange)
{
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {"mu = -0.1\n", {"[model] mu = -0.1 is out of range", "0 <= mu"}},
        {"mu = nan\n", {"[model] mu = nan is out of range"}},
        {"mu_wall = -1\n", {"[model] mu_wall = -1 is out of range"}},
        {"inertia = 0\n", {"[model] inertia = 0 is out of range", "0 < inertia <= 2/3"}},
        {"inertia = 0.7\n", {"[model] inertia = 0.7 is out of range"}},
        {"inertia = \"solid\"\n", {"[model] inertia = \"solid\"", "a string"}},
        {"mu = { min = -1, max = 1, n = 4 }\n", {"[model] mu.min = -1", "0 <= mu"}},
        {"mu = { min = 0.5, max = 1, n = 4 }\nmu_wall = 1\nmu_floor = 1\n", {"[model] mu is a range", "nothing would follow it"}},
        {"inertie = 0.5\n", {"unknown key [model] inertie (did you mean inertia?)"}},
    };
    for (const auto& [extra, needles] : cases) {
        const std::string message = error_of(sweep_job("e = 0.9\nalpha = 0.9\n" + extra, one_coordinate_range));
        ASSERT_FALSE(message.empty()) << extra;
        for (const std::string& needle : needles) EXPECT_NE(message.find(needle), std::string::npos) << message;
    }
}

TEST(Sweep, Errors)
{
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        // A range end out of the physical range names the end.
        {sweep_job("e = 0.9\nalpha = { min = 0.5, max = 1.5, n = 4 }\n", one_coordinate_range),
         {"[model] alpha.max = 1.5", "-1 <= alpha <= 1"}},
        {sweep_job("e = { min = 0, max = 1, n = 4 }\nalpha = 0.5\n", one_coordinate_range), {"[model] e.min = 0", "0 < e <= 1"}},
        {sweep_job("e = 0.9\nalpha = { min = 0.5, max = 0.5, n = 4 }\n", one_coordinate_range), {"[model] alpha", "min < max"}},
        {sweep_job("e = 0.9\nalpha = { min = 0.1, max = 0.5, n = 0 }\n", one_coordinate_range), {"[model] alpha.n"}},
        {sweep_job("e = 0.9\nalpha = { min = 0.1, max = 0.5, n = 4, step = 1 }\n", one_coordinate_range),
         {"[model] alpha.step"}},
        // Shadowed: nothing would follow e.
        {sweep_job("e = { min = 0.5, max = 1, n = 4 }\nalpha = 0.5\ne_wall = 0.9\ne_floor = 0.9\n", one_coordinate_range),
         {"[model] e is a range", "nothing would follow it"}},
        // Five range axes.
        {sweep_job("e = { min = 0.5, max = 1, n = 2 }\nalpha = { min = 0, max = 1, n = 2 }\n",
                   "xi = { min = 0, max = 1, n = 2 }\nU = { min = -2, max = -1, n = 2 }\nW = { min = -1, max = 1, n = 2 }\n"),
         {"5 range axes", "at most 4"}},
    };
    for (const auto& [text, needles] : cases) {
        const std::string message = error_of(text);
        ASSERT_FALSE(message.empty()) << text;
        for (const std::string& needle : needles) EXPECT_NE(message.find(needle), std::string::npos) << message;
    }
}

}  // namespace superball
