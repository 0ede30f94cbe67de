// Numerical edge cases of counting: starts at and extremely near the planes xi = 0 and
// xi = 1, U -> 0-, huge |W|, subnormal numbers, no dissipation (e = alpha = 1), a smooth
// ball (alpha = -1), counts above 65535, and arbitrary bit patterns. On every one the
// scalar count() and every variant of the vectorised kernel this processor runs agree, and every input gets an
// Outcome with its contract (invalid: 0 impacts; capped: exactly max_bounces; never more
// than max_bounces).
//
// The decision these tests pin down (map.hpp, representable): a step of G that leaves the
// range of double precision (lambda zero or infinite, U' or W' infinite, xi' NaN) does not
// count as a miss or a leave: the start is reported invalid with 0 impacts. That happens
// for |W| (or |U|) beyond about 1e154, where v+^2 overflows, and for a subnormal e, where
// lambda underflows; never for starts of any physical scale (SaneStartsStayRepresentable).
// Where the double computation stays in range it agrees with the same map evaluated in
// 80-bit long double (W = +-1e150, U = -1e-300, xi = 1e-300 ...).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"

namespace {

using namespace superball;

constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double denorm = std::numeric_limits<double>::denorm_min();
constexpr double huge = std::numeric_limits<double>::max();

const double below_one = std::nextafter(1.0, 0.0);

// The loop of count() on the same map, in x87 extended precision: a reference for
// starts whose double evaluation stays in range.
BounceCount count_long_double(const CanonicalState<double>& start, const ModelMatrices& m, std::uint32_t max_bounces)
{
    CanonicalState<long double> c{start.xi, start.U, start.W};
    std::uint32_t n = 0;
    for (;;) {
        if (!(c.xi < 1.0L)) return {n, Outcome::missed};
        if (n >= max_bounces) return {n, Outcome::capped};
        c = canonical_map(c, m).next;
        ++n;
        if (c.U >= 0.0L) return {n, Outcome::left};
    }
}

std::string describe(const CanonicalState<double>& c)
{
    char buf[128];
    std::snprintf(buf, sizeof buf, "(xi %.17g, U %.17g, W %.17g)", c.xi, c.U, c.W);
    return buf;
}

// count() and a vectorised kernel on every start: identical, and each result keeps the
// contract of an Outcome.
void expect_kernel_agrees(const KernelVariant& kernel, const std::vector<CanonicalState<double>>& s, const Model& model,
                          std::uint32_t max)
{
    SCOPED_TRACE(describe(kernel));
    const ModelMatrices m = ModelMatrices::of(model);
    const Starts soa = Starts::of(s);
    std::vector<std::uint32_t> wb(s.size(), 0xdeadbeef);
    std::vector<std::uint8_t> oc(s.size(), 0xff);
    kernel.count(soa.view(), m, max, wb, oc);
    int reported = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const BounceCount a = count(s[i], m, max);
        const bool ok = a.wall_bounces == wb[i] && static_cast<std::uint8_t>(a.outcome) == oc[i] &&
                        static_cast<int>(a.outcome) < outcome_count && a.wall_bounces <= max &&
                        (a.outcome != Outcome::invalid || a.wall_bounces == 0) &&
                        (a.outcome != Outcome::capped || a.wall_bounces == max);
        if (!ok && ++reported <= 5) {
            ADD_FAILURE() << describe(s[i]) << " e " << model.wall.e << " alpha " << model.wall.alpha << " max " << max
                          << ": count " << a.wall_bounces << "/" << name(a.outcome) << ", simd " << wb[i] << "/"
                          << int(oc[i]);
        }
    }
}

// ... for every variant this processor runs (test_kernels.cpp says which it skips).
void expect_kernels_agree(const std::vector<CanonicalState<double>>& s, const Model& model, std::uint32_t max)
{
    for (const KernelVariant& k : simd_kernels()) {
        if (k.runs_here()) expect_kernel_agrees(k, s, model, max);
    }
}

const std::vector<double> edge_xi = {0.0, -0.0, denorm, 1e-310, 1e-300, 1e-200, 1e-16, 0.25, 0.5, 1 - 1e-16,
                                     below_one, 1.0, std::nextafter(1.0, 2.0), 1e300, inf, -denorm, nan};
