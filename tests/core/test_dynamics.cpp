// Jacobians, fixed points and cycles of G (core/dynamics.hpp) and its limits on the
// boundary planes (core/boundary_planes.hpp).
#include <gtest/gtest.h>

#include <Eigen/LU>  // determinant()
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include "core/boundary_planes.hpp"
#include "core/count.hpp"
#include "core/dynamics.hpp"
#include "dynamics_testing.hpp"

namespace superball {
namespace {

using test::admissible_states;
using test::models;

const Model elastic = Model::uniform(1.0, 1.0);

// Central differences of (G^k, product of lambdas), step relative to each coordinate's scale.
struct Numerical {
    Eigen::Matrix3d dG;
    Eigen::RowVector3d dlambda;
};

Numerical central_differences(const CanonicalState<double>& s, const ModelMatrices& m, int k)
{
    const auto eval = [&](const Eigen::Vector3d& z) {
        CanonicalState<double> c = as_state(z);
        double lambda = 1.0;
        for (int i = 0; i < k; ++i) {
            const CanonicalStep<double> g = canonical_map(c, m);
            lambda *= g.lambda;
            c = g.next;
        }
        return std::pair{as_vector(c), lambda};
    };
    Numerical n;
    const Eigen::Vector3d z = as_vector(s);
    const Eigen::Vector3d scale{std::min(s.xi, 1.0 - s.xi), std::abs(s.U), std::max(1.0, std::abs(s.W))};
    for (int j = 0; j < 3; ++j) {
        const double h = 1e-5 * scale(j);
        Eigen::Vector3d up = z, down = z;
        up(j) += h;
        down(j) -= h;
        const auto [g_up, l_up] = eval(up);
        const auto [g_down, l_down] = eval(down);
        n.dG.col(j) = (g_up - g_down) / (up(j) - down(j));
        n.dlambda(j) = (l_up - l_down) / (up(j) - down(j));
    }
    return n;
}

void expect_jacobian_matches_differences(int k, int count)
{
    for (const Model& model : models(k)) {
        const ModelMatrices m = ModelMatrices::of(model);
        for (const CanonicalState<double>& s : admissible_states(m, k, count, 42 + static_cast<std::uint64_t>(k))) {
            const IterateJacobian j = iterate_jacobian(s, m, k);
            ASSERT_TRUE(j.in_region);
            const Numerical n = central_differences(s, m, k);
            // Column by column, relative to the column's size: the columns of xi, U and W
            // can differ by orders of magnitude.
            for (int c = 0; c < 3; ++c) {
                EXPECT_LE((j.dG.col(c) - n.dG.col(c)).norm(), 1e-6 * j.dG.col(c).norm())
                    << "k=" << k << " column " << c << " at (" << s.xi << ", " << s.U << ", " << s.W << ")\n"
                    << j.dG << "\nvs\n"
                    << n.dG;
                EXPECT_NEAR(j.dlambda(c), n.dlambda(c), 1e-6 * j.dlambda.norm()) << "k=" << k << " column " << c;
            }
        }
    }
}

TEST(Dynamics, JacobianOfGMatchesCentralDifferences) { expect_jacobian_matches_differences(1, 200); }

TEST(Dynamics, JacobianOfG2MatchesCentralDifferences) { expect_jacobian_matches_differences(2, 100); }

// The derivatives are those of the same template the kernels run: its value part is the
// double instantiation's, bit for bit.
TEST(Dynamics, AutomaticDifferentiationCarriesTheExactValue)
{
    for (const Model& model : models()) {
        const ModelMatrices m = ModelMatrices::of(model);
        for (const CanonicalState<double>& s : admissible_states(m, 1, 100, 7)) {
            const CanonicalStep<double> g = canonical_map(s, m);
            const StepJacobian j = step_jacobian(s, m);
            EXPECT_EQ(j.step.next.xi, g.next.xi);
            EXPECT_EQ(j.step.next.U, g.next.U);
            EXPECT_EQ(j.step.next.W, g.next.W);
            EXPECT_EQ(j.step.lambda, g.lambda);
        }
    }
}

TEST(Dynamics, IterateJacobianIsTheChainRule)
{
    const ModelMatrices m = ModelMatrices::of(Model{{0.8, 0.6}, {0.95, 0.3}});
    for (const CanonicalState<double>& s : admissible_states(m, 3, 50, 11)) {
        const IterateJacobian j3 = iterate_jacobian(s, m, 3);
        const StepJacobian a = step_jacobian(s, m);
        const StepJacobian b = step_jacobian(a.step.next, m);
        const StepJacobian c = step_jacobian(b.step.next, m);
        EXPECT_LE((j3.dG - c.dG * b.dG * a.dG).norm(), 1e-13 * j3.dG.norm());
        EXPECT_NEAR(j3.lambda, a.step.lambda * b.step.lambda * c.step.lambda, 1e-15 * j3.lambda);
        const Eigen::RowVector3d dlambda = b.step.lambda * c.step.lambda * a.dlambda +
                                           a.step.lambda * c.step.lambda * b.dlambda * a.dG +
                                           a.step.lambda * b.step.lambda * c.dlambda * b.dG * a.dG;
        EXPECT_LE((j3.dlambda - dlambda).norm(), 1e-13 * dlambda.norm());
    }
}

// e = alpha = 1: G preserves the flux measure 2 |U| v^5 dxi dU dW dv of the floor section
// (dynamics.hpp), so |det D(G)| = |U| / (|U'| lambda^6) at every state.
TEST(Dynamics, ElasticJacobianDeterminantFollowsFromTheInvariantMeasure)
{
    const ModelMatrices m = ModelMatrices::of(elastic);
    for (const CanonicalState<double>& s : admissible_states(m, 1, 300, 3)) {
        const StepJacobian j = step_jacobian(s, m);
        const double expected = std::abs(s.U) / (std::abs(j.step.next.U) * std::pow(j.step.lambda, 6));
        EXPECT_NEAR(std::abs(j.dG.determinant()), expected, 1e-10 * expected);
    }
}

// The self-retracing fixed points of the elastic ball (dynamics.hpp): xi = (1 + U)/2,
// W = 5U/2, lambda = 1; eigenvalues 1 and the roots of 49 U mu^2 + (122 U + 40) mu + 49 U.
struct Expected {
    std::array<std::complex<double>, 3> eigenvalues;
    Stability stability;
};

Expected self_retracing_eigenvalues(double U)
{
    const double b = (122.0 * U + 40.0) / (49.0 * U);  // mu^2 + b mu + 1 = 0
    const std::complex<double> root = std::sqrt(std::complex<double>(b * b - 4.0, 0.0));
    std::array<std::complex<double>, 3> ev{1.0, (-b + root) / 2.0, (-b - root) / 2.0};
    std::sort(ev.begin(), ev.end(), [](const auto& x, const auto& y) {
        if (std::abs(std::abs(x) - std::abs(y)) > 1e-9) return std::abs(x) > std::abs(y);
        return x.imag() > y.imag();
    });
    return {ev, U < -2.0 / 11.0 ? Stability::marginal : Stability::saddle};
}

void expect_same_eigenvalues(std::array<std::complex<double>, 3> got, std::array<std::complex<double>, 3> want,
                             double tolerance)
{
    // Match each expected eigenvalue to the nearest computed one (orders may differ when
    // moduli tie).
    for (const auto& w : want) {
        const auto nearest = std::min_element(got.begin(), got.end(), [&](const auto& a, const auto& b) {
            return std::abs(a - w) < std::abs(b - w);
        });
        EXPECT_LE(std::abs(*nearest - w), tolerance) << "eigenvalue " << w << " not found";
        *nearest = std::complex<double>(HUGE_VAL, HUGE_VAL);
    }
}

TEST(Dynamics, ElasticSelfRetracingMotionsAreFixedPoints)
{
    const ModelMatrices m = ModelMatrices::of(elastic);
    for (const double U : {-0.95, -0.7, -0.5, -0.3, -0.19, -0.17, -0.1, -0.02}) {
        const CanonicalState<double> s{(1.0 + U) / 2.0, U, 2.5 * U};
        const StepJacobian j = step_jacobian(s, m);
        EXPECT_NEAR(j.step.next.xi, s.xi, 1e-15);
        EXPECT_NEAR(j.step.next.U, s.U, 1e-15);
        EXPECT_NEAR(j.step.next.W, s.W, 1e-15);
        EXPECT_NEAR(j.step.lambda, 1.0, 1e-15);
        EXPECT_NEAR(j.dG.determinant(), 1.0, 1e-12);
        EXPECT_NEAR(j.dG.trace(), -(73.0 * U + 40.0) / (49.0 * U), 1e-12 * std::abs(j.dG.trace()));
        // The tangent of the family is the eigenvector of eigenvalue 1.
        const Eigen::Vector3d tangent{0.5, 1.0, 2.5};
        EXPECT_LE((j.dG * tangent - tangent).norm(), 1e-12);

        const auto c = make_cycle(s, m, 1);
        ASSERT_TRUE(c.has_value()) << "U = " << U;
        const Expected want = self_retracing_eigenvalues(U);
        expect_same_eigenvalues(c->eigenvalues, want.eigenvalues, 1e-9);
        EXPECT_EQ(c->stability, want.stability) << "U = " << U;
        EXPECT_TRUE(c->family);
        EXPECT_NEAR(c->lambda, 1.0, 1e-15);
    }
}

// Newton's method from seeded starts finds only (and many points of) that family, with the
// eigenvalues of the closed form.
TEST(Dynamics, ElasticSearchFindsTheSelfRetracingFamily)
{
    const ModelMatrices m = ModelMatrices::of(elastic);
    const std::vector<Cycle> cycles = find_cycles(m, 1, 400, 2024);
    ASSERT_GE(cycles.size(), 20u);
    double smallest_U = 0.0, largest_U = -1.0;
    for (const Cycle& c : cycles) {
        ASSERT_EQ(c.period, 1);
        const CanonicalState<double>& p = c.points.front();
        EXPECT_NEAR(p.xi, (1.0 + p.U) / 2.0, 1e-9) << p.U;
        EXPECT_NEAR(p.W, 2.5 * p.U, 1e-9) << p.U;
        EXPECT_NEAR(c.lambda, 1.0, 1e-10);  // to the accuracy of the point
        EXPECT_LE(c.residual, residual_tolerance);
        EXPECT_TRUE(c.family);
        if (std::abs(p.U + 2.0 / 11.0) > 1e-3) {
            const Expected want = self_retracing_eigenvalues(p.U);
            expect_same_eigenvalues(c.eigenvalues, want.eigenvalues, 1e-7);
            EXPECT_EQ(c.stability, want.stability) << p.U;
        }
        smallest_U = std::min(smallest_U, p.U);
        largest_U = std::max(largest_U, p.U);
    }
    // Both the elliptic (U < -2/11) and the hyperbolic part of the family are found.
    EXPECT_LT(smallest_U, -0.5);
    EXPECT_GT(largest_U, -2.0 / 11.0);
}

// Checks a reported cycle against the physical map F (another code path than G): after
// `period` excursions the launch is the same up to the scale, which is lambda.
void expect_physical_cycle(const Cycle& c, const ModelMatrices& m)
{
    PhysicalState<double> s = to_physical(c.points.front(), 1.0, 1.0);
    for (int i = 0; i < c.period; ++i) {
        s = physical_map(s, m, 1.0);
        const CanonicalState<double> q = to_canonical(s, 1.0);
        const CanonicalState<double>& want = c.points[static_cast<std::size_t>((i + 1) % c.period)];
        EXPECT_NEAR(q.xi, want.xi, 1e-9 * want.xi);
        EXPECT_NEAR(q.U, want.U, 1e-9 * std::hypot(want.U, want.W));
        EXPECT_NEAR(q.W, want.W, 1e-9 * std::hypot(want.U, want.W));
    }
    EXPECT_NEAR(s.v, c.lambda, 1e-12 * c.lambda);
}

void expect_dissipative_cycles(const std::vector<Cycle>& cycles, const ModelMatrices& m)
{
    for (const Cycle& c : cycles) {
        ASSERT_EQ(c.points.size(), static_cast<std::size_t>(c.period));
        for (const auto& p : c.points) {
            EXPECT_TRUE(in_region(p));
            EXPECT_GE(p.xi, c.points.front().xi);  // the representative has the smallest xi
        }
        const auto image = iterate(c.points.front(), m, c.period);
        ASSERT_TRUE(image.has_value());
        EXPECT_LE((as_vector(*image) - as_vector(c.points.front())).norm(), 1e-10 * as_vector(c.points.front()).norm());
        EXPECT_LE(c.residual, residual_tolerance);
        EXPECT_LT(c.lambda, 1.0);
        EXPECT_GT(c.lambda, 0.0);
        EXPECT_EQ(c.stability, classify(c.eigenvalues));
        EXPECT_FALSE(c.family);
        expect_physical_cycle(c, m);
    }
}

// e = alpha = 0.9: whatever is reported is a cycle with lambda < 1. (None exists in the
// interior for periods up to 3: the elastic family is destroyed by dissipation; what is
// left is the corner fixed point on the plane xi = 0, see BoundaryPlanes.)
TEST(Dynamics, DissipativeCyclesAreCycles)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.9));
    expect_dissipative_cycles(find_cycles(m, 3, 300, 5), m);
}

