// Every variant of the vectorised kernel against the scalar count(): identical on every
// point, and the choice among the variants (core/kernels.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "core/count_simd.hpp"
#include "core/input.hpp"
#include "core/kernels.hpp"
#include "reference_data.hpp"

namespace {

using namespace superball;

struct Counts {
    std::vector<std::uint32_t> wall_bounces;
    std::vector<std::uint8_t> outcomes;
};

Counts run(const KernelVariant& kernel, const std::vector<CanonicalState<double>>& s, const Model& model,
           std::uint32_t max)
{
    // Poisoned outputs: every point must be written.
    Counts c{std::vector<std::uint32_t>(s.size(), 0xdeadbeef), std::vector<std::uint8_t>(s.size(), 0xff)};
    kernel.count(Starts::of(s).view(), ModelMatrices::of(model), max, c.wall_bounces, c.outcomes);
    return c;
}

void expect_identical(const KernelVariant& kernel, const std::vector<CanonicalState<double>>& s, const Model& model,
                      std::uint32_t max)
{
    const Counts a = run(scalar_kernel(), s, model, max);
    const Counts b = run(kernel, s, model, max);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (a.wall_bounces[i] != b.wall_bounces[i] || a.outcomes[i] != b.outcomes[i]) {
            if (++differ <= 5) {
                ADD_FAILURE() << "point " << i << " (xi " << s[i].xi << ", U " << s[i].U << ", W " << s[i].W
                              << "): scalar " << a.wall_bounces[i] << "/" << int(a.outcomes[i]) << ", "
                              << kernel.name << " " << b.wall_bounces[i] << "/" << int(b.outcomes[i]);
            }
        }
    }
    EXPECT_EQ(differ, 0u) << "of " << s.size() << " points";
}

// n_xi x n_W cell centres of xi in (0, 1), W in [-3, 3] at fixed U; with `stride`, only
// every stride-th row in xi of that grid.
std::vector<CanonicalState<double>> slice(std::size_t n, double U, std::size_t stride = 1)
{
    std::vector<CanonicalState<double>> s;
    for (std::size_t i = 0; i < n; i += stride) {
        for (std::size_t k = 0; k < n; ++k) {
            s.push_back({(static_cast<double>(i) + 0.5) / static_cast<double>(n), U,
                         -3.0 + (static_cast<double>(k) + 0.5) * 6.0 / static_cast<double>(n)});
        }
    }
    return s;
}

// One test per variant any build may have: those this build lacks or this processor
// cannot run are skipped, saying why.
class Variant : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override
    {
        for (const KernelVariant& k : simd_kernels()) {
            if (k.name != GetParam()) continue;
            if (!k.runs_here()) GTEST_SKIP() << "this processor lacks " << k.requirement << " for " << k.name;
            kernel = &k;
            return;
        }
        GTEST_SKIP() << "this build has no " << GetParam() << " variant";
    }
    const KernelVariant* kernel = nullptr;
};

TEST_P(Variant, ReferencePoints)
{
    const std::vector<test::CountRow> rows = test::count_rows_or_empty();
    ASSERT_FALSE(rows.empty()) << "no reference rows in " << test::canonical_counts_path();
    for (const test::CountRow& r : rows) {
        // Alone and amid a batch of other points (lanes and refill).
        std::vector<CanonicalState<double>> s(13, CanonicalState<double>{0.3, -1.0, 0.5});
        s.insert(s.begin() + 5, r.start);
        const Counts c = run(*kernel, s, r.model, 1000);
        EXPECT_EQ(c.wall_bounces[5], r.wall_bounces) << r;
        EXPECT_EQ(c.outcomes[5], static_cast<std::uint8_t>(r.outcome)) << r;
        const Counts one = run(*kernel, {r.start}, r.model, 1000);
        EXPECT_EQ(one.wall_bounces[0], r.wall_bounces) << r;
        EXPECT_EQ(one.outcomes[0], static_cast<std::uint8_t>(r.outcome)) << r;
    }
}

TEST_P(Variant, BenchmarkSliceIdentical)
{
    // The grid points of the 4096^2 benchmark slice (tests/bench/slice_4096.toml), every
    // 8th row: 2.1 M points.
    expect_identical(*kernel, slice(4096, -1.0, 8), Model::uniform(0.9, 0.9), 1000);
}

