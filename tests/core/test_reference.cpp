// The core against the independently computed reference values (tests/reference, a copy
// of ../shared/reference): every canonical count, and the example trajectory.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "core/count.hpp"
#include "core/map.hpp"
#include "core/trajectory.hpp"
#include "reference_data.hpp"

namespace superball {
namespace {

using test::CountRow;
using test::RelNear;

// ------------------------------------------------------------------ the files themselves

TEST(ReferenceFiles, CanonicalCountsParse)
{
    std::vector<CountRow> rows;
    ASSERT_NO_THROW(rows = test::read_count_rows(test::canonical_counts_path()));
    EXPECT_EQ(rows.size(), 40u) << "canonical_counts.csv should hold 40 data rows";
    // The table exercises more than one outcome and a model with different surfaces;
    // if it did not, the parameterised test below would prove less than it claims.
    std::set<Outcome> outcomes;
    bool per_surface = false;
    for (const CountRow& r : rows) {
        outcomes.insert(r.outcome);
        per_surface = per_surface || r.model.wall.e != r.model.floor.e || r.model.wall.alpha != r.model.floor.alpha;
        EXPECT_TRUE(in_range(r.model)) << r;
    }
    EXPECT_TRUE(outcomes.count(Outcome::left)) << "no row with outcome left";
    EXPECT_TRUE(outcomes.count(Outcome::missed)) << "no row with outcome missed";
    EXPECT_TRUE(per_surface) << "no row with per-surface coefficients";
}

TEST(ReferenceFiles, TrajectoryExampleParses)
{
    std::vector<test::TrajectoryRow> rows;
    ASSERT_NO_THROW(rows = test::read_trajectory_rows(test::trajectory_example_path()));
    ASSERT_EQ(rows.size(), test::example_wall_bounces + 1);
    for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].n, static_cast<int>(i));
    EXPECT_TRUE(std::isnan(rows.back().y)) << "the last state leaves: no further wall impact";
}

// The copy in tests/reference must not drift from ../shared/reference.
TEST(ReferenceFiles, CopyIsByteIdenticalToShared)
{
    namespace fs = std::filesystem;
    const fs::path shared = test::shared_reference_dir();
    const fs::path copy = test::reference_dir();
    if (!fs::is_directory(shared)) GTEST_SKIP() << "no shared reference folder at " << shared << ": nothing to compare";
    int compared = 0;
    for (const auto& entry : fs::directory_iterator(shared)) {
        if (!entry.is_regular_file() || entry.path().extension() != ".csv") continue;
        const auto original = test::read_bytes(entry.path().string());
        const auto duplicate = test::read_bytes((copy / entry.path().filename()).string());
        ASSERT_TRUE(original.has_value()) << "cannot read " << entry.path();
        ASSERT_TRUE(duplicate.has_value()) << entry.path().filename() << " is missing from " << copy;
        EXPECT_TRUE(*original == *duplicate) << (copy / entry.path().filename()) << " differs from " << entry.path();
        ++compared;
    }
    EXPECT_GE(compared, 2) << "expected canonical_counts.csv and trajectory_example.csv in " << shared;
}

// ------------------------------------------------------------------ canonical counts

class CanonicalCounts : public ::testing::TestWithParam<CountRow> {};

TEST_P(CanonicalCounts, Reproduced)
{
    const CountRow& r = GetParam();
    const BounceCount got = count(r.start, r.model, 1000);
    EXPECT_EQ(got.wall_bounces, r.wall_bounces) << r << "\n  got outcome " << name(got.outcome);
    EXPECT_EQ(got.outcome, r.outcome) << r << "\n  got " << got.wall_bounces << " wall bounces, outcome "
                                      << name(got.outcome);
    // The same through the ModelMatrices overload and with a generous cap.
    EXPECT_EQ(count(r.start, ModelMatrices::of(r.model), 1u << 20), got) << r;
}

INSTANTIATE_TEST_SUITE_P(Reference, CanonicalCounts, ::testing::ValuesIn(test::count_rows_or_empty()),
                         [](const ::testing::TestParamInfo<CountRow>& info) {
                             return "line" + std::to_string(info.param.line_number);
                         });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(CanonicalCounts);  // CanonicalCountsParse reports a broken file