// e = 0.9 with alpha = 1 and 0.99: dissipative models with interior cycles.
TEST(Dynamics, DissipativeSelfSimilarMotionsAreFound)
{
    const ModelMatrices rough = ModelMatrices::of(Model::uniform(0.9, 1.0));
    const std::vector<Cycle> a = find_cycles(rough, 1, 1000, 1);
    ASSERT_EQ(a.size(), 1u);
    expect_dissipative_cycles(a, rough);
    EXPECT_NEAR(a[0].points[0].xi, 0.347498927545322, 1e-9);
    EXPECT_NEAR(a[0].points[0].U, -0.354891811487491, 1e-9);
    EXPECT_NEAR(a[0].points[0].W, -0.874280404918623, 1e-9);
    EXPECT_NEAR(a[0].lambda, 0.919164594869, 1e-9);
    EXPECT_EQ(a[0].stability, Stability::saddle);

    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.99));
    const std::vector<Cycle> b = find_cycles(m, 3, 1500, 7);
    ASSERT_GE(b.size(), 2u);
    EXPECT_EQ(b.front().period, 1);
    EXPECT_EQ(b.back().period, 3);
    expect_dissipative_cycles(b, m);
}

// A k-cycle found from any of its points is one cycle, with the same representative; a
// fixed point found as a solution of G^2(s) = s has period 1.
TEST(Dynamics, CyclesAreDeduplicatedAndHaveTheirMinimalPeriod)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.99));
    const std::vector<Cycle> found = find_cycles(m, 3, 1500, 7);
    const auto three = std::find_if(found.begin(), found.end(), [](const Cycle& c) { return c.period == 3; });
    ASSERT_NE(three, found.end());
    std::vector<Cycle> again;
    for (const auto& p : three->points) {
        const auto point = newton_cycle(p, m, 3);
        ASSERT_TRUE(point.has_value());
        const auto c = make_cycle(*point, m, 3);
        ASSERT_TRUE(c.has_value());
        EXPECT_EQ(c->period, 3);
        EXPECT_TRUE(same_cycle(*c, *three));
        EXPECT_NEAR(c->points.front().xi, three->points.front().xi, 1e-12);
        again.push_back(*c);
    }
    EXPECT_EQ(distinct_cycles(again).size(), 1u);

    const auto one = std::find_if(found.begin(), found.end(), [](const Cycle& c) { return c.period == 1; });
    ASSERT_NE(one, found.end());
    const auto as_two = make_cycle(one->points.front(), m, 2);
    ASSERT_TRUE(as_two.has_value());
    EXPECT_EQ(as_two->period, 1);
}

