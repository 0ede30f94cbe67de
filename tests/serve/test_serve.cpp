// Unit tests of the server's library (src/serve) below HTTP: request parameters, views and
// their job files, counting a view, tiles, and the worker pool. tests/serve/test_api.py
// checks the same through HTTP against the command line.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/count.hpp"
#include "job/grid.hpp"
#include "serve/pool.hpp"
#include "serve/query.hpp"
#include "serve/region.hpp"
#include "serve/tiles.hpp"
#include "serve/view.hpp"

namespace superball::serve {
namespace {

Parameters quickstart(std::initializer_list<std::pair<const std::string, std::string>> more = {})
{
    Parameters p{{"x", "xi"},     {"x_min", "0"}, {"x_max", "1"}, {"nx", "5"},   {"y", "W"},
                 {"y_min", "-3"}, {"y_max", "3"}, {"ny", "4"},    {"U", "-1"},   {"e", "0.9"},
                 {"alpha", "0.9"}};
    for (const auto& [k, v] : more) {  // an empty value removes the key
        p.erase(k);
        if (!v.empty()) p.emplace(k, v);
    }
    return p;
}

View view_of(const Parameters& p, bool sizes = true)
{
    Query q(p, view_keys(sizes));
    return parse_view(q, Limits{}, sizes);
}

std::string error_of(const Parameters& p, bool sizes = true)
{
    try {
        view_of(p, sizes);
    } catch (const RequestError& e) {
        EXPECT_EQ(e.status, 400);
        return e.what();
    }
    return "no error";
}

TEST(Query, RefusesUnknownAndRepeatedKeysAndBadNumbers)
{
    const Parameters unknown{{"xii", "1"}};
    try {
        Query q(unknown, {"xi", "U"});
        FAIL() << "accepted";
    } catch (const RequestError& e) {
        EXPECT_EQ(std::string(e.what()), "unknown parameter xii (did you mean xi?): accepted xi or U");
    }
    const Parameters twice{{"xi", "1"}, {"xi", "2"}};
    Query q(twice, {"xi"});
    EXPECT_THROW(q.number("xi"), RequestError);
    const Parameters bad{{"a", "1x"}, {"b", ""}, {"c", "1e999"}, {"n", "12"}, {"m", "-3"}};
    Query r(bad, {"a", "b", "c", "n", "m"});
    EXPECT_THROW(r.number("a"), RequestError);
    EXPECT_THROW(r.number("b"), RequestError);
    EXPECT_EQ(*r.number("c"), HUGE_VAL);
    EXPECT_THROW(r.finite("c"), RequestError);
    EXPECT_EQ(*r.integer("n", 1, 12, "1 to 12"), 12);
    EXPECT_THROW(r.integer("m", 1, 12, "1 to 12"), RequestError);
    EXPECT_THROW(r.number("not_accepted"), std::logic_error);
}

TEST(View, ReadsAPlaneAndNamesWhatIsWrong)
{
    const View v = view_of(quickstart());
    EXPECT_EQ(v.plane.x, 0);
    EXPECT_EQ(v.plane.y, 2);
    EXPECT_EQ(v.plane.fixed, 1);
    EXPECT_EQ(v.x, (Range{0, 1, 5}));
    EXPECT_EQ(v.y, (Range{-3, 3, 4}));
    EXPECT_EQ(v.fixed, -1);
    EXPECT_EQ(v.max_bounces, 1000u);
    EXPECT_EQ(error_of(quickstart({{"x_min", "1"}, {"x_max", "0"}})), "x_min = 1 and x_max = 0: accepted x_min < x_max");
    EXPECT_EQ(error_of(quickstart({{"nx", "0"}})), "nx = 0 is out of range: accepted nx >= 1");
    EXPECT_EQ(error_of(quickstart({{"y", "xi"}})), "x = xi and y = xi are the same axis: accepted two different axes of xi, U, W");
    EXPECT_EQ(error_of(quickstart({{"e", "2"}})), "e = 2 is out of range: accepted 0 < e <= 1");
    EXPECT_NE(error_of(quickstart({{"xi", "0.5"}})).find("xi is given, but it is the x axis"), std::string::npos);
}

TEST(View, ItsJobIsWhatParseJobReadsBack)
{
    const View v = view_of(quickstart({{"x", "W"}, {"x_min", "-2.5"}, {"x_max", "1e-05"}, {"y", "U"}, {"y_min", "-3"},
                                       {"y_max", "-0.1"}, {"U", ""}, {"xi", "0.1"}, {"e_floor", "0.7"},
                                       {"max_bounces", "77"}}));
    const Job job = parse_job(job_toml(v, "out.h5"), "test");
    EXPECT_EQ(job.grid[0].fixed, 0.1);
    EXPECT_EQ(job.grid[1].range, (Range{-3, -0.1, 4}));  // y = U
    EXPECT_EQ(job.grid[2].range, (Range{-2.5, 1e-05, 5}));  // x = W
    EXPECT_EQ(job.model.wall.e, 0.9);
    EXPECT_EQ(job.model.floor.e, 0.7);
    EXPECT_EQ(job.model.floor.alpha, 0.9);
    EXPECT_EQ(job.max_bounces, 77u);
    EXPECT_EQ(job.output, "out.h5");
    EXPECT_EQ(fingerprint(job), fingerprint(job_of(v)));
}

TEST(View, NeighbouringTilesShareTheirEdgesExactly)
{
    const View window = view_of(quickstart({{"nx", ""}, {"ny", ""}}), false);
    for (const int z : {0, 3, 17, 40}) {
        const std::int64_t t = (std::int64_t{1} << z) / 3;
        const View a = tile_view(window, z, t, t, 256), right = tile_view(window, z, t + 1, t, 256),
                   below = tile_view(window, z, t, t + 1, 256);
        EXPECT_EQ(a.x.max, right.x.min) << z;
        EXPECT_EQ(a.y.min, below.y.max) << z;
        EXPECT_LT(a.x.sample(255), right.x.sample(0)) << z;
    }
    EXPECT_THROW(tile_view(window, 60, 0, 0, 256), RequestError);
}

TEST(Region, CountsEveryPointAsCountDoesRowsAlongY)
{
    for (const auto& axes : {std::pair{"xi", "W"}, std::pair{"W", "xi"}}) {
        const View v = view_of(quickstart({{"x", axes.first}, {"x_min", axes.first == std::string("xi") ? "0" : "-3"},
                                           {"x_max", axes.first == std::string("xi") ? "1" : "3"},
                                           {"y", axes.second}, {"y_min", axes.second == std::string("xi") ? "0" : "-3"},
                                           {"y_max", axes.second == std::string("xi") ? "1" : "3"}, {"nx", "37"},
                                           {"ny", "23"}}));
        RegionWork work(v);
        for (std::size_t b = work.blocks(); b-- > 0;) work.count_block(b);  // any order
        const RegionCounts r = work.take();
        ASSERT_EQ(r.wall_bounces.size(), 37u * 23u);
        for (std::uint64_t j = 0; j < 23; ++j) {
            for (std::uint64_t i = 0; i < 37; ++i) {
                const double x = v.x.sample(i), y = v.y.sample(j);
                const CanonicalState<double> s = v.plane.x == 0 ? CanonicalState<double>{x, -1, y} : CanonicalState<double>{y, -1, x};
                const BounceCount c = count(s, Model::uniform(0.9, 0.9), 1000);
                ASSERT_EQ(r.wall_bounces[j * 37 + i], c.wall_bounces) << i << " " << j;
                ASSERT_EQ(r.outcomes[j * 37 + i], static_cast<std::uint8_t>(c.outcome));
            }
        }
    }
}

TEST(Region, BlocksAreShortWhateverMaxBounces)
{
    for (const char* cap : {"1", "1000", "1000000"}) {
        const View v = view_of(quickstart({{"nx", "1000"}, {"ny", "3"}, {"max_bounces", cap}}));
        RegionWork work(v);
        EXPECT_GE(work.blocks() * block_points, 3000u);
        EXPECT_LE(3000 / work.blocks() * v.max_bounces, 2 * block_iterations) << cap;
    }
}

TEST(Tiles, ColoursAndLegend)
{
    Colouring c;
    EXPECT_EQ(colour_of(c, 5, Outcome::invalid), (Rgb{153, 153, 153}));
    EXPECT_EQ(colour_of(c, 1000, Outcome::capped), (Rgb{0, 0, 0}));
    EXPECT_EQ(colour_of(c, 20, Outcome::left), colour_of(c, 500, Outcome::missed));  // N >= colour_max
    EXPECT_NE(colour_of(c, 1, Outcome::left), colour_of(c, 2, Outcome::left));
    c.outcome = true;
    EXPECT_EQ(colour_of(c, 1, Outcome::missed), (Rgb{255, 127, 14}));
    c = {1, 100, false};
    const nlohmann::json legend = nlohmann::json::parse(legend_json(c));
    EXPECT_EQ(legend["colours"], "viridis");
    std::vector<std::string> labels;
    for (const auto& e : legend["entries"]) labels.push_back(e["label"]);
    EXPECT_NE(std::find(labels.begin(), labels.end(), "N = 70"), labels.end());
    EXPECT_NE(std::find(labels.begin(), labels.end(), "N >= 100"), labels.end());
    EXPECT_EQ(std::string(legend["entries"][0]["colour"]).size(), 7u) << "#rrggbb";
    const std::vector<std::uint8_t> rgba(3 * 2 * 4, 200);
    const std::string png = encode_png(3, 2, rgba);
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_THROW(encode_png(3, 3, rgba), std::invalid_argument);
}

TEST(Pool, InterleavesTasksAndStopsCancelledAndLateOnes)
{
    Pool pool(1, 8);
    std::mutex m;
    std::vector<int> order;
    const auto far = Clock::now() + std::chrono::hours(1);
    // One worker: a long task's blocks alternate with a short task's.
    std::atomic<bool> hold{true};
    auto gate = std::make_shared<Task>(1, [&](std::size_t) { while (hold) std::this_thread::yield(); }, far);
    ASSERT_TRUE(pool.submit(gate));
    auto a = std::make_shared<Task>(4, [&](std::size_t) { std::lock_guard l(m); order.push_back(1); }, far);
    auto b = std::make_shared<Task>(2, [&](std::size_t) { std::lock_guard l(m); order.push_back(2); }, far);
    ASSERT_TRUE(pool.submit(a));
    ASSERT_TRUE(pool.submit(b));
    hold = false;
    EXPECT_EQ(a->wait_for(std::chrono::seconds(10)), Task::Status::done);
    EXPECT_EQ(b->wait_for(std::chrono::seconds(10)), Task::Status::done);
    EXPECT_EQ(order, (std::vector<int>{1, 2, 1, 2, 1, 1}));

    std::atomic<int> ran{0};
    auto cancelled = std::make_shared<Task>(1000, [&](std::size_t) {
        ++ran;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }, far);
    ASSERT_TRUE(pool.submit(cancelled));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    cancelled->cancel();
    EXPECT_EQ(cancelled->wait_for(std::chrono::seconds(10)), Task::Status::cancelled);
    EXPECT_LT(ran.load(), 1000);

    auto late = std::make_shared<Task>(1000, [&](std::size_t) { std::this_thread::sleep_for(std::chrono::milliseconds(1)); },
                                       Clock::now() + std::chrono::milliseconds(20));
    ASSERT_TRUE(pool.submit(late));
    EXPECT_EQ(late->wait_for(std::chrono::seconds(10)), Task::Status::timed_out);

    auto failing = std::make_shared<Task>(3, [](std::size_t b) {
        if (b == 1) throw std::runtime_error("block 1");
    }, far);
    ASSERT_TRUE(pool.submit(failing));
    EXPECT_EQ(failing->wait_for(std::chrono::seconds(10)), Task::Status::failed);
    EXPECT_THROW(std::rethrow_exception(failing->error()), std::runtime_error);

    const PoolStats s = pool.stats();
    EXPECT_EQ(s.tasks, 6u);
    EXPECT_EQ(s.cancelled, 1u);
    EXPECT_EQ(s.timed_out, 1u);
    EXPECT_EQ(s.pending, 0u);
}

TEST(Pool, RefusesTasksBeyondItsQueue)
{
    Pool pool(1, 1);
    std::atomic<bool> hold{true};
    const auto far = Clock::now() + std::chrono::hours(1);
    auto busy = std::make_shared<Task>(2, [&](std::size_t) { while (hold) std::this_thread::yield(); }, far);
    ASSERT_TRUE(pool.submit(busy));  // one block runs, one waits: the task stays queued
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_FALSE(pool.submit(std::make_shared<Task>(1, [](std::size_t) {}, far)));
    EXPECT_EQ(pool.stats().refused, 1u);
    hold = false;
    EXPECT_EQ(busy->wait_for(std::chrono::seconds(10)), Task::Status::done);
}

}  // namespace
}  // namespace superball::serve