// The example of `superball count --help` and of the paper.
TEST(DocumentedExample, EightWallBouncesThenLeft)
{
    const BounceCount r = count(CanonicalState<double>{0.05, -1.0, -2.0}, Model::uniform(0.9, 0.9), 1000);
    EXPECT_EQ(r, (BounceCount{8, Outcome::left})) << r.wall_bounces << " " << name(r.outcome);
}

// ------------------------------------------------------------------ trajectory example

constexpr double traj_tol = 1e-12;

class TrajectoryExample : public ::testing::Test {
protected:
    void SetUp() override
    {
        ASSERT_NO_THROW(rows = test::read_trajectory_rows(test::trajectory_example_path()));
        ASSERT_EQ(rows.size(), test::example_wall_bounces + 1);
    }
    PhysicalState<double> start() const
    {
        return {rows[0].x, rows[0].u, rows[0].v, rows[0].omega * test::example_radius};
    }
    std::vector<test::TrajectoryRow> rows;
};

TEST_F(TrajectoryExample, ReproducedByTrajectory)
{
    const Trajectory tr = trajectory(start(), test::example_model, test::example_g, 1000);
    EXPECT_EQ(tr.result, (BounceCount{test::example_wall_bounces, test::example_outcome}))
        << tr.result.wall_bounces << " " << name(tr.result.outcome);
    // launch, (wall, floor) x 12, land
    ASSERT_EQ(tr.events.size(), 2 * test::example_wall_bounces + 2);
    const double a = test::example_radius;
    for (std::uint32_t n = 1; n <= test::example_wall_bounces; ++n) {
        SCOPED_TRACE("after wall impact " + std::to_string(n));
        const Event& wall = tr.events[2 * n - 1];
        const Event& floor = tr.events[2 * n];
        ASSERT_EQ(wall.kind, EventKind::wall);
        ASSERT_EQ(floor.kind, EventKind::floor);
        const test::TrajectoryRow& before = rows[n - 1];
        const test::TrajectoryRow& after = rows[n];
        EXPECT_PRED_FORMAT3(RelNear, wall.y, before.y, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, floor.x, after.x, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, floor.after.u, after.u, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, floor.after.v, after.v, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, floor.after.W / a, after.omega, traj_tol);
    }
    EXPECT_EQ(tr.events.back().kind, EventKind::land);
    EXPECT_GE(tr.events[2 * test::example_wall_bounces].after.u, 0.0) << "the last floor bounce sends the ball away";
}

TEST_F(TrajectoryExample, ReproducedByPhysicalMap)
{
    const ModelMatrices m = ModelMatrices::of(test::example_model);
    PhysicalState<double> s = start();
    for (std::size_t n = 0; n + 1 < rows.size(); ++n) {
        SCOPED_TRACE("excursion from state " + std::to_string(n) + " (line " + std::to_string(rows[n].line_number) +
                     ")");
        ASSERT_LT(s.u, 0.0) << "the reference still heads to the wall here";
        const Excursion<double> ex = excursion(s, m, test::example_g);
        EXPECT_PRED_FORMAT3(RelNear, ex.to_wall.y, rows[n].y, traj_tol);
        const PhysicalState<double> next = physical_map(s, m, test::example_g);
        // physical_map is excursion().next: the same numbers.
        EXPECT_EQ(next.x, ex.next.x);
        EXPECT_EQ(next.W, ex.next.W);
        EXPECT_PRED_FORMAT3(RelNear, next.x, rows[n + 1].x, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, next.u, rows[n + 1].u, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, next.v, rows[n + 1].v, traj_tol);
        EXPECT_PRED_FORMAT3(RelNear, next.W / test::example_radius, rows[n + 1].omega, traj_tol);
        s = next;
    }
    EXPECT_GE(s.u, 0.0) << "after 12 wall impacts the ball leaves";
}

TEST_F(TrajectoryExample, CountedFromPhysicalAndCanonicalStart)
{
    const BounceCount expected{test::example_wall_bounces, test::example_outcome};
    EXPECT_EQ(count(start(), test::example_model, test::example_g, 1000), expected);
    EXPECT_EQ(count(to_canonical(start(), test::example_g), test::example_model, 1000), expected);
}

}  // namespace
}  // namespace superball