// Cycles on the corner plane xi = 0. e = alpha: the analytic corner fixed point
// (U, W) = (-1, -5/2) (boundary_planes.md), lambda = e^2, transverse multiplier e^-4.
TEST(Dynamics, CornerSearchFindsTheAnalyticCornerFixedPoint)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.9));
    const std::vector<Cycle> cycles = find_cycles(m, 2, 300, 3, Domain::corner);
    ASSERT_EQ(cycles.size(), 1u);
    const Cycle& c = cycles.front();
    EXPECT_TRUE(c.corner);
    EXPECT_EQ(c.period, 1);
    EXPECT_EQ(c.points[0].xi, 0.0);
    EXPECT_NEAR(c.points[0].U, -1.0, 1e-12);
    EXPECT_NEAR(c.points[0].W, -2.5, 1e-12);
    EXPECT_NEAR(c.lambda, 0.81, 1e-12);
    EXPECT_NEAR(c.eigenvalues[0].real(), std::pow(0.9, -4), 1e-10);
    EXPECT_EQ(c.eigenvalues[0].imag(), 0.0);
    EXPECT_EQ(c.stability, Stability::unstable);
    // The interior search does not mistake the plane for fixed points.
    for (const Cycle& interior : find_cycles(m, 1, 300, 3)) EXPECT_GT(interior.points[0].xi, 1e-6);
}