TEST_P(Variant, OtherSlicesAndModelsIdentical)
{
    expect_identical(*kernel, slice(128, -0.3), Model::uniform(0.95, 0.95), 1000);
    expect_identical(*kernel, slice(128, -2.0), Model{{0.8, 0.6}, {0.85, 0.7}}, 1000);
    expect_identical(*kernel, slice(64, -0.5), Model::uniform(1.0, 1.0), 300);   // conservative: many capped
    expect_identical(*kernel, slice(64, -1.0), Model::uniform(1.0, -1.0), 300);  // smooth elastic
}

TEST_P(Variant, RandomStatesIncludingInadmissibleIdentical)
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
    expect_identical(*kernel, s, Model::uniform(0.9, 0.9), 1000);
    expect_identical(*kernel, s, Model::uniform(0.99, 0.99), 5);  // many capped at a small cap
}

TEST_P(Variant, EdgeSizesAndCaps)
{
    const auto s = slice(40, -1.0);
    // Around the lane counts (2, 4, 8) and the block of 512 points.
    for (std::size_t n : {0u, 1u, 2u, 3u, 5u, 7u, 8u, 9u, 15u, 17u, 511u, 512u, 513u, 1025u}) {
        const std::vector<CanonicalState<double>> part(s.begin(), s.begin() + static_cast<long>(std::min(n, s.size())));
        expect_identical(*kernel, part, Model::uniform(0.9, 0.9), 1000);
    }
    for (std::uint32_t max : {0u, 1u, 2u, 3u}) expect_identical(*kernel, s, Model::uniform(0.95, 0.95), max);
}

TEST_P(Variant, DescribedByItsInstructionSet)
{
    EXPECT_GE(kernel->lanes, 2u);
    EXPECT_FALSE(kernel->instruction_set.empty());
    EXPECT_NE(describe(*kernel).find(std::string(kernel->instruction_set)), std::string::npos);
    EXPECT_EQ(&kernel_named(kernel->name, "test"), kernel);
}

INSTANTIATE_TEST_SUITE_P(Kernels, Variant, ::testing::Values("baseline", "avx2", "avx512", "native"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(Kernels, ThisBuildHasItsVariants)
{
    const auto all = simd_kernels();
    ASSERT_FALSE(all.empty());
    EXPECT_TRUE(all.front().runs_here()) << all.front().name << " must run wherever the binary runs";
    const auto has = [&](std::string_view name) {
        return std::any_of(all.begin(), all.end(), [&](const KernelVariant& k) { return k.name == name; });
    };
#if defined(__x86_64__) && !defined(__AVX2__) && defined(NDEBUG)
    // A portable optimised x86-64 build: all three; clang's without AVX-512 (src/CMakeLists.txt).
#ifdef __clang__
    EXPECT_TRUE(has("baseline") && has("avx2") && !has("avx512"));
#else
    EXPECT_TRUE(has("baseline") && has("avx2") && has("avx512"));
#endif
#endif
    EXPECT_TRUE(has("baseline") != has("native"));
    // Narrowest first; the best is the widest this processor runs.
    for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].lanes, all[i].lanes);
    for (const KernelVariant& k : all) {
        if (k.runs_here()) {
            EXPECT_LE(k.lanes, best_kernel().lanes) << k.name;
        }
    }
    EXPECT_TRUE(best_kernel().runs_here());
}

TEST(Kernels, CountEachSimdIsTheBest)
{
    const auto s = slice(64, -1.0);
    const Counts best = run(best_kernel(), s, Model::uniform(0.9, 0.9), 1000);
    Counts c{std::vector<std::uint32_t>(s.size()), std::vector<std::uint8_t>(s.size())};
    count_each_simd(Starts::of(s).view(), ModelMatrices::of(Model::uniform(0.9, 0.9)), 1000, c.wall_bounces,
                    c.outcomes);
    EXPECT_EQ(c.wall_bounces, best.wall_bounces);
    EXPECT_EQ(c.outcomes, best.outcomes);
}

// The refusals, on made-up variants so that they are checked on any processor.
bool never() { return false; }
bool always() { return true; }
const KernelVariant made_up[] = {
    {"baseline", "SSE2", "", 2, &count_each, &always},
    {"avx2", "AVX2+FMA", "AVX2, FMA, BMI1 and BMI2 (x86-64-v3)", 4, &count_each, &always},
    {"avx512", "AVX-512", "AVX-512 F, CD, VL, DQ and BW (x86-64-v4)", 8, &count_each, &never},
};

