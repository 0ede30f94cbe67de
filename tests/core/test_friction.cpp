// Which ball, which surface (SPEC.md 1b): the moment of inertia kappa and Walton's Coulomb
// friction law. The defaults are the Cross model bit for bit; each impact conserves the
// angular momentum about the contact point, keeps beta in [-1, alpha], never adds energy,
// and where it slides its tangential impulse is exactly mu times the normal one; the
// impact is continuous across the grip/slide threshold; G commutes with F; every kernel
// variant counts as the scalar kernel does.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "core/dynamics.hpp"
#include "core/impact.hpp"
#include "core/kernels.hpp"
#include "core/map.hpp"
#include "core/state.hpp"
#include "reference_data.hpp"

namespace superball::friction_testing {
namespace {

using test::describe;
using test::full;
using test::Sampler;
using test::ScaledNear;

constexpr double inf = std::numeric_limits<double>::infinity();

// Twice the kinetic energy per unit mass: u^2 + v^2 + kappa W^2 (W = a omega).
double energy2(const Velocities<double>& s, double kappa) { return s.u * s.u + s.v * s.v + kappa * s.W * s.W; }

// ------------------------------------------------------------------ the defaults

// With q = 1/kappa = 2.5 the matrix entries are section 1's numerators and denominator
// halved (impact.hpp): the same doubles, for every alpha. Checked on a million alphas.
TEST(FrictionDefaults, SolidBallEntriesAreSectionOnesBitForBit)
{
    EXPECT_EQ(1.0 / solid_ball_inertia, 2.5);
    Sampler smp(0x5eed1b01);
    std::vector<double> alphas{-1.0, -0.5, 0.0, 0.5, 0.9, 0.99, 1.0, -0.0, 1e-300, -1e-300, 0.1, 0.3, 0.7};
    for (int i = 0; i < 1000000; ++i) alphas.push_back(smp.uniform(-1.0, 1.0));
    for (const double alpha : alphas) {
        const ImpactMatrix k = ImpactMatrix::of(Surface{0.9, alpha});
        ASSERT_EQ(k.c_ss, (5.0 - 2.0 * alpha) / 7.0) << full(alpha);
        ASSERT_EQ(k.c_sW, 2.0 * (1.0 + alpha) / 7.0) << full(alpha);
        ASSERT_EQ(k.c_Ws, 5.0 * (1.0 + alpha) / 7.0) << full(alpha);
        ASSERT_EQ(k.c_WW, (2.0 - 5.0 * alpha) / 7.0) << full(alpha);
    }
    const Model defaults;
    EXPECT_EQ(defaults.inertia, 0.4);
    EXPECT_EQ(defaults.wall.mu, inf);
    EXPECT_EQ(defaults.floor.mu, inf);
    EXPECT_FALSE(defaults.frictional());
    EXPECT_FALSE(ModelMatrices::of(Model::uniform(0.9, 0.9)).frictional);
}

// An infinite mu is the Cross model for the same kappa, bit for bit: Walton's impacts
// return the gripping impact's very numbers, for any inertia.
TEST(FrictionDefaults, InfiniteMuIsTheCrossModelBitForBit)
{
    Sampler smp(0x5eed1b02);
    for (int i = 0; i < 20000; ++i) {
        Model m = smp.model();
        m.inertia = smp.inertia();
        const ModelMatrices k = ModelMatrices::of(m);
        const Velocities<double> in{-smp.log_uniform(1e-3, 10.0), smp.uniform(-10.0, 10.0), smp.uniform(-10.0, 10.0)};
        const Velocities<double> a = wall_impact(in, k.wall), b = walton_wall_impact(in, k.wall);
        ASSERT_TRUE(a.u == b.u && a.v == b.v && a.W == b.W) << describe(m);
        const Velocities<double> floor_in{in.u, -in.v * in.v - 0.1, in.W};
        const Velocities<double> c = floor_impact(floor_in, k.floor), d = walton_floor_impact(floor_in, k.floor);
        ASSERT_TRUE(c.u == d.u && c.v == d.v && c.W == d.W) << describe(m);
        const CanonicalState<double> s = smp.launch();
        const CanonicalStep<double> g1 = canonical_map<ImpactLaw::cross>(s, k);
        const CanonicalStep<double> g2 = canonical_map<ImpactLaw::walton>(s, k);
        ASSERT_TRUE(g1.next.xi == g2.next.xi && g1.next.U == g2.next.U && g1.next.W == g2.next.W &&
                    g1.lambda == g2.lambda)
            << describe(m) << " " << describe(s);
    }
}

// ------------------------------------------------------------------ one impact

struct Case {
    Surface surface;
    double kappa;
    Velocities<double> in;
};

std::vector<Case> cases(Sampler& smp)
{
    std::vector<Case> out;
    for (int i = 0; i < 400; ++i) {
        Surface s = smp.surface();
        s.mu = smp.mu();
        const double kappa = smp.inertia();
        for (int j = 0; j < 50; ++j) {
            // A normal velocity that approaches the surface (u < 0 at the wall, v < 0 at the floor).
            out.push_back({s, kappa, {-smp.log_uniform(1e-3, 10.0), smp.uniform(-10.0, 10.0), smp.uniform(-10.0, 10.0)}});
        }
    }
    return out;
}

std::string describe(const Case& c)
{
    return "e " + full(c.surface.e) + ", alpha " + full(c.surface.alpha) + ", mu " + full(c.surface.mu) + ", kappa " +
           full(c.kappa) + ", in (u " + full(c.in.u) + ", v " + full(c.in.v) + ", W " + full(c.in.W) + ")";
}

// The checks shared by both surfaces, in the surface's own terms: `n`, `t` the normal and
// tangential velocity of the centre before (n < 0: approaching) and after, `s`, `s_out` the
// contact velocity before and after, `l`, `l_out` the angular momentum about the contact point.
struct Seen {
    double n, n_out, t, t_out, s, s_out, l, l_out;
};

void check_impact(const Case& c, const Seen& x, double energy_before, double energy_after)
{
    const double scale = std::fabs(c.in.u) + std::fabs(c.in.v) + std::fabs(c.in.W) / c.kappa;
    constexpr double tol = 1e-13;
    EXPECT_EQ(x.n_out, -c.surface.e * x.n) << describe(c);
    EXPECT_PRED_FORMAT4(ScaledNear, x.l_out, x.l, scale, tol) << describe(c);
    EXPECT_LE(energy_after, energy_before * (1.0 + tol)) << describe(c);
    const double approach = -x.n;
    const double psi = std::fabs(x.s) / approach;
    const double threshold = c.surface.mu * (1.0 + c.surface.e) * (1.0 + 1.0 / c.kappa) / (1.0 + c.surface.alpha);
    if (std::fabs(x.s) < 1e-9 * scale) return;  // beta is not measurable
    // beta = -s'/s in [-1, alpha]; alpha exactly where it grips.
    const double beta = -x.s_out / x.s;
    EXPECT_GE(beta, -1.0 - 1e-9 * scale / std::fabs(x.s)) << describe(c);
    EXPECT_LE(beta, c.surface.alpha + 1e-9 * scale / std::fabs(x.s)) << describe(c);
    if (psi > threshold * (1.0 + 1e-12)) {
        // Slides: |tangential impulse| = mu |normal impulse|, against the contact velocity.
        EXPECT_PRED_FORMAT4(ScaledNear, std::fabs(x.t_out - x.t), c.surface.mu * (1.0 + c.surface.e) * approach, scale,
                            tol)
            << describe(c);
        EXPECT_LE((x.t_out - x.t) * x.s, 0.0) << describe(c);  // 0 where mu = 0
        EXPECT_NEAR(beta, -1.0 + c.surface.mu * (1.0 + c.surface.e) * (1.0 + 1.0 / c.kappa) / psi,
                    1e-9 * scale / std::fabs(x.s))
            << describe(c);
    } else if (psi < threshold * (1.0 - 1e-12)) {
        EXPECT_NEAR(beta, c.surface.alpha, 1e-9 * scale / std::fabs(x.s)) << describe(c);
    }
}

// Wall: normal u, tangential v, contact velocity v - W, angular momentum kappa W + v.
TEST(FrictionImpacts, WallConservesAndCaps)
{
    Sampler smp(0x5eed1b03);
    int slid = 0;
    for (const Case& c : cases(smp)) {
        const Velocities<double> out = walton_wall_impact(c.in, ImpactMatrix::of(c.surface, c.kappa));
        check_impact(c,
                     {c.in.u, out.u, c.in.v, out.v, c.in.v - c.in.W, out.v - out.W, c.kappa * c.in.W + c.in.v,
                      c.kappa * out.W + out.v},
                     energy2(c.in, c.kappa), energy2(out, c.kappa));
        slid += slides(c.in.v - c.in.W, -c.in.u, ImpactMatrix::of(c.surface, c.kappa));
    }
    EXPECT_GT(slid, 2000);  // both kinds of impact are exercised
}

// Floor: normal v, tangential u, contact velocity u + W, angular momentum kappa W - u.
TEST(FrictionImpacts, FloorConservesAndCaps)
{
    Sampler smp(0x5eed1b04);
    int slid = 0;
    for (Case c : cases(smp)) {
        c.in = {c.in.v, c.in.u, c.in.W};  // the approaching velocity is the normal one: v < 0
        const Velocities<double> out = walton_floor_impact(c.in, ImpactMatrix::of(c.surface, c.kappa));
        check_impact(c,
                     {c.in.v, out.v, c.in.u, out.u, c.in.u + c.in.W, out.u + out.W, c.kappa * c.in.W - c.in.u,
                      c.kappa * out.W - out.u},
                     energy2(c.in, c.kappa), energy2(out, c.kappa));
        slid += slides(c.in.u + c.in.W, -c.in.v, ImpactMatrix::of(c.surface, c.kappa));
    }
    EXPECT_GT(slid, 2000);
}

// The impact is continuous across the switching surface: just below and just above the
// threshold psi* the results differ by O(distance) only, and contact() reports beta = alpha
// on the gripping side and beta -> alpha from below on the sliding side.
TEST(FrictionImpacts, ContinuousAcrossTheGripSlideThreshold)
{
    const Surface surface{0.9, 0.8, 0.7};
    for (const double kappa : {0.25, 0.4, 2.0 / 3.0}) {
        const ImpactMatrix k = ImpactMatrix::of(surface, kappa);
        const double threshold = surface.mu * (1.0 + surface.e) * (1.0 + 1.0 / kappa) / (1.0 + surface.alpha);
        EXPECT_DOUBLE_EQ(k.grip_ratio, threshold);
        for (const double sign : {1.0, -1.0}) {
            const double W = 0.3;
            const auto at = [&](double psi) { return walton_wall_impact(Velocities<double>{-1.0, W + sign * psi, W}, k); };
            const Velocities<double> below = at(threshold * (1.0 - 1e-9)), above = at(threshold * (1.0 + 1e-9));
            EXPECT_NEAR(below.v, above.v, 1e-7) << kappa;
            EXPECT_NEAR(below.W, above.W, 1e-7) << kappa;
            const Contact grip = contact(sign * threshold * (1.0 - 1e-9), 1.0, surface.alpha, k);
            const Contact slip = contact(sign * threshold * (1.0 + 1e-9), 1.0, surface.alpha, k);
            EXPECT_FALSE(grip.slid);
            EXPECT_EQ(grip.beta, surface.alpha);
            EXPECT_TRUE(slip.slid);
            EXPECT_LT(slip.beta, surface.alpha);
            EXPECT_NEAR(slip.beta, surface.alpha, 1e-8);
        }
    }
}

// mu = 0 is a smooth surface: the tangential velocity and the spin pass unchanged (beta = -1).
TEST(FrictionImpacts, ZeroMuIsSmooth)
{
    const ImpactMatrix k = ImpactMatrix::of(Surface{0.8, 0.9, 0.0}, 0.5);
    const Velocities<double> w = walton_wall_impact(Velocities<double>{-1.5, 0.25, 3.0}, k);
    EXPECT_EQ(w.v, 0.25);
    EXPECT_EQ(w.W, 3.0);
    const Velocities<double> f = walton_floor_impact(Velocities<double>{0.25, -1.5, 3.0}, k);
    EXPECT_EQ(f.u, 0.25);
    EXPECT_EQ(f.W, 3.0);
    EXPECT_EQ(contact(2.75, 1.5, 0.9, k).beta, -1.0);
}

// ------------------------------------------------------------------ the maps

// C(F(s)) = G(C(s)) for frictional models: psi is a ratio of velocities, so whether an
// impact slides is the same for every representative of the scale class (SPEC.md 1b).
// Same restrictions and tolerance as test_properties' MapsCommute, and launches whose
// impacts come within 1e-9 of a threshold are left out (the two routes round differently
// and may take different sides there).
TEST(FrictionMaps, CanonicalOfPhysicalMapEqualsCanonicalMap)
{
    Sampler smp(0x5eed1b05);
    int compared = 0, slid = 0;
    for (int i = 0; i < 20000; ++i) {
        const Model model = smp.walton_model();
        const ModelMatrices m = ModelMatrices::of(model);
        const CanonicalState<double> c = smp.launch(0.01, 0.99);
        const double g = smp.gravity(), v = smp.speed();
        const PhysicalState<double> s = to_physical(c, g, v);
        const Excursion<double> x = excursion(s, m, g);
        // Distance of each impact from its threshold.
        const double s_wall = x.to_wall.v_w - s.W, s_floor = x.after_wall.u + x.after_wall.W;
        const double psi_wall = std::fabs(s_wall) / -s.u, psi_floor = std::fabs(s_floor) / -x.to_floor.v_f;
        const auto near_threshold = [](double psi, double threshold) {
            return std::isfinite(threshold) && std::fabs(psi - threshold) <= 1e-9 * threshold;
        };
        if (near_threshold(psi_wall, m.wall.grip_ratio) || near_threshold(psi_floor, m.floor.grip_ratio)) continue;
        slid += psi_wall > m.wall.grip_ratio || psi_floor > m.floor.grip_ratio;
        if (!(x.next.u < 0.0)) continue;
        const CanonicalState<double> a = to_canonical(x.next, g);
        const CanonicalStep<double> b = canonical_map(c, m);
        if (!(b.next.U < 0.0)) continue;
        // As in MapsCommute: relative to the terms u' is made of (it may cancel), and xi'
        // relative to itself times that cancellation (xi' ~ 1/|u'|).
        const double terms = (std::fabs(x.after_wall.u) + std::fabs(x.after_wall.W) / model.inertia) / x.next.v;
        const double cancellation = std::fmax(1.0, terms / std::fabs(b.next.U));
        EXPECT_PRED_FORMAT4(ScaledNear, a.U, b.next.U, terms, 1e-11) << describe(model) << describe(c);
        EXPECT_PRED_FORMAT4(ScaledNear, a.W, b.next.W, terms + std::fabs(b.next.W), 1e-11) << describe(model) << describe(c);
        EXPECT_PRED_FORMAT4(ScaledNear, a.xi, b.next.xi, b.next.xi * cancellation, 1e-10) << describe(model) << describe(c);
        EXPECT_PRED_FORMAT4(ScaledNear, x.next.v / s.v, b.lambda, b.lambda, 1e-11) << describe(model) << describe(c);
        ++compared;
    }
    EXPECT_GT(compared, 3000);
    EXPECT_GT(slid, 2000);
}

// Energy never grows along whole orbits of frictional models: the kinetic energy just after
// each floor bounce (height 0, so the whole mechanical energy), excursion after excursion of F.
TEST(FrictionMaps, EnergyNeverGrowsAlongOrbits)
{
    Sampler smp(0x5eed1b06);
    for (int i = 0; i < 2000; ++i) {
        const Model model = smp.walton_model();
        const ModelMatrices m = ModelMatrices::of(model);
        PhysicalState<double> s = to_physical(smp.launch(0.01, 0.99), 1.0, 1.0);
        for (int n = 0; n < 20 && s.u < 0.0 && s.x > 0.0; ++n) {
            if (!(flight_to_wall(s, 1.0).y > 0.0)) break;
            const Excursion<double> x = excursion(s, m, 1.0);
            // Mechanical energy after each floor bounce (height 0): kinetic only.
            const double before = energy2({s.u, s.v, s.W}, model.inertia);
            const double after = energy2({x.next.u, x.next.v, x.next.W}, model.inertia);
            ASSERT_LE(after, before * (1.0 + 1e-13)) << describe(model) << " excursion " << n;
            s = x.next;
        }
    }
}

// ------------------------------------------------------------------ the reference

// tests/reference/mp_friction_counts.csv: launches counted by an independent implementation
// of SPEC.md 1b in mpmath at 40 and 80 digits (tests/reference/mp_reference.py --friction),
// kept only where the answer survives perturbations of the launch, the coefficients and each
// step and no impact comes within 1e-9 of its grip/slide threshold: long and capped orbits,
// 25 models (mu 0 to infinite, per surface; inertia 1/4 to 2/3). Every row, through the
// scalar kernel and every vectorised variant this processor runs, alone and amid a batch.
struct FrictionRow {
    int line_number;
    std::string text;
    Model model;
    CanonicalState<double> start;
    std::uint32_t max_bounces, wall_bounces;
    Outcome outcome;
    int slides;
};

std::vector<FrictionRow> friction_rows()
{
    const std::string path = test::reference_dir() + "/mp_friction_counts.csv";
    std::vector<FrictionRow> rows;
    for (const test::CsvLine& l : test::read_csv(path, "e_wall,alpha_wall,mu_wall,e_floor,alpha_floor,mu_floor,inertia,"
                                                       "max_bounces,xi,U,W,wall_bounces,outcome,slides")) {
        if (l.fields.size() != 14) throw std::runtime_error(path + ": line " + std::to_string(l.line_number));
        std::vector<double> x;
        for (std::size_t i = 0; i < 14; ++i) x.push_back(i == 12 ? 0.0 : test::parse_double(l.fields[i]));
        const auto outcome = outcome_from_name(l.fields[12]);
        if (!outcome) throw std::runtime_error(path + ": bad outcome " + l.fields[12]);
        rows.push_back({l.line_number, l.text, Model{{x[0], x[1], x[2]}, {x[3], x[4], x[5]}, x[6]}, {x[8], x[9], x[10]},
                        static_cast<std::uint32_t>(x[7]), static_cast<std::uint32_t>(x[11]), *outcome,
                        static_cast<int>(x[13])});
    }
    return rows;
}

TEST(FrictionReference, EveryKernelCountsEveryRowAsTheReference)
{
    const std::vector<FrictionRow> rows = friction_rows();
    ASSERT_GE(rows.size(), 500u);
    int slid = 0, capped = 0, long_orbits = 0;
    std::vector<const KernelVariant*> kernels{&scalar_kernel()};
    for (const KernelVariant& k : simd_kernels()) {
        if (k.runs_here()) kernels.push_back(&k);
    }
    for (const FrictionRow& r : rows) {
        slid += r.slides > 0;
        capped += r.outcome == Outcome::capped;
        long_orbits += r.wall_bounces >= 100;
        const BounceCount one = count(r.start, r.model, r.max_bounces);
        EXPECT_EQ(one.wall_bounces, r.wall_bounces) << "line " << r.line_number << ": " << r.text;
        EXPECT_EQ(one.outcome, r.outcome) << "line " << r.line_number << ": " << r.text;
        std::vector<CanonicalState<double>> batch(11, CanonicalState<double>{0.3, -1.0, 0.5});
        batch.insert(batch.begin() + 4, r.start);
        const Starts s = Starts::of(batch);
        for (const KernelVariant* k : kernels) {
            std::vector<std::uint32_t> n(batch.size());
            std::vector<std::uint8_t> o(batch.size());
            k->count(s.view(), ModelMatrices::of(r.model), r.max_bounces, n, o);
            EXPECT_EQ(n[4], r.wall_bounces) << k->name << ", line " << r.line_number << ": " << r.text;
            EXPECT_EQ(o[4], static_cast<std::uint8_t>(r.outcome)) << k->name << ", line " << r.line_number;
        }
    }
    // What the file must exercise: sliding orbits, capped ones, long ones.
    EXPECT_GT(slid, 300);
    EXPECT_GT(capped, 100);
    EXPECT_GT(long_orbits, 200);
}

// ------------------------------------------------------------------ the kernels

// Every vectorised variant this processor runs counts frictional models as the scalar
// kernel does, bit for bit (the friction limit is a select per lane).
TEST(FrictionKernels, EveryVariantCountsAsTheScalarKernel)
{
    std::vector<CanonicalState<double>> starts;
    for (int i = 0; i < 96; ++i) {
        for (int k = 0; k < 96; ++k) starts.push_back({(i + 0.5) / 96.0, -1.0, -3.0 + (k + 0.5) * 6.0 / 96.0});
    }
    Sampler smp(0x5eed1b07);
    std::vector<Model> models{Model::uniform(0.9, 0.9), Model::uniform(0.95, 0.99)};
    models[0].wall.mu = models[0].floor.mu = 1.0;
    models[1].wall.mu = 0.3;
    models[1].inertia = thin_shell_inertia;
    for (int i = 0; i < 4; ++i) models.push_back(smp.walton_model());
    const Starts s = Starts::of(starts);
    int variants = 0;
    for (const Model& model : models) {
        const ModelMatrices m = ModelMatrices::of(model);
        std::vector<std::uint32_t> n0(starts.size()), n1(starts.size());
        std::vector<std::uint8_t> o0(starts.size()), o1(starts.size());
        scalar_kernel().count(s.view(), m, 500, n0, o0);
        for (const KernelVariant& k : simd_kernels()) {
            if (!k.runs_here()) continue;
            ++variants;
            k.count(s.view(), m, 500, n1, o1);
            std::size_t differ = 0;
            for (std::size_t p = 0; p < starts.size(); ++p) differ += n0[p] != n1[p] || o0[p] != o1[p];
            EXPECT_EQ(differ, 0u) << k.name << " " << describe(model);
        }
    }
    EXPECT_GT(variants, 0);
}

// A finite mu changes the counts of the quickstart slice, an infinite one does not.
TEST(FrictionKernels, FiniteMuChangesTheSliceInfiniteDoesNot)
{
    std::vector<CanonicalState<double>> starts;
    for (int i = 0; i < 64; ++i) {
        for (int k = 0; k < 64; ++k) starts.push_back({(i + 0.5) / 64.0, -1.0, -3.0 + (k + 0.5) * 6.0 / 64.0});
    }
    const Starts s = Starts::of(starts);
    const auto counts = [&](const Model& model) {
        std::vector<std::uint32_t> n(starts.size());
        std::vector<std::uint8_t> o(starts.size());
        best_kernel().count(s.view(), ModelMatrices::of(model), 1000, n, o);
        return n;
    };
    Model cross = Model::uniform(0.9, 0.9), infinite = cross, walton = cross;
    infinite.wall.mu = infinite.floor.mu = inf;
    walton.wall.mu = walton.floor.mu = 1.0;
    EXPECT_EQ(counts(cross), counts(infinite));
    const std::vector<std::uint32_t> a = counts(cross), b = counts(walton);
    std::size_t differ = 0;
    for (std::size_t p = 0; p < a.size(); ++p) differ += a[p] != b[p];
    EXPECT_GT(differ, a.size() / 20);
}

// ------------------------------------------------------------------ cycles

// Fixed points of the piecewise smooth map take the Jacobian of the side of each switching
// surface they lie on. At e = 0.9, alpha = 0.99, mu = 0.5 (`superball fixed-points --e 0.9
// --alpha 0.99 --mu 0.5`) the fixed point's wall impact slides (SPEC.md 1b's threshold,
// written out here), and the eigenvalues make_cycle reports (automatic differentiation) are
// those of a central-difference Jacobian of G there: every difference stays on the point's
// side of both impacts' switches.
TEST(FrictionCycles, FixedPointOfASlidingImpactHasItsSidesJacobian)
{
    Model model = Model::uniform(0.9, 0.99);
    model.wall.mu = model.floor.mu = 0.5;
    const ModelMatrices m = ModelMatrices::of(model);
    const auto point = newton_cycle({0.673, -0.514, 23.78}, m, 1);
    ASSERT_TRUE(point.has_value());
    const auto cycle = make_cycle(*point, m, 1);
    ASSERT_TRUE(cycle.has_value());
    const CanonicalState<double> s = cycle->points.front();
    EXPECT_LE(cycle->residual, 1e-12);

    // SPEC.md 1b: grips while psi <= mu (1 + e)(1 + 1/kappa) / (1 + alpha); u = U, v = 1 - 2 xi.
    const double psi = std::abs(1.0 - 2.0 * s.xi - s.W) / -s.U;
    EXPECT_GT(psi, 1.5 * 0.5 * 1.9 * 3.5 / 1.99) << "the wall impact slides, well past its switch";

    const auto sides = [&](const CanonicalState<double>& c) {
        const ImpactContacts ic = impact_contacts(c, m);
        return std::pair{std::abs(ic.s_wall) > m.wall.grip_ratio * ic.approach_wall,
                         std::abs(ic.s_floor) > m.floor.grip_ratio * ic.approach_floor};
    };
    // Central differences of G with the matrices `with` (they stay on s's side of the switches).
    const auto eigenvalues_of_differences = [&](const ModelMatrices& with) {
        Eigen::Matrix3d differences;
        for (int j = 0; j < 3; ++j) {
            const double h = 1e-6 * std::max(1.0, std::abs(as_vector(s)(j)));
            Eigen::Vector3d up = as_vector(s), down = as_vector(s);
            up(j) += h;
            down(j) -= h;
            EXPECT_EQ(sides(as_state(up)), sides(s));
            EXPECT_EQ(sides(as_state(down)), sides(s));
            differences.col(j) = (as_vector(canonical_map(as_state(up), with).next) -
                                  as_vector(canonical_map(as_state(down), with).next)) / (2.0 * h);
        }
        // core's eigenvalue routine (what the difference Jacobian is compared through is not
        // under test here; its own instantiation of Eigen's solver cost this unit 5 s).
        const auto eigenvalues = sorted_eigenvalues(differences);
        EXPECT_TRUE(eigenvalues.has_value());
        return eigenvalues.value_or(std::array<std::complex<double>, 3>{});
    };
    // The largest distance from a reported eigenvalue to the nearest of `expected`, relative.
    const auto distance = [&](const std::array<std::complex<double>, 3>& expected) {
        double worst = 0.0;
        for (const std::complex<double>& z : cycle->eigenvalues) {
            double nearest = inf;
            for (const std::complex<double>& x : expected) nearest = std::min(nearest, std::abs(x - z));
            worst = std::max(worst, nearest / std::abs(z));
        }
        return worst;
    };
    EXPECT_LE(distance(eigenvalues_of_differences(m)), 1e-5);
    // ... and not those of the gripping side's formulas (the Cross model's map at the same
    // point): the test tells the sides apart.
    EXPECT_GT(distance(eigenvalues_of_differences(ModelMatrices::of(Model::uniform(0.9, 0.99)))), 1e-2);
}

}  // namespace
}  // namespace superball::friction_testing