const std::vector<double> edge_U = {-1e-300, -denorm, -1e-16, -0.5, -1.0, -3.0, -1e16, -1e150, -1e300, -huge,
                                    -0.0, 0.0, denorm, -inf, nan};
const std::vector<double> edge_W = {0.0, -0.0, denorm, -denorm, 1.0, -2.0, -1.25, 1e16, -1e16, 1e150, -1e150,
                                    1e155, -1e155, 1e300, -1e300, huge, -huge, inf, nan};

std::vector<CanonicalState<double>> edge_starts()
{
    std::vector<CanonicalState<double>> s;
    for (double xi : edge_xi) {
        for (double U : edge_U) {
            for (double W : edge_W) s.push_back({xi, U, W});
        }
    }
    return s;
}

const std::vector<Model> edge_models = {
    Model::uniform(0.9, 0.9), Model::uniform(1.0, 1.0), Model::uniform(1.0, -1.0), Model::uniform(0.5, -1.0),
    Model{{0.8, 0.6}, {0.85, 0.7}}, Model::uniform(0.9, 0.4), Model::uniform(denorm, 0.5), Model::uniform(1e-300, 1.0),
    Model::uniform(std::numeric_limits<double>::min(), -0.3)};

TEST(Edges, KernelsAgreeOnEdgeStarts)
{
    const auto s = edge_starts();
    for (const Model& model : edge_models) {
        for (std::uint32_t max : {0u, 1u, 2u, 3u, 1000u}) expect_kernels_agree(s, model, max);
    }
}

TEST(Edges, KernelsAgreeOnArbitraryBitPatterns)
{
    // Every double, NaN payloads and negative zero included: each gets an Outcome.
    std::mt19937_64 rng(7);
    const auto any_double = [&] {
        const std::uint64_t bits = rng();
        double x;
        std::memcpy(&x, &bits, sizeof x);
        return x;
    };
    std::uniform_real_distribution<double> xi(0.0, 1.0), U(-3.0, 0.0), W(-5.0, 5.0);
    std::vector<CanonicalState<double>> s;
    for (int i = 0; i < 30000; ++i) {
        // Mostly one arbitrary coordinate among sane ones, so that launches stay common.
        CanonicalState<double> c{xi(rng), U(rng), W(rng)};
        switch (i % 4) {
            case 0: c.xi = any_double(); break;
            case 1: c.U = any_double(); break;
            case 2: c.W = any_double(); break;
            default: c = {any_double(), any_double(), any_double()};
        }
        s.push_back(c);
    }
    for (const Model& model : edge_models) expect_kernels_agree(s, model, 300);
}

TEST(Edges, PlaneXiZero)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.9));
    // xi = 0 is the plane itself, not a launch (SPEC.md section 3).
    EXPECT_EQ(count({0.0, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid}));
    EXPECT_EQ(count({-0.0, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid}));
    EXPECT_EQ(count({-denorm, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid}));
    // Extremely near it, subnormal included: a launch, counted like its neighbours (the
    // limit from inside), as in extended precision.
    const BounceCount near = count({1e-300, -1.0, -2.0}, m, 1000);
    EXPECT_NE(near.outcome, Outcome::invalid);
    for (double xi : {denorm, 1e-310, 1e-300, 1e-200}) {
        const CanonicalState<double> c{xi, -1.0, -2.0};
        EXPECT_EQ(count(c, m, 1000), near) << describe(c);
        EXPECT_EQ(count(c, m, 1000), count_long_double(c, m, 1000)) << describe(c);
    }
}

TEST(Edges, PlaneXiOne)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.9));
    // xi >= 1 misses the wall before any impact.
    for (double xi : {1.0, std::nextafter(1.0, 2.0), 1e300}) {
        EXPECT_EQ(count({xi, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::missed})) << xi;
    }
    EXPECT_EQ(count({inf, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid}));
    // Just below: the wall is hit at floor level, an ordinary launch.
    for (double xi : {1 - 1e-16, below_one}) {
        for (double W : {-2.0, 0.0, 1.0}) {
            const CanonicalState<double> c{xi, -1.0, W};
            const BounceCount r = count(c, m, 1000);
            EXPECT_NE(r.outcome, Outcome::invalid) << describe(c);
            EXPECT_GE(r.wall_bounces, 1u) << describe(c);
            EXPECT_EQ(r, count_long_double(c, m, 1000)) << describe(c);
        }
    }
}