// e = 0.9, alpha = 0.99: the corner fixed point attracts, and G itself converges to it
// from a launch near the corner: U, W tend to the fixed point and xi shrinks by kappa per
// excursion (infinitely many bounces, the count is capped).
TEST(Dynamics, StableCornerFixedPointAttractsTheMotion)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.99));
    const std::vector<Cycle> cycles = find_cycles(m, 1, 300, 3, Domain::corner);
    ASSERT_EQ(cycles.size(), 1u);
    const Cycle& c = cycles.front();
    EXPECT_EQ(c.stability, Stability::stable);
    const auto kappa = std::find_if(c.eigenvalues.begin(), c.eigenvalues.end(),
                                    [](const auto& z) { return z.imag() == 0.0; });
    ASSERT_NE(kappa, c.eigenvalues.end());

    CanonicalState<double> s{1e-3, -1.0, -2.5};
    for (int i = 0; i < 2000; ++i) s = canonical_map(s, m).next;  // xi ~ 1e-23: U, W converge like xi
    const CanonicalState<double> next = canonical_map(s, m).next;
    EXPECT_NEAR(s.U, c.points[0].U, 1e-12);
    EXPECT_NEAR(s.W, c.points[0].W, 1e-12);
    EXPECT_NEAR(next.xi / s.xi, kappa->real(), 1e-12);
    EXPECT_EQ(count(CanonicalState<double>{1e-3, -1.0, -2.5}, m, 2000).outcome, Outcome::capped);
}

