// Continuation of cycles of G in one coefficient (core/continuation.hpp), checked against
// references computed here independently: central differences for the derivatives,
// the scalar map for residuals, newton_cycle/make_cycle of core/dynamics (other
// variables, other Jacobian code) for the points, eigenvalues and events, and the closed
// forms of the elastic ball's fixed points (dynamics.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "core/continuation.hpp"
#include "core/dynamics.hpp"
#include "core/event_curve.hpp"
#include "dynamics_testing.hpp"

namespace superball {
namespace {

// Event curves (core/event_curve.hpp) are checked the same way: every point is an event of a
// one-parameter branch, found again by plain continuation in alpha at the point's e.
//
// Cycles of e = 0.9, alpha = 0.99 (superball fixed-points --e 0.9 --alpha 0.99 --period 3
// --corner): the interior fixed point, a period-3 cycle and the corner fixed point.
const Model dissipative = Model::uniform(0.9, 0.99);
const CanonicalState<double> interior_start{0.24880413569367, -0.5569088577658755, -1.356749283937639};
const CanonicalState<double> period3_start{0.01252607017597572, -0.6582213646031074, -0.5405380108558157};
const CanonicalState<double> corner_start{0.0, -1.076947076732448, -2.594682044804059};

Cycle cycle_at(const CanonicalState<double>& near, const Model& model, int k)
{
    const Domain domain = near.xi == 0.0 ? Domain::corner : Domain::interior;
    const ModelMatrices m = ModelMatrices::of(model);
    const auto p = newton_cycle(near, m, k, domain);
    EXPECT_TRUE(p.has_value());
    const auto c = p ? make_cycle(*p, m, k, domain) : std::nullopt;
    EXPECT_TRUE(c.has_value());
    return c ? *c : Cycle{};
}

// The cycle newton_cycle and make_cycle (core/dynamics) find from `near` at parameter value p.
std::optional<Cycle> reference_cycle(const CanonicalState<double>& near, const Model& model, Parameter parameter,
                                     double p, int k, Domain domain)
{
    const ModelMatrices m = ModelMatrices::of(with_parameter(model, parameter, p));
    const auto point = newton_cycle(near, m, k, domain);
    return point ? make_cycle(*point, m, k, domain) : std::nullopt;
}

Branch branch_of(const CanonicalState<double>& near, const Model& model, Parameter parameter, int k, double min,
                 double max, double max_step = 0.05)
{
    ContinuationSettings s;
    s.min = min;
    s.max = max;
    s.max_step = max_step;
    const auto b = continue_cycle(cycle_at(near, model, k), model, parameter, s);
    EXPECT_TRUE(b.has_value());
    return b ? *b : Branch{};
}

std::vector<BranchPoint> events_of(const Branch& b, BranchEvent e)
{
    std::vector<BranchPoint> out;
    std::copy_if(b.points.begin(), b.points.end(), std::back_inserter(out),
                 [&](const BranchPoint& p) { return p.event == e; });
    return out;
}

std::vector<BranchEvent> event_sequence(const Branch& b)
{
    std::vector<BranchEvent> out;
    for (const BranchPoint& p : b.points) {
        if (p.event != BranchEvent::none) out.push_back(p.event);
    }
    return out;
}

// The complex pair's modulus (the eigenvalue with the largest imaginary part).
double pair_modulus(const std::array<std::complex<double>, 3>& ev)
{
    return std::abs(*std::max_element(ev.begin(), ev.end(), [](auto a, auto b) { return a.imag() < b.imag(); }));
}

// ---- Derivatives -----------------------------------------------------------------------

// d G^k / dp by automatic differentiation against central differences of the scalar map,
// for every parameter; d G^k / dx against iterate_jacobian (the chain rule of dynamics.cpp);
// the value part bit for bit the double instantiation's.
TEST(Continuation, ParameterDerivativeMatchesCentralDifferences)
{
    // Also a model with friction and another ball (SPEC.md 1b): mu and inertia are
    // parameters too (an infinite mu is not: continuation starts from a finite one).
    Model frictional = Model::uniform(0.9, 0.9);
    frictional.wall.mu = 2.0;
    frictional.floor.mu = 3.0;
    frictional.inertia = 0.5;
    for (const int k : {1, 2}) {
        std::vector<Model> models = test::models(k);
        models.push_back(frictional);
        for (const Model& model : models) {
            const ModelMatrices m = ModelMatrices::of(model);
            for (const CanonicalState<double>& s : test::admissible_states(m, k, 20, 5 + static_cast<std::uint64_t>(k))) {
                for (const Parameter p : all_parameters) {
                    if (!parameter_defined(model, p) || !std::isfinite(parameter_value(model, p))) continue;
                    const ParameterJacobian j = parameter_jacobian(s, model, p, k);
                    ASSERT_TRUE(j.finite);
                    const IterateJacobian ref = iterate_jacobian(s, m, k);
                    EXPECT_EQ(j.image.xi, ref.state.xi);
                    EXPECT_EQ(j.image.U, ref.state.U);
                    EXPECT_EQ(j.image.W, ref.state.W);
                    EXPECT_LE((j.dG - ref.dG).norm(), 1e-12 * ref.dG.norm());
                    // Central differences; the analytic extension beyond e = 1 or alpha = 1 is
                    // the same formula, so the step may cross the physical bound.
                    const double p0 = parameter_value(model, p);
                    const double h = 1e-6;
                    const auto up = iterate(s, ModelMatrices::of(with_parameter(model, p, p0 + h)), k);
                    const auto down = iterate(s, ModelMatrices::of(with_parameter(model, p, p0 - h)), k);
                    ASSERT_TRUE(up && down);
                    const Eigen::Vector3d fd = (as_vector(*up) - as_vector(*down)) / (2.0 * h);
                    EXPECT_LE((j.dG_dp - fd).norm(), 1e-6 * std::max(1.0, fd.norm()))
                        << name(p) << " k=" << k << " AD " << j.dG_dp.transpose() << " FD " << fd.transpose();
                }
            }
        }
    }
}

TEST(Continuation, ParametersByName)
{
    for (const Parameter p : all_parameters) EXPECT_EQ(parameter_named(name(p)), p);
    EXPECT_FALSE(parameter_named("beta"));
    const Model m{{0.8, 0.6}, {0.95, 0.3}};
    EXPECT_FALSE(parameter_defined(m, Parameter::e));
    EXPECT_TRUE(parameter_defined(m, Parameter::e_floor));
    const Model both = with_parameter(m, Parameter::alpha, 0.5);
    EXPECT_EQ(both.wall.alpha, 0.5);
    EXPECT_EQ(both.floor.alpha, 0.5);
    EXPECT_EQ(both.wall.e, 0.8);
    EXPECT_EQ(parameter_value(with_parameter(m, Parameter::e_floor, 0.7), Parameter::e_floor), 0.7);
    EXPECT_EQ(with_parameter(m, Parameter::e_floor, 0.7).wall.e, 0.8);
}

// ---- Every point ------------------------------------------------------------------------

// Residual with the scalar map, parameter within the bounds, arclength increasing,
// and the eigenvalues of the scalar Jacobian of dynamics.cpp.
void expect_points_are_cycles(const Branch& b, const Model& model, Parameter parameter, double min, double max)
{
    ASSERT_FALSE(b.points.empty());
    for (std::size_t i = 0; i < b.points.size(); ++i) {
        const BranchPoint& q = b.points[i];
        SCOPED_TRACE(testing::Message() << "point " << i << " at " << name(parameter) << " = " << q.parameter);
        // Within the bounds up to the slack of 1e-12 (a branch along a bound, such as the
        // elastic family at alpha = 1, stays there up to rounding).
        EXPECT_GE(q.parameter, min - 1e-12);
        EXPECT_LE(q.parameter, max + 1e-12);
        if (i > 0) {
            EXPECT_GE(q.arclength, b.points[i - 1].arclength);
        }
        const ModelMatrices m = ModelMatrices::of(with_parameter(model, parameter, q.parameter));
        CanonicalState<double> c = q.point;
        for (int s = 0; s < b.period; ++s) c = canonical_map(c, m).next;
        const double residual = (as_vector(c) - as_vector(q.point)).cwiseAbs().maxCoeff();
        EXPECT_LE(residual, 1e-10);
        EXPECT_LE(q.residual, 1e-10);
        if (b.domain == Domain::corner) {
            EXPECT_EQ(q.point.xi, 0.0);
        }
        EXPECT_EQ(q.stability, classify(q.eigenvalues));
    }
}

// The branch passes through the cycles newton_cycle finds at the parameters it crosses:
// Newton's method from a branch point at its own parameter stays there, with the same
// eigenvalues (up to the conditioning of the eigenvalues near a fold).
void expect_points_are_newton_cycles(const Branch& b, const Model& model, Parameter parameter, int every)
{
    int checked = 0;
    for (std::size_t i = 0; i < b.points.size(); i += static_cast<std::size_t>(every)) {
        const BranchPoint& q = b.points[i];
        if (q.event != BranchEvent::none || (b.domain == Domain::interior && q.representative.xi < 1e-6)) continue;
        SCOPED_TRACE(testing::Message() << "point " << i << " at " << name(parameter) << " = " << q.parameter);
        const auto c = reference_cycle(q.representative, model, parameter, q.parameter, b.period, b.domain);
        ASSERT_TRUE(c.has_value());
        EXPECT_EQ(c->period, b.period);
        const CanonicalState<double>& r = c->points.front();
        const double scale = std::max(1.0, as_vector(r).norm());
        EXPECT_LE((as_vector(r) - as_vector(q.representative)).norm(), 1e-8 * scale);
        EXPECT_NEAR(c->lambda, q.lambda, 1e-10);
        for (std::size_t e = 0; e < 3; ++e) EXPECT_LE(std::abs(c->eigenvalues[e] - q.eigenvalues[e]), 1e-6);
        ++checked;
    }
    EXPECT_GT(checked, 3);
}

// ---- The elastic ball ---------------------------------------------------------------------

// e = alpha = 1: the fixed points (xi, U, W) = ((1 + U)/2, U, 5U/2) form a family at fixed
// parameter, with eigenvalue 1 and the pair mu, 1/mu everywhere. Continued in alpha the
// branch is the family itself: no fold, no Neimark-Sacker (their test functions vanish up to
// rounding), and it ends where the family does, at the corner point (-1, -5/2) and at U -> 0.
TEST(Continuation, ElasticFamilyHasNoFalseEvents)
{
    const Model elastic = Model::uniform(1.0, 1.0);
    const Branch b = branch_of({0.25, -0.5, -1.25}, elastic, Parameter::alpha, 1, 0.5, 1.0);
    expect_points_are_cycles(b, elastic, Parameter::alpha, 0.5, 1.0);
    for (const BranchPoint& q : b.points) {
        EXPECT_NEAR(q.parameter, 1.0, 1e-12);
        EXPECT_NEAR(q.lambda, 1.0, 1e-10);
        EXPECT_NEAR(q.point.xi, (1.0 + q.point.U) / 2.0, 1e-9);
        EXPECT_NEAR(q.point.W, 2.5 * q.point.U, 1e-9);
    }
    EXPECT_EQ(event_sequence(b), (std::vector<BranchEvent>{BranchEvent::boundary, BranchEvent::boundary}));
    const BranchPoint& corner = b.points.front();
    EXPECT_EQ(corner.note, "xi -> 0");
    EXPECT_NEAR(corner.point.U, -1.0, 1e-9);
    EXPECT_NEAR(corner.point.W, -2.5, 1e-9);
    EXPECT_EQ(b.points.back().note.rfind("U -> 0", 0), 0u);
    EXPECT_GT(b.points.size(), 30u);
}

// Continued in e, the family has one genuine branch point: at U = -1/3, where the branch of
// dissipative fixed points of alpha = 1, e < 1 meets it. Checked against newton_cycle at
// e = 1 - d: the fixed point near the family is U = -1/3 + O(d).
TEST(Continuation, ElasticFamilyBranchPointWhereTheDissipativeBranchAttaches)
{
    const Model elastic = Model::uniform(1.0, 1.0);
    const Branch b = branch_of({0.25, -0.5, -1.25}, elastic, Parameter::e, 1, 0.5, 1.0);
    const auto bp = events_of(b, BranchEvent::branch_point);
    ASSERT_EQ(bp.size(), 1u);
    // At a branch point the corrector's matrix is singular: the point is located to about
    // the square root of the rounding error (the AVX-512 build of Eigen's LU puts e at
    // 1 + 2.3e-8, the portable one within 1e-8), not to the corrector's tolerance.
    EXPECT_NEAR(bp[0].point.U, -1.0 / 3.0, 1e-7);
    EXPECT_NEAR(bp[0].parameter, 1.0, 1e-7);
    EXPECT_EQ(event_sequence(b), (std::vector<BranchEvent>{BranchEvent::boundary, BranchEvent::branch_point, BranchEvent::boundary}));
    for (const double d : {1e-3, 1e-4}) {
        const auto c = reference_cycle(bp[0].point, Model::uniform(1.0 - d, 1.0), Parameter::e, 1.0 - d, 1,
                                       Domain::interior);
        ASSERT_TRUE(c.has_value());
        EXPECT_LT(std::abs(c->points.front().U + 1.0 / 3.0), 0.5 * d);
        EXPECT_GT(std::abs(c->points.front().U + 1.0 / 3.0), 0.05 * d);  // not on the family: it moves
    }
}

// ---- e = 0.9: the interior fixed point and the corner fixed point in alpha ---------------

struct Dissipative {
    Branch interior = branch_of(interior_start, dissipative, Parameter::alpha, 1, 0.95, 1.0);
    Branch corner = branch_of(corner_start, dissipative, Parameter::alpha, 1, 0.95, 1.0);
};

const Dissipative& dissipative_branches()
{
    static const Dissipative d;
    return d;
}

TEST(Continuation, InteriorBranchPointsAreCycles)
{
    const Branch& b = dissipative_branches().interior;
    expect_points_are_cycles(b, dissipative, Parameter::alpha, 0.95, 1.0);
    expect_points_are_newton_cycles(b, dissipative, Parameter::alpha, 3);
    // The start is the cycle fixed-points reports.
    EXPECT_EQ(b.points[b.start].parameter, 0.99);
    EXPECT_LE((as_vector(b.points[b.start].point) - as_vector(interior_start)).norm(), 1e-12);
}

TEST(Continuation, CornerBranchPointsAreCycles)
{
    const Branch& b = dissipative_branches().corner;
    EXPECT_EQ(b.domain, Domain::corner);
    expect_points_are_cycles(b, dissipative, Parameter::alpha, 0.95, 1.0);
    expect_points_are_newton_cycles(b, dissipative, Parameter::alpha, 1);
}

// The interior branch goes from alpha = 1 (saddle) through two Neimark-Sacker points to the
// corner plane, which it reaches where the corner fixed point's transverse multiplier kappa
// passes 1 (a transcritical crossing): the two branches' events agree.
TEST(Continuation, InteriorBranchMeetsTheCornerBranchAtItsBranchPoint)
{
    const Dissipative& d = dissipative_branches();
    EXPECT_EQ(event_sequence(d.interior), (std::vector<BranchEvent>{BranchEvent::boundary, BranchEvent::neimark_sacker,
                                                               BranchEvent::neimark_sacker, BranchEvent::end}));
    EXPECT_EQ(event_sequence(d.corner), (std::vector<BranchEvent>{BranchEvent::end, BranchEvent::neimark_sacker, BranchEvent::branch_point,
                                                             BranchEvent::end}));
    const BranchPoint& meet = d.interior.points.front();
    EXPECT_EQ(meet.note, "xi -> 0");
    EXPECT_LT(meet.point.xi, 1e-12);
    const BranchPoint bp = events_of(d.corner, BranchEvent::branch_point).at(0);
    EXPECT_NEAR(meet.parameter, bp.parameter, 1e-9);
    EXPECT_NEAR(meet.point.U, bp.point.U, 1e-7);
    EXPECT_NEAR(meet.point.W, bp.point.W, 1e-7);
    // Independently: the corner cycle of dynamics.cpp at that alpha has kappa = 1, and kappa
    // is on either side of 1 just beside it.
    const auto kappa = [&](double alpha) {
        const auto c = reference_cycle(bp.point, dissipative, Parameter::alpha, alpha, 1, Domain::corner);
        EXPECT_TRUE(c.has_value());
        return c ? iterate_jacobian(c->points.front(), ModelMatrices::of(Model::uniform(0.9, alpha)), 1,
                                    Domain::corner)
                       .dG(0, 0)
                 : 0.0;
    };
    EXPECT_NEAR(kappa(bp.parameter), 1.0, 1e-7);
    EXPECT_GT(kappa(bp.parameter - 1e-5), 1.0);
    EXPECT_LT(kappa(bp.parameter + 1e-5), 1.0);
    // Both ends of the parameter range are solved there exactly.
    EXPECT_EQ(d.interior.points.back().parameter, 1.0);
    EXPECT_EQ(d.corner.points.front().parameter, 0.95);
    EXPECT_EQ(d.corner.points.back().parameter, 1.0);
}

// Neimark-Sacker: a complex pair on the unit circle at the event, inside on one side and
// outside on the other (the neighbouring branch points, and cycles of dynamics.cpp 1e-6
// away in the parameter).
TEST(Continuation, NeimarkSackerIsAPairCrossingTheUnitCircle)
{
    const Dissipative& d = dissipative_branches();
    std::size_t seen = 0;
    for (const Branch* b : {&d.interior, &d.corner}) {
        for (std::size_t i = 1; i + 1 < b->points.size(); ++i) {
            const BranchPoint& q = b->points[i];
            if (q.event != BranchEvent::neimark_sacker) continue;
            ++seen;
            SCOPED_TRACE(testing::Message() << "alpha = " << q.parameter);
            EXPECT_NEAR(pair_modulus(q.eigenvalues), 1.0, 1e-7);
            EXPECT_LE(q.bracket, 1e-8);
            const double before = pair_modulus(b->points[i - 1].eigenvalues) - 1.0;
            const double after = pair_modulus(b->points[i + 1].eigenvalues) - 1.0;
            EXPECT_LT(before * after, 0.0);
            const auto side = [&](double alpha) {
                const auto c = reference_cycle(q.representative, dissipative, Parameter::alpha, alpha, 1, b->domain);
                EXPECT_TRUE(c.has_value());
                return c ? pair_modulus(c->eigenvalues) - 1.0 : 0.0;
            };
            EXPECT_LT(side(q.parameter - 1e-6) * side(q.parameter + 1e-6), 0.0);
        }
    }
    EXPECT_EQ(seen, 3u);
}

// ---- A period-3 branch: folds, a period doubling ------------------------------------------

// Step control through a fold: the branch turns back in alpha; the fold is located by the
// sign change of the tangent's alpha component, the same with steps ten times smaller, and
// agrees with an independent computation: at alpha = alpha_f - delta the two cycles
// newton_cycle finds on either side of the fold are sqrt(delta) c apart, so the squared
// distance at two deltas extrapolates linearly to the fold's alpha.
TEST(Continuation, FoldOfAPeriod3Cycle)
{
    const Branch coarse = branch_of(period3_start, dissipative, Parameter::alpha, 3, 0.99, 1.0);
    const Branch fine = branch_of(period3_start, dissipative, Parameter::alpha, 3, 0.99, 1.0, 0.005);
    expect_points_are_cycles(coarse, dissipative, Parameter::alpha, 0.99, 1.0);
    // The first event after the start in increasing alpha.
    const auto first_fold = [](const Branch& b) {
        for (std::size_t i = b.start; i < b.points.size(); ++i) {
            if (b.points[i].event == BranchEvent::fold) return i;
        }
        return b.points.size();
    };
    const std::size_t i = first_fold(coarse);
    ASSERT_LT(i, coarse.points.size());
    const BranchPoint& f = coarse.points[i];
    const BranchPoint& fine_fold = fine.points.at(first_fold(fine));
    EXPECT_NEAR(f.parameter, fine_fold.parameter, 1e-10);
    EXPECT_GT(fine.points.size(), coarse.points.size());
    // alpha turns back: both neighbours lie below the fold.
    const BranchPoint& before = coarse.points[i - 1];
    const BranchPoint& after = coarse.points[i + 1];
    EXPECT_LT(before.parameter, f.parameter);
    EXPECT_LT(after.parameter, f.parameter);
    const auto ev1 = std::min_element(f.eigenvalues.begin(), f.eigenvalues.end(),
                                      [](auto a, auto b) { return std::abs(a - 1.0) < std::abs(b - 1.0); });
    EXPECT_LT(std::abs(*ev1 - 1.0), 1e-6);

    // Independent: the pair of cycles at alpha_f - delta.
    const auto squared_gap = [&](double delta) {
        // Starts on either side of the fold, scaled from the neighbours to the expected gap.
        const double scale = std::sqrt(delta / (f.parameter - before.parameter));
        const auto near = [&](const BranchPoint& side) {
            return as_state(as_vector(f.point) + scale * (as_vector(side.point) - as_vector(f.point)));
        };
        const auto a = reference_cycle(near(before), dissipative, Parameter::alpha, f.parameter - delta, 3,
                                       Domain::interior);
        const auto b = reference_cycle(near(after), dissipative, Parameter::alpha, f.parameter - delta, 3,
                                       Domain::interior);
        EXPECT_TRUE(a && b);
        if (!a || !b) return 0.0;
        // The same point of each cycle: the one nearest the fold point.
        const auto nearest = [&](const Cycle& c) {
            return *std::min_element(c.points.begin(), c.points.end(), [&](const auto& x, const auto& y) {
                return (as_vector(x) - as_vector(f.point)).norm() < (as_vector(y) - as_vector(f.point)).norm();
            });
        };
        return (as_vector(nearest(*a)) - as_vector(nearest(*b))).squaredNorm();
    };
    const double d1 = 4e-6, d2 = 1e-6;
    const double g1 = squared_gap(d1), g2 = squared_gap(d2);
    ASSERT_GT(g1, g2);
    EXPECT_NEAR(g1 / g2, d1 / d2, 0.05 * d1 / d2);  // the square-root law of a fold
    const double p1 = f.parameter - d1, p2 = f.parameter - d2;
    const double independent = (g1 * p2 - g2 * p1) / (g1 - g2);
    EXPECT_NEAR(independent, f.parameter, 1e-8);
    // Beyond the fold the two cycles are gone: Newton's method from the fold point finds
    // nothing near it.
    const auto beyond = reference_cycle(f.point, dissipative, Parameter::alpha, f.parameter + 1e-5, 3, Domain::interior);
    if (beyond) {
        const double gap = std::min({(as_vector(beyond->points[0]) - as_vector(f.point)).norm(),
                                     (as_vector(beyond->points[1]) - as_vector(f.point)).norm(),
                                     (as_vector(beyond->points[2]) - as_vector(f.point)).norm()});
        EXPECT_GT(gap, 1e-2);
    }
}

// Period doubling on the period-3 branch: a real eigenvalue through -1.
TEST(Continuation, PeriodDoublingIsARealEigenvalueThroughMinusOne)
{
    const Branch b = branch_of(period3_start, dissipative, Parameter::alpha, 3, 0.98, 1.0);
    const auto pd = events_of(b, BranchEvent::period_doubling);
    ASSERT_FALSE(pd.empty());
    for (const BranchPoint& q : pd) {
        SCOPED_TRACE(testing::Message() << "alpha = " << q.parameter);
        const auto minus_one = [](const std::array<std::complex<double>, 3>& ev) {
            return *std::min_element(ev.begin(), ev.end(),
                                     [](auto a, auto b) { return std::abs(a + 1.0) < std::abs(b + 1.0); });
        };
        EXPECT_LT(std::abs(minus_one(q.eigenvalues) + 1.0), 1e-7);
        const auto side = [&](double alpha) {
            const auto c = reference_cycle(q.representative, dissipative, Parameter::alpha, alpha, 3, Domain::interior);
            EXPECT_TRUE(c.has_value());
            const std::complex<double> z = c ? minus_one(c->eigenvalues) : 0.0;
            EXPECT_EQ(z.imag(), 0.0);
            return z.real() + 1.0;
        };
        EXPECT_LT(side(q.parameter - 1e-6) * side(q.parameter + 1e-6), 0.0);
    }
}

// ---- Grip and slide (SPEC.md 1b) -----------------------------------------------------------

// The friction coefficient at which an impact of the Cross model's cycle `c` begins to
// slide, from SPEC.md 1b's formulas written out here: psi (1 + alpha) / ((1 + e)(1 + 1/kappa))
// with psi = |s| / v_n of its wall impact (canonical coordinates: u = U, v = 1 - 2 xi) and of
// the floor impact after it (reached with vertical speed sqrt(v+^2 + 2 y), y = 2 xi (1 - xi)
// the height of the wall impact, where v0 = g = 1).
struct SwitchingMu {
    double wall = 0.0, floor = 0.0;
};

SwitchingMu switching_mu(const CanonicalState<double>& c, const Model& model)
{
    const double kappa = model.inertia;
    const auto limit = [&](const Surface& f, double psi) { return psi * (1.0 + f.alpha) / ((1.0 + f.e) * (1.0 + 1.0 / kappa)); };
    const double u = c.U, v = 1.0 - 2.0 * c.xi, W = c.W;
    const double beta = model.wall.alpha;
    const double v_after = ((1.0 - kappa * beta) * v + kappa * (1.0 + beta) * W) / (1.0 + kappa);
    const double W_after = ((1.0 + beta) * v + (kappa - beta) * W) / (1.0 + kappa);
    const double u_after = -model.wall.e * u;
    const double floor_speed = std::sqrt(v_after * v_after + 4.0 * c.xi * (1.0 - c.xi));
    return {limit(model.wall, std::abs(v - W) / -u), limit(model.floor, std::abs(u_after + W_after) / floor_speed)};
}

// Continued down in mu from 5, the interior fixed point of e = 0.9, alpha = 0.99 grips until
// mu reaches what its wall impact needs (its floor impact needs less): the cycle stays the
// Cross model's, with no event, then the branch turns (a kink: G is continuous, its Jacobian
// jumps) and goes on through sliding cycles. The switch is located to 1e-8 of the reference.
TEST(Continuation, GripSlideWhereTheGrippingCycleNeedsMoreThanMu)
{
    Model model = dissipative;
    model.wall.mu = model.floor.mu = 5.0;
    const CanonicalState<double> cross = cycle_at(interior_start, dissipative, 1).points.front();
    const SwitchingMu needed = switching_mu(cross, dissipative);
    ASSERT_GT(needed.wall, needed.floor);
    ASSERT_LT(needed.wall, 5.0);

    const Branch b = branch_of(interior_start, model, Parameter::mu, 1, 0.05, 5.0);
    expect_points_are_cycles(b, model, Parameter::mu, 0.05, 5.0);
    expect_points_are_newton_cycles(b, model, Parameter::mu, 2);
    const auto slides = events_of(b, BranchEvent::grip_slide);
    ASSERT_FALSE(slides.empty());
    const BranchPoint& first = *std::max_element(slides.begin(), slides.end(), [](const auto& x, const auto& y) {
        return x.parameter < y.parameter;
    });
    EXPECT_NEAR(first.parameter, needed.wall, 1e-8);
    EXPECT_LE(first.bracket, 1e-8);
    EXPECT_NE(first.note.find("wall impact"), std::string::npos) << first.note;
    std::size_t beyond = 0;
    for (const BranchPoint& q : b.points) {
        SCOPED_TRACE(testing::Message() << "mu = " << q.parameter << ", " << name(q.event));
        if (q.parameter > needed.wall + 1e-8) {
            // Gripping: the Cross model's cycle, and no event but the end at mu = 5.
            EXPECT_LE((as_vector(q.point) - as_vector(cross)).norm(), 1e-9);
            EXPECT_TRUE(q.event == BranchEvent::none || (q.event == BranchEvent::end && q.parameter == 5.0));
        } else if (q.parameter < needed.wall - 1e-6) {
            ++beyond;
        }
    }
    // The branch went on past the switch, not stopped by a corrector that could not turn.
    EXPECT_GE(beyond, 3u);
    EXPECT_NE(b.points.front().note.find("xi -> 0"), std::string::npos) << b.points.front().note;
}

// ---- Event curves in (alpha, e) ----------------------------------------------------------

EventCurve curve_of(const Branch& b, BranchEvent e, std::size_t nth, double min_e, double max_e)
{
    std::size_t seen = 0;
    for (std::size_t i = 0; i < b.points.size(); ++i) {
        if (b.points[i].event != e || seen++ != nth) continue;
        EventCurveSettings s;
        s.min1 = 0.5;
        s.max1 = 1.0;
        s.min2 = min_e;
        s.max2 = max_e;
        const auto c = continue_event(b, i, dissipative, Parameter::alpha, Parameter::e, s);
        EXPECT_TRUE(c.has_value());
        return c ? *c : EventCurve{};
    }
    ADD_FAILURE() << "no " << name(e) << " number " << nth;
    return {};
}

// At curve points, plain continuation in alpha with e fixed there finds the same event at the
// same alpha.
void expect_curve_matches_one_parameter_continuation(const EventCurve& c, double tolerance)
{
    ASSERT_GT(c.points.size(), 6u);
    int checked = 0;
    for (std::size_t i = 0; i < c.points.size(); i += std::max<std::size_t>(1, c.points.size() / 8)) {
        const EventCurvePoint& p = c.points[i];
        SCOPED_TRACE(testing::Message() << "alpha = " << p.first << ", e = " << p.second);
        // Started off the event (a start on it would see no change of sign), on the side where
        // the cycles exist for a fold.
        std::optional<Cycle> start;
        double offset = 0.0;
        for (const double d : {-0.003, 0.003}) {
            start = reference_cycle(p.point.point, Model::uniform(p.second, p.first + d), Parameter::alpha,
                                    p.first + d, c.period, c.domain);
            offset = d;
            if (start) break;
        }
        ASSERT_TRUE(start.has_value());
        const Model m = Model::uniform(p.second, p.first + offset);
        ContinuationSettings s;
        s.min = std::max(0.5, p.first - 0.01);
        s.max = std::min(1.0, p.first + 0.01);
        s.max_step = 0.002;
        const auto b = continue_cycle(*start, m, Parameter::alpha, s);
        ASSERT_TRUE(b.has_value());
        double nearest = HUGE_VAL;
        for (const BranchPoint& q : b->points) {
            if (q.event == c.event) nearest = std::min(nearest, std::abs(q.parameter - p.first));
        }
        EXPECT_LE(nearest, tolerance);
        ++checked;
    }
    EXPECT_GT(checked, 3);
}

// The corner fixed point's Neimark-Sacker curve: a pair on the unit circle all along, inside on
// one side and outside on the other (cycles of dynamics.cpp 1e-6 away in alpha).
TEST(EventCurve, NeimarkSackerCurveOfTheCornerFixedPoint)
{
    const EventCurve c = curve_of(dissipative_branches().corner, BranchEvent::neimark_sacker, 0, 0.5, 0.99);
    EXPECT_EQ(c.domain, Domain::corner);
    EXPECT_EQ(c.points[c.start].second, 0.9);
    for (std::size_t i = 0; i + 1 < c.points.size(); ++i) {
        EXPECT_LT(std::hypot(c.points[i + 1].first - c.points[i].first, c.points[i + 1].second - c.points[i].second), 0.03);
    }
    for (std::size_t i = 0; i < c.points.size(); i += 5) {
        const EventCurvePoint& p = c.points[i];
        SCOPED_TRACE(testing::Message() << "alpha = " << p.first << ", e = " << p.second);
        EXPECT_EQ(p.point.point.xi, 0.0);
        EXPECT_NEAR(pair_modulus(p.point.eigenvalues), 1.0, 1e-7);
        const Model m = Model::uniform(p.second, p.first);
        const auto side = [&](double alpha) {
            const auto r = reference_cycle(p.point.point, m, Parameter::alpha, alpha, 1, Domain::corner);
            EXPECT_TRUE(r.has_value());
            return r ? pair_modulus(r->eigenvalues) - 1.0 : 0.0;
        };
        EXPECT_LT(side(p.first - 1e-6) * side(p.first + 1e-6), 0.0);
    }
    expect_curve_matches_one_parameter_continuation(c, 1e-8);
    // It spans the whole e range asked for.
    const auto [lo, hi] = std::minmax_element(c.points.begin(), c.points.end(),
                                              [](const auto& a, const auto& b) { return a.second < b.second; });
    EXPECT_LT(lo->second, 0.52);
    EXPECT_GT(hi->second, 0.97);
}

// The corner fixed point's branch-point curve (kappa = 1), where interior fixed points are born
// at the corner plane: kappa = 1 of the corner cycle of dynamics.cpp along it.
TEST(EventCurve, BranchPointCurveWhereInteriorFixedPointsMeetTheCorner)
{
    const EventCurve c = curve_of(dissipative_branches().corner, BranchEvent::branch_point, 0, 0.5, 0.99);
    for (std::size_t i = 0; i < c.points.size(); i += 5) {
        const EventCurvePoint& p = c.points[i];
        SCOPED_TRACE(testing::Message() << "alpha = " << p.first << ", e = " << p.second);
        const auto r = reference_cycle(p.point.point, Model::uniform(p.second, p.first), Parameter::alpha, p.first, 1,
                                       Domain::corner);
        ASSERT_TRUE(r.has_value());
        const double kappa = iterate_jacobian(r->points.front(), ModelMatrices::of(Model::uniform(p.second, p.first)), 1,
                                              Domain::corner)
                                 .dG(0, 0);
        EXPECT_NEAR(kappa, 1.0, 1e-7);
    }
    expect_curve_matches_one_parameter_continuation(c, 1e-8);
}

// A fold curve of the period-3 cycle, followed where it turns: an eigenvalue 1 along it, and the
// fold found again by continuation in alpha.
TEST(EventCurve, FoldCurveOfAPeriod3Cycle)
{
    const Branch b = branch_of(period3_start, dissipative, Parameter::alpha, 3, 0.98, 1.0);
    const EventCurve c = curve_of(b, BranchEvent::fold, 0, 0.85, 0.95);
    for (const EventCurvePoint& p : c.points) {
        const auto ev1 = std::min_element(p.point.eigenvalues.begin(), p.point.eigenvalues.end(),
                                          [](auto x, auto y) { return std::abs(x - 1.0) < std::abs(y - 1.0); });
        EXPECT_LT(std::abs(*ev1 - 1.0), 1e-6) << "alpha = " << p.first << ", e = " << p.second;
    }
    expect_curve_matches_one_parameter_continuation(c, 1e-8);
}

TEST(EventCurve, RefusesWhatIsNoCurve)
{
    const Branch& b = dissipative_branches().corner;
    EventCurveSettings s;
    // An end point is no event to follow; alpha and alpha_wall are not independent.
    EXPECT_FALSE(continue_event(b, 0, dissipative, Parameter::alpha, Parameter::e, s));
    for (std::size_t i = 0; i < b.points.size(); ++i) {
        if (b.points[i].event == BranchEvent::neimark_sacker) {
            EXPECT_FALSE(continue_event(b, i, dissipative, Parameter::alpha, Parameter::alpha_wall, s));
        }
    }
    EXPECT_TRUE(independent(Parameter::alpha, Parameter::e));
    EXPECT_TRUE(independent(Parameter::e_wall, Parameter::e_floor));
    EXPECT_FALSE(independent(Parameter::e, Parameter::e_floor));
    EXPECT_FALSE(independent(Parameter::alpha, Parameter::alpha));
    // SPEC.md 1b's: mu moves both surfaces' mu, inertia the ball's.
    EXPECT_FALSE(independent(Parameter::mu, Parameter::mu_wall));
    EXPECT_TRUE(independent(Parameter::mu_wall, Parameter::mu_floor));
    EXPECT_TRUE(independent(Parameter::mu, Parameter::e));
    EXPECT_TRUE(independent(Parameter::inertia, Parameter::alpha));
    EXPECT_FALSE(independent(Parameter::inertia, Parameter::inertia));
}

}  // namespace
}  // namespace superball