TEST(Edges, LaunchDirectionToZero)
{
    for (const Model& model : {Model::uniform(0.9, 0.9), Model::uniform(1.0, 1.0)}) {
        const ModelMatrices m = ModelMatrices::of(model);
        for (double U : {-1e-300, -denorm, -1e-16}) {
            const CanonicalState<double> c{0.3, U, -2.0};
            const BounceCount r = count(c, m, 1000);
            EXPECT_NE(r.outcome, Outcome::invalid) << describe(c);
            EXPECT_EQ(r, count_long_double(c, m, 1000)) << describe(c);
        }
        // U = 0 and U = -0 are not a launch toward the wall.
        EXPECT_EQ(count({0.3, 0.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid}));
        EXPECT_EQ(count({0.3, -0.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid}));
    }
}

TEST(Edges, HugeSpinWithinRangeIsExact)
{
    // |W| up to ~1e153: v+^2 stays finite and the double result equals extended precision.
    for (const Model& model : {Model::uniform(0.9, 0.9), Model::uniform(1.0, 1.0), Model{{0.8, 0.6}, {0.85, 0.7}}}) {
        const ModelMatrices m = ModelMatrices::of(model);
        for (double W : {1e16, -1e16, 1e100, -1e100, 1e150, -1e150, 1e153, -1e153}) {
            for (double xi : {0.1, 0.3, 0.7}) {
                const CanonicalState<double> c{xi, -1.0, W};
                const BounceCount r = count(c, m, 1000);
                EXPECT_NE(r.outcome, Outcome::invalid) << describe(c);
                EXPECT_EQ(r, count_long_double(c, m, 1000)) << describe(c);
            }
        }
    }
}

TEST(Edges, HugeSpinBeyondRangeIsInvalid)
{
    // v+^2 overflows: before the fix, W = -1e300 came out as "1 wall bounce, left" (the
    // overflowed multiplier made U' = -0) where the map, evaluated in extended precision,
    // gives 3 bounces. Now such a start has no answer: invalid, 0 impacts.
    for (const Model& model : {Model::uniform(0.9, 0.9), Model::uniform(1.0, 1.0), Model{{0.8, 0.6}, {0.85, 0.7}}}) {
        const ModelMatrices m = ModelMatrices::of(model);
        for (double W : {1e155, -1e155, 1e300, -1e300, huge, -huge}) {
            for (double xi : {1e-300, 0.1, 0.3, 0.7, below_one}) {
                EXPECT_EQ(count({xi, -1.0, W}, m, 1000), (BounceCount{0, Outcome::invalid})) << describe({xi, -1.0, W});
            }
        }
    }
}

TEST(Edges, SubnormalRestitutionIsInvalid)
{
    // lambda = e_floor * |v_f| underflows: the canonical state is lost at the first floor
    // bounce. Launches that miss the wall are still decided before any impact.
    const ModelMatrices m = ModelMatrices::of(Model::uniform(denorm, 0.5));
    for (double xi : {1e-300, 0.3, below_one}) {
        EXPECT_EQ(count({xi, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::invalid})) << xi;
    }
    EXPECT_EQ(count({1.0, -1.0, -2.0}, m, 1000), (BounceCount{0, Outcome::missed}));
}