TEST(Dynamics, NewtonStaysInTheRegion)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 1.0));
    EXPECT_FALSE(newton_cycle({1.2, -0.5, 0.0}, m, 1).has_value());  // misses the wall
    EXPECT_FALSE(newton_cycle({0.3, 0.5, 0.0}, m, 1).has_value());   // heads away
    EXPECT_FALSE(newton_cycle({0.0, -0.5, 0.0}, m, 1).has_value());
    EXPECT_FALSE(iterate({0.3, 0.5, 0.0}, m, 1).has_value());
    EXPECT_FALSE(make_cycle({0.3, -0.5, 0.0}, m, 1).has_value());    // not a fixed point
    // Starts are reproducible and independent of how many are drawn.
    const auto a = seeded_starts(9, 10);
    const auto b = seeded_starts(9, 20);
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].xi, b[i].xi);
        EXPECT_EQ(a[i].W, b[i].W);
        EXPECT_TRUE(in_region(a[i]));
    }
}

TEST(Dynamics, StabilityLabels)
{
    using C = std::complex<double>;
    const std::array<C, 3> stable{C(0.5), C(-0.2, 0.3), C(-0.2, -0.3)};
    const std::array<C, 3> unstable{C(2.0), C(-1.5), C(1.01)};
    const std::array<C, 3> saddle{C(2.0), C(0.5), C(1.0)};
    const std::array<C, 3> marginal{C(1.0), C(0.6, 0.8), C(0.6, -0.8)};
    const std::array<C, 3> half{C(1.0 + 1e-12), C(0.5), C(0.2)};
    EXPECT_EQ(classify(stable), Stability::stable);
    EXPECT_EQ(classify(unstable), Stability::unstable);
    EXPECT_EQ(classify(saddle), Stability::saddle);
    EXPECT_EQ(classify(marginal), Stability::marginal);
    EXPECT_EQ(classify(half), Stability::marginal);
    EXPECT_EQ(name(Stability::saddle), "saddle");
}