std::string refusal(std::string_view name, std::string_view source)
{
    try {
        kernel_named(name, source, made_up);
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << name << " was accepted";
    return {};
}

TEST(KernelChoice, ByName)
{
    EXPECT_EQ(&kernel_named("simd", "--kernel simd", made_up), &made_up[1]);  // the widest that runs
    EXPECT_EQ(&kernel_named("avx2", "--kernel avx2", made_up), &made_up[1]);
    EXPECT_EQ(&kernel_named("baseline", "--kernel baseline", made_up), &made_up[0]);
    EXPECT_EQ(&kernel_named("scalar", "--kernel scalar", made_up), &scalar_kernel());
    EXPECT_EQ(&kernel_named("simd", "x"), &best_kernel());
}

TEST(KernelChoice, ProcessorLacksTheVariant)
{
    const std::string m = refusal("avx512", "--kernel avx512");
    EXPECT_EQ(m.rfind("--kernel avx512: this processor cannot run the avx512 kernel", 0), 0u) << m;
    EXPECT_NE(m.find("AVX-512 F, CD, VL, DQ and BW"), std::string::npos) << m;
    EXPECT_NE(m.find("accepted here: simd (here avx2), scalar, baseline, avx2"), std::string::npos) << m;
    EXPECT_EQ(m.find("avx2, avx512"), std::string::npos) << m;
}

TEST(KernelChoice, UnknownOrOfAnotherBuild)
{
    std::string m = refusal("avx", "SUPERBALL_KERNEL=avx");
    EXPECT_EQ(m.rfind("SUPERBALL_KERNEL=avx: unknown kernel 'avx'", 0), 0u) << m;
    EXPECT_NE(m.find("accepted here: simd (here avx2), scalar, baseline, avx2"), std::string::npos) << m;
    m = refusal("native", "--kernel native");
    EXPECT_NE(m.find("this build has no native kernel (it has baseline, avx2, avx512)"), std::string::npos) << m;
    EXPECT_NE(m.find("cmake --preset native"), std::string::npos) << m;
}

// SUPERBALL_KERNEL for the length of a test.
class KernelVariable {
public:
    explicit KernelVariable(const char* value)
    {
        if (const char* old = std::getenv(kernel_environment_variable)) saved_ = old;
        if (value) {
            ::setenv(kernel_environment_variable, value, 1);
        } else {
            ::unsetenv(kernel_environment_variable);
        }
    }
    ~KernelVariable()
    {
        if (saved_) {
            ::setenv(kernel_environment_variable, saved_->c_str(), 1);
        } else {
            ::unsetenv(kernel_environment_variable);
        }
    }
    KernelVariable(const KernelVariable&) = delete;
    KernelVariable& operator=(const KernelVariable&) = delete;

private:
    std::optional<std::string> saved_;
};

TEST(KernelChoice, FlagThenEnvironmentThenBest)
{
    {
        const KernelVariable unset(nullptr);
        EXPECT_EQ(&select_kernel(""), &best_kernel());
        EXPECT_EQ(&select_kernel("scalar"), &scalar_kernel());
    }
    {
        const KernelVariable empty("");
        EXPECT_EQ(&select_kernel(""), &best_kernel());
    }
    {
        const KernelVariable scalar("scalar");
        EXPECT_EQ(&select_kernel(""), &scalar_kernel());
        EXPECT_EQ(&select_kernel("simd"), &best_kernel());  // the flag wins
        EXPECT_NE(kernel_report().find("counting kernel: scalar;"), std::string::npos) << kernel_report();
    }
    {
        const KernelVariable bad("sse9");
        EXPECT_THROW(select_kernel(""), InputError);
        try {
            select_kernel("");
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("SUPERBALL_KERNEL=sse9: unknown kernel", 0), 0u) << e.what();
        }
        EXPECT_EQ(&select_kernel("scalar"), &scalar_kernel());
    }
}

TEST(KernelChoice, ReportNamesTheKernelInUse)
{
    const KernelVariable unset(nullptr);
    const std::string r = kernel_report();
    EXPECT_EQ(r.rfind("counting kernel: " + describe(best_kernel()) + ";", 0), 0u) << r;
    EXPECT_NE(r.find("this processor runs: "), std::string::npos) << r;
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