TEST(Edges, SaneStartsStayRepresentable)
{
    // Starts of any physical scale (xi from 1e-16 to 1 - 1e-16, |U| <= 10, |W| <= 1000) with
    // any coefficients: no step ever leaves the range, so the invalid-on-overflow rule
    // changes no ordinary result.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> log_xi(-16.0, 0.0), U(-10.0, 0.0), log_W(-3.0, 3.0), e(0.05, 1.0),
        alpha(-1.0, 1.0), sign(-1.0, 1.0);
    for (int k = 0; k < 12; ++k) {
        const Model model = k == 0 ? Model::uniform(1.0, 1.0) : Model{{e(rng), alpha(rng)}, {e(rng), alpha(rng)}};
        const ModelMatrices m = ModelMatrices::of(model);
        for (int i = 0; i < 2000; ++i) {
            CanonicalState<double> c{std::pow(10.0, log_xi(rng)), U(rng), std::copysign(std::pow(10.0, log_W(rng)), sign(rng))};
            if (i % 2) c.xi = 1.0 - c.xi;
            for (int n = 0; n < 1000 && c.xi < 1.0 && c.U < 0.0; ++n) {
                const CanonicalStep<double> step = canonical_map(c, m);
                ASSERT_TRUE(representable(step)) << describe(c) << " e " << model.wall.e;
                c = step.next;
            }
        }
    }
}

TEST(Edges, NoDissipationCapsExactly)
{
    // e = alpha = 1: the self-retracing motions ((1 + U)/2, U, 5U/2) are fixed points with
    // lambda = 1, marginally stable for U < -2/11. On and near them the ball bounces for
    // ever: capped at exactly max_bounces, also beyond 65535 (uint32 in result files).
    const Model model = Model::uniform(1.0, 1.0);
    const ModelMatrices m = ModelMatrices::of(model);
    std::vector<CanonicalState<double>> s;
    for (double U : {-0.25, -0.5, -0.75, -0.9}) {
        const CanonicalState<double> c{(1 + U) / 2, U, 2.5 * U};
        s.push_back(c);
        s.push_back({std::nextafter(c.xi, 1.0), c.U, c.W});
        s.push_back({c.xi, std::nextafter(c.U, 0.0), c.W});
        s.push_back({c.xi * (1 + 1e-9), c.U, c.W * (1 - 1e-9)});
    }
    for (std::uint32_t max : {1u, 2u, 1000u, 65535u, 65536u, 70000u}) {
        for (const auto& c : s) EXPECT_EQ(count(c, m, max), (BounceCount{max, Outcome::capped})) << describe(c) << " " << max;
        expect_kernels_agree(s, model, max);
    }
    // The saddle branch (U > -2/11) is left by rounding: an ordinary end, same in both kernels.
    const CanonicalState<double> saddle{(1 - 0.125) / 2, -0.125, -0.3125};
    const BounceCount r = count(saddle, m, 70000);
    EXPECT_NE(r.outcome, Outcome::capped);
    EXPECT_LT(r.wall_bounces, 70000u);
    expect_kernels_agree({saddle}, model, 70000);
}

TEST(Edges, SmoothBallLeavesAfterOneImpact)
{
    // alpha = -1 on both surfaces: no friction, the spin never changes the velocities and
    // the floor keeps u+ = -e_wall U > 0: every launch that reaches the wall leaves after
    // exactly one impact, whatever W (huge ones included: W does not enter v+).
    for (double e : {1.0, 0.5, 1e-3}) {
        const ModelMatrices m = ModelMatrices::of(Model::uniform(e, -1.0));
        for (double xi : {denorm, 1e-300, 0.3, below_one}) {
            for (double W : {0.0, -2.0, 1e150, -1e300}) {
                EXPECT_EQ(count({xi, -1.0, W}, m, 1000), (BounceCount{1, Outcome::left})) << describe({xi, -1.0, W}) << e;
            }
        }
    }
}

TEST(Edges, PhysicalExtremesGiveAnOutcome)
{
    // Physical starts whose canonical coordinates overflow or underflow.
    const Model model = Model::uniform(0.9, 0.9);
    for (const PhysicalState<double>& s : std::vector<PhysicalState<double>>{
             {1e-300, -1e300, 1e300, 0.0}, {1e300, -1e-300, 1e-300, 0.0}, {denorm, -1.0, 1.0, -1e300}, {0.02, -2.0, 2.0, -5.0}}) {
        const BounceCount r = count(s, model, 9.81, 1000);
        EXPECT_LT(static_cast<int>(r.outcome), outcome_count);
        if (r.outcome == Outcome::invalid) {
            EXPECT_EQ(r.wall_bounces, 0u);
        }
    }
}

}  // namespace