// ---------------------------------------------------------------------------------------
// Boundary planes.

// Random (U, W) whose rebound off the wall, p = c_sW W + c_ss v_w, is of either sign but
// not near 0 (the singular line), and whose floor bounce sends the ball back (U' < 0).
std::vector<std::array<double, 2>> plane_points(const ModelMatrices& m, bool at_one, int count, std::uint64_t seed)
{
    const double v_w = at_one ? -1.0 : 1.0;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<std::array<double, 2>> out;
    for (int attempt = 0; attempt < 1000000 && static_cast<int>(out.size()) < count; ++attempt) {
        const double U = -std::pow(10.0, -1.0 + 1.5 * unit(rng));
        const double W = 10.0 * (2.0 * unit(rng) - 1.0);
        const double p = m.wall.c_sW * W + m.wall.c_ss * v_w;
        const PlaneStep limit = at_one ? plane_map_xi1(U, W, m) : plane_map_xi0(U, W, m);
        if (std::abs(p) > 0.2 && std::abs(p) < 3.0 && limit.U < -0.05) {
            out.push_back({U, W});
        }
    }
    return out;
}

// G at distance d from the plane minus its limit, for each of (U', W', lambda, xi' or xi'/d).
std::array<double, 4> plane_error(const ModelMatrices& m, bool at_one, double d, double U, double W)
{
    const PlaneStep limit = at_one ? plane_map_xi1(U, W, m) : plane_map_xi0(U, W, m);
    const double xi = at_one ? 1.0 - d : d;
    const double dist = at_one ? 1.0 - xi : xi;  // the d the input actually carries
    const CanonicalStep<double> g = canonical_map(CanonicalState<double>{xi, U, W}, m);
    const double xi_value = limit.to_corner ? g.next.xi / dist : g.next.xi;
    return {g.next.U - limit.U, g.next.W - limit.W, g.lambda - limit.lambda, xi_value - limit.xi};
}

// First order: error(d) = a d + b d^2 + ..., so the slopes error(d)/d converge to a with
// differences shrinking tenfold per decade of d, and where a dominates, the error itself
// shrinks tenfold per decade.
void expect_first_order(bool at_one)
{
    int corner = 0, interior = 0, tenfold = 0;
    for (const Model& model : models()) {
        const ModelMatrices m = ModelMatrices::of(model);
        for (const auto& [U, W] : plane_points(m, at_one, 40, at_one ? 5 : 6)) {
            const PlaneStep limit = at_one ? plane_map_xi1(U, W, m) : plane_map_xi0(U, W, m);
            (limit.to_corner ? corner : interior)++;
            const auto e4 = plane_error(m, at_one, 1e-4, U, W);
            const auto e5 = plane_error(m, at_one, 1e-5, U, W);
            const auto e6 = plane_error(m, at_one, 1e-6, U, W);
            const std::array<double, 4> size{std::abs(limit.U), std::abs(limit.W), limit.lambda, std::abs(limit.xi)};
            for (std::size_t q = 0; q < 4; ++q) {
                const double scale = std::max(1.0, size[q]);
                const double s4 = e4[q] / 1e-4, s5 = e5[q] / 1e-5, s6 = e6[q] / 1e-6;
                EXPECT_LE(std::abs(e6[q]), 1e-3 * scale) << "quantity " << q << " U=" << U << " W=" << W;
                EXPECT_LE(std::abs(s6 - s5), 0.15 * std::abs(s5 - s4) + 1e-6 * scale)
                    << "quantity " << q << " U=" << U << " W=" << W << " slopes " << s4 << " " << s5 << " " << s6;
                if (std::abs(s6) > 100.0 * std::abs(s5 - s6) && std::abs(e5[q]) > 1e-9 * scale) {
                    ++tenfold;
                    EXPECT_NEAR(e4[q] / e5[q], 10.0, 0.5) << "quantity " << q << " U=" << U << " W=" << W;
                    EXPECT_NEAR(e5[q] / e6[q], 10.0, 0.5) << "quantity " << q << " U=" << U << " W=" << W;
                }
            }
        }
    }
    // Both branches (the wall sends the ball up, or down into the corner) were tested, and
    // most quantities converge at exactly first order.
    EXPECT_GT(corner, 10);
    EXPECT_GT(interior, 10);
    EXPECT_GT(tenfold, 200);  // of 960 (6 models, 40 points, 4 quantities)
}

