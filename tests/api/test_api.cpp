// The public C++ API (src/api/superball/superball.hpp), used as an installed program would:
// counts equal one by one and on threads, bad input refused naming it, a job run and its
// result read back equal to the counts of its grid's points.
#include <gtest/gtest.h>

#include <superball/superball.hpp>

#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../temp_dir.hpp"

namespace {

namespace api = superball::api;

const api::Coefficients nine{0.9, 0.9, {}, {}, {}, {}};

TEST(Api, CountsOneByOneAndOnThreadsAlike)
{
    const api::Count one = api::count(0.05, -1.0, -2.0, nine);
    EXPECT_EQ(one.wall_bounces, 8u);
    EXPECT_EQ(one.outcome, api::Outcome::left);
    std::vector<double> xi, U, W;
    for (int i = 0; i < 3000; ++i) {
        xi.push_back(0.001 + 0.998 * (i % 100) / 99.0);
        U.push_back(-1.0);
        W.push_back(-3.0 + 6.0 * (i / 100) / 29.0);
    }
    std::vector<std::uint32_t> counts(xi.size());
    std::vector<api::Outcome> outcomes(xi.size());
    api::count(xi, U, W, nine, 1000, counts, outcomes, 2);
    for (std::size_t i = 0; i < xi.size(); ++i) {
        const api::Count c = api::count(xi[i], U[i], W[i], nine);
        ASSERT_EQ(counts[i], c.wall_bounces) << i;
        ASSERT_EQ(outcomes[i], c.outcome) << i;
    }
}

TEST(Api, BadInputIsRefusedNamingIt)
{
    const auto message = [](auto call) {
        try {
            call();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(message([] { api::count(0.05, -1.0, -2.0, {1.5, 0.9, {}, {}, {}, {}}); }).find("e = 1.5 is out of range"),
              std::string::npos);
    EXPECT_NE(message([] { api::count(0.05, -1.0, -2.0, nine, 0); }).find("max_bounces = 0 is out of range"),
              std::string::npos);
    EXPECT_NE(message([] { api::count(0.05, -1.0, -2.0, {0.9, {}, {}, {}, {}, {}}); }).find("alpha"), std::string::npos);
    std::vector<double> three(3, 0.5), two(2, -1.0);
    std::vector<std::uint32_t> counts(3);
    std::vector<api::Outcome> outcomes(3);
    EXPECT_NE(message([&] { api::count(three, two, three, nine, 1000, counts, outcomes); }).find("as many each"),
              std::string::npos);
}

TEST(Api, RunsAJobAndReadsItsResult)
{
    const superball::test_support::TempDir dir("superball-api");
    const std::string job = (dir / "job.toml").string();
    std::ofstream(job) << "[model]\ne = 0.9\nalpha = 0.9\n[grid]\ncoordinates = \"canonical\"\n"
                          "xi = { min = 0.01, max = 0.99, n = 40 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 24 }\n"
                          "[run]\nmax_bounces = 1000\n";
    api::RunOptions options;
    options.output = dir / "result.h5";
    options.threads = 2;
    const api::RunResult run = api::run_job(job, options);
    EXPECT_TRUE(run.complete);
    EXPECT_EQ(run.points_this_run, 40u * 24u);
    const api::Result result(run.output);
    EXPECT_TRUE(result.complete());
    ASSERT_EQ(result.axis_names(), (std::vector<std::string>{"xi", "W"}));
    ASSERT_EQ(result.shape(), (std::vector<std::uint64_t>{40, 24}));
    EXPECT_NE(result.job_toml().find("max_bounces = 1000"), std::string::npos);
    const std::vector<double> xi = result.axis(0), W = result.axis(1);
    std::vector<std::uint32_t> counts(40 * 24);
    std::vector<api::Outcome> outcomes(40 * 24);
    result.read({0, 0}, {40, 24}, counts, outcomes);
    for (std::size_t i = 0; i < 40; ++i) {
        for (std::size_t j = 0; j < 24; ++j) {
            const api::Count c = api::count(xi[i], -1.0, W[j], nine);
            ASSERT_EQ(counts[i * 24 + j], c.wall_bounces) << i << " " << j;
            ASSERT_EQ(outcomes[i * 24 + j], c.outcome) << i << " " << j;
        }
    }
    // Not overwritten unless asked.
    EXPECT_THROW(api::run_job(job, options), std::invalid_argument);
    std::vector<std::uint32_t> one(1);
    std::vector<api::Outcome> one_outcome(1);
    EXPECT_THROW(result.read({40, 0}, {1, 1}, one, one_outcome), std::invalid_argument);
}

}  // namespace
