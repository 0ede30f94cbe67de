// The vectorised kernel against the scalar count(): identical on every point.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/count.hpp"
#include "core/count_simd.hpp"

namespace {

using namespace superball;


struct Counts {
    std::vector<std::uint32_t> wall_bounces;
    std::vector<std::uint8_t> outcomes;
};

Counts scalar(const std::vector<CanonicalState<double>>& s, const Model& model, std::uint32_t max)
{
    Counts c{std::vector<std::uint32_t>(s.size()), std::vector<std::uint8_t>(s.size())};
    count_each(Starts::of(s).view(), ModelMatrices::of(model), max, c.wall_bounces, c.outcomes);
    return c;
}

Counts simd(const std::vector<CanonicalState<double>>& s, const Model& model, std::uint32_t max)
{
    // Poisoned outputs: every point must be written.
    Counts c{std::vector<std::uint32_t>(s.size(), 0xdeadbeef), std::vector<std::uint8_t>(s.size(), 0xff)};
    count_each_simd(Starts::of(s).view(), ModelMatrices::of(model), max, c.wall_bounces, c.outcomes);
    return c;
}

void expect_identical(const std::vector<CanonicalState<double>>& s, const Model& model, std::uint32_t max)
{
    const Counts a = scalar(s, model, max);
    const Counts b = simd(s, model, max);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (a.wall_bounces[i] != b.wall_bounces[i] || a.outcomes[i] != b.outcomes[i]) {
            if (++differ <= 5) {
                ADD_FAILURE() << "point " << i << " (xi " << s[i].xi << ", U " << s[i].U << ", W " << s[i].W
                              << "): scalar " << a.wall_bounces[i] << "/" << int(a.outcomes[i]) << ", simd "
                              << b.wall_bounces[i] << "/" << int(b.outcomes[i]);
            }
        }
    }
    EXPECT_EQ(differ, 0u) << "of " << s.size() << " points";
}

// n x n cell centres of xi in (0, 1), W in [-3, 3] at fixed U.
std::vector<CanonicalState<double>> slice(std::size_t n, double U)
{
    std::vector<CanonicalState<double>> s;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = 0; k < n; ++k) {
            s.push_back({(i + 0.5) / n, U, -3.0 + (k + 0.5) * 6.0 / n});
        }
    }
    return s;
}

TEST(Kernels, BenchmarkSliceIdentical)
{
    expect_identical(slice(256, -1.0), Model::uniform(0.9, 0.9), 1000);
}

TEST(Kernels, OtherSlicesAndModelsIdentical)
{
    expect_identical(slice(128, -0.3), Model::uniform(0.95, 0.95), 1000);
    expect_identical(slice(128, -2.0), Model{{0.8, 0.6}, {0.85, 0.7}}, 1000);
    expect_identical(slice(64, -0.5), Model::uniform(1.0, 1.0), 300);  // conservative: many capped
    expect_identical(slice(64, -1.0), Model::uniform(1.0, -1.0), 300);  // smooth elastic
}

TEST(Kernels, RandomStatesIncludingInadmissibleIdentical)
{
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> xi(-0.1, 1.2), U(-3.0, 0.3), W(-5.0, 5.0);
    std::vector<CanonicalState<double>> s;
    for (int i = 0; i < 20000; ++i) s.push_back({xi(rng), U(rng), W(rng)});
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const auto& bad : std::vector<CanonicalState<double>>{
             {nan, -1, 0}, {0.5, nan, 0}, {0.5, -1, inf}, {0.0, -1, 0}, {0.5, -0.0, 0}, {1.0, -1, 0}, {0.5, 0.0, 1}}) {
        s.insert(s.begin() + static_cast<long>(rng() % s.size()), bad);
    }
    expect_identical(s, Model::uniform(0.9, 0.9), 1000);
    expect_identical(s, Model::uniform(0.99, 0.99), 5);  // many capped at a small cap
}

TEST(Kernels, EdgeSizesAndCaps)
{
    const auto s = slice(40, -1.0);
    for (std::size_t n : {0u, 1u, 2u, 3u, 5u, 7u, 511u, 512u, 513u, 1025u}) {
        const std::vector<CanonicalState<double>> part(s.begin(), s.begin() + static_cast<long>(std::min(n, s.size())));
        expect_identical(part, Model::uniform(0.9, 0.9), 1000);
    }
    for (std::uint32_t max : {0u, 1u, 2u, 3u}) expect_identical(s, Model::uniform(0.95, 0.95), max);
}

}  // namespace

namespace {

// count_on_plane() is the limit of count() from inside: for almost every (U, W) a launch
// a hair from the plane gives the same count (the exceptions lie on the boundaries of
// the regions, where the limit itself jumps).
TEST(BoundaryPlane, CountIsTheLimitFromInside)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.9));
    for (const double plane : {0.0, 1.0}) {
        const double inside = plane == 0.0 ? 1e-13 : 1.0 - 1e-13;
        std::size_t same = 0, total = 0, long_lived = 0;
        for (int i = 0; i < 60; ++i) {
            for (int k = 0; k < 60; ++k) {
                const double U = -3.0 + (i + 0.5) * 3.0 / 60, W = -6.0 + (k + 0.5) * 9.0 / 60;
                const BounceCount on = count_on_plane({plane, U, W}, m, 1000);
                const BounceCount near = count({inside, U, W}, m, 1000);
                same += on == near;
                ++total;
                long_lived += on.wall_bounces > 5;
                EXPECT_NE(on.outcome, Outcome::invalid);
            }
        }
        EXPECT_GT(same, total * 99 / 100) << "plane xi = " << plane;
        if (plane == 0.0) {
            EXPECT_GT(long_lived, 100u);  // the corner's unstable fixed point draws long motions
        }
    }
    // Off the planes, and non-launches, are invalid; the kernel agrees with the function.
    EXPECT_EQ(count_on_plane({0.5, -1.0, 0.0}, m, 1000).outcome, Outcome::invalid);
    EXPECT_EQ(count_on_plane({0.0, 0.5, 0.0}, m, 1000).outcome, Outcome::invalid);
    EXPECT_EQ(count_on_plane({1.0, -1.0, 0.0}, m, 0), (BounceCount{0, Outcome::capped}));
    const Starts s = Starts::of(std::vector<CanonicalState<double>>{{0.0, -1.0, -2.5}, {1.0, -0.5, 1.0}, {0.3, -1, 0}});
    std::vector<std::uint32_t> wb(3);
    std::vector<std::uint8_t> oc(3);
    count_each_on_plane(s.view(), m, 1000, wb, oc);
    for (std::size_t i = 0; i < 3; ++i) {
        const BounceCount r = count_on_plane(s.view()[i], m, 1000);
        EXPECT_EQ(wb[i], r.wall_bounces);
        EXPECT_EQ(oc[i], static_cast<std::uint8_t>(r.outcome));
    }
}

}  // namespace