TEST(BoundaryPlanes, GConvergesToThePlaneMapAtXi0WithOrderOne) { expect_first_order(false); }

TEST(BoundaryPlanes, GConvergesToThePlaneMapAtXi1WithOrderOne) { expect_first_order(true); }

// e = alpha on both surfaces: (U, W) = (-1, -5/2) is a fixed point of the plane map at
// xi = 0 with lambda = e^2 and transverse multiplier xi'/xi = e^-4 (boundary_planes.md).
TEST(BoundaryPlanes, CornerFixedPointForEqualCoefficients)
{
    for (const double e : {0.5, 0.9, 1.0}) {
        const ModelMatrices m = ModelMatrices::of(Model::uniform(e, e));
        const PlaneStep r = plane_map_xi0(-1.0, -2.5, m);
        EXPECT_TRUE(r.to_corner);
        EXPECT_NEAR(r.p, -e, 1e-15);
        EXPECT_NEAR(r.U, -1.0, 1e-14);
        EXPECT_NEAR(r.W, -2.5, 1e-14);
        EXPECT_NEAR(r.lambda, e * e, 1e-15);
        EXPECT_NEAR(r.xi, std::pow(e, -4), 1e-13 * std::pow(e, -4));
        // The transverse multiplier is the limit of dxi'/dxi of G itself (first order in xi).
        const StepJacobian j = step_jacobian({1e-12, -1.0, -2.5}, m);
        EXPECT_NEAR(j.dG(0, 0), std::pow(e, -4), 1e-8 * std::pow(e, -4));
    }
}

// The plane xi = 1, rebound downward, is mapped onto the plane xi = 0; upward, into the
// interior at the limit value.
TEST(BoundaryPlanes, PlaneXi1LandsInTheCornerWhenTheWallSendsTheBallDown)
{
    const ModelMatrices m = ModelMatrices::of(Model::uniform(0.9, 0.9));
    const PlaneStep down = plane_map_xi1(-0.5, -1.0, m);  // p = c_sW W - c_ss < 0
    ASSERT_TRUE(down.to_corner);
    EXPECT_LT(down.p, 0.0);
    EXPECT_NEAR(canonical_map(CanonicalState<double>{1.0 - 1e-9, -0.5, -1.0}, m).next.xi, 1e-9 * down.xi, 1e-15);
    // Up and back to the wall needs a wall that turns much spin into lift (alpha_wall < 0).
    const ModelMatrices lift = ModelMatrices::of(Model{{0.7, -0.5}, {0.9, 1.0}});
    const PlaneStep up = plane_map_xi1(-0.2, 8.0, lift);
    ASSERT_FALSE(up.to_corner);
    ASSERT_LT(up.U, 0.0);
    EXPECT_GT(up.xi, 0.0);
    EXPECT_NEAR(canonical_map(CanonicalState<double>{1.0 - 1e-9, -0.2, 8.0}, lift).next.xi, up.xi, 1e-7 * up.xi);
}

}  // namespace
}  // namespace superball
