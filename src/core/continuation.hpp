// Continuation of cycles of the canonical map G in one coefficient of the model: how the
// self-similar motions of dynamics.hpp are born, change stability and die as the ball's
// material changes (a bifurcation diagram).
//
// The branch is the solution curve of  H(x, p) = G^k(x; p) - x = 0  in the four unknowns
// y = (xi, U, W, p), followed by pseudo-arclength continuation: from a point y with unit
// tangent t (the null vector of the 3 x 4 Jacobian [H_x  H_p]), the predictor y + h t is
// corrected by Newton's method on H = 0 together with t . (y' - y) = h. The arclength h
// takes the branch around folds, where p turns back and natural-parameter continuation
// (step p, solve for x) stops. Plain coordinates (not log xi as in newton_cycle): where the
// wall sends the ball down, G extends analytically through the plane xi = 0 and maps it
// into itself (boundary_planes.md), so a branch that reaches that plane crosses the branch
// of corner cycles transversally, and the crossing is a zero of the coordinate xi along
// the branch, located like every other event.
//
// Derivatives: forward-mode automatic differentiation of the same canonical_map template
// the counting kernels run, with the coefficient as a fourth independent variable (the
// impact matrices are computed from it in the AutoDiff type, BasicImpactMatrix<Dual>).
//
// Events are zeros of test functions along the branch, detected as a change of sign
// between consecutive points and located by a bracketing (Illinois) solve on the arclength
// to 1e-10 in it, hence in p (|dp/ds| <= 1):
//   fold             the tangent's p component (p turns back; an eigenvalue of D(G^k) is 1)
//   branch_point     det [H_x H_p; t^T] (the Jacobian loses rank: another branch crosses;
//                    an eigenvalue 1 without a fold). On the corner plane also kappa - 1:
//                    the transverse multiplier through 1, where a branch of interior cycles
//                    meets the corner branch.
//   period_doubling  det(D(G^k) + I) (a real eigenvalue through -1)
//   neimark_sacker   det(D(G^k) (.) D(G^k) - I), the bialternate product whose eigenvalues
//                    are mu_i mu_j - 1: reported when a complex pair is on the unit circle
//                    there (a real pair with mu_i mu_j = 1, a neutral saddle, is no event)
//   grip_slide       psi* - psi of the wall or floor impact of some point of the cycle
//                    (SPEC.md 1b: psi = |contact velocity| / approach speed, psi* the
//                    largest that grips): the impact passes from gripping to sliding
//   boundary         xi, 1 - xi or -U of some point of the cycle through 0: the branch
//                    leaves the region where G is the motion; it stops there
//   end              the parameter bound (the last point is solved at p = bound exactly),
//                    or the continuation cannot go on (see BranchPoint::note)
// The determinant tests are divided by Hadamard's bound (product of the rows' norms), so
// they lie in [-1, 1]; a sign change counts only between values beyond 1e-9 in size. This
// keeps rounding noise from making events where a test function vanishes identically:
// for the elastic ball (e = alpha = 1) the fixed points form a family along which the
// eigenvalue 1 and the pair mu, 1/mu persist (dynamics.hpp), so the fold and
// Neimark-Sacker tests are zero up to rounding all the way.
#pragma once

#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dynamics.hpp"
#include "model.hpp"

namespace superball {

// The coefficient continued in: e, alpha and mu set both surfaces (which must then agree);
// mu and inertia are SPEC.md 1b's.
enum class Parameter : std::uint8_t { e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall, mu_floor, inertia };

inline constexpr std::array<Parameter, 10> all_parameters{
    Parameter::e,           Parameter::alpha, Parameter::e_wall,  Parameter::alpha_wall, Parameter::e_floor,
    Parameter::alpha_floor, Parameter::mu,    Parameter::mu_wall, Parameter::mu_floor,   Parameter::inertia};

std::string_view name(Parameter p);
std::optional<Parameter> parameter_named(std::string_view name);

// The parameter's value in the model (e and alpha: the wall's).
double parameter_value(const Model& m, Parameter p);
// The model with the parameter set (e and alpha: on both surfaces).
Model with_parameter(Model m, Parameter p, double value);
// The model gives the parameter one value (e, alpha: the two surfaces agree).
bool parameter_defined(const Model& m, Parameter p);
// Physical range of the parameter (model.hpp).
bool parameter_in_range(Parameter p, double value);
const char* parameter_range_text(Parameter p);

// The direction that changes no coefficient (not Model{}: a Model's defaults are a ball's,
// mu infinite and inertia 2/5).
inline constexpr Model no_change{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0.0};

// A line in the space of the coefficients: coefficients(s) = origin + s direction.
// Continuation in one coefficient follows the line along it (s is its value); an event
// curve in two coefficients is found on lines across it (continue_event).
struct ParameterPath {
    Model origin;
    Model direction;   // per coefficient, its rate of change with s
    std::string name;  // what s is, for the notes of events ("alpha", "s")

    Model at(double s) const;
    // s = the value of p, the other coefficients those of `model`.
    static ParameterPath along(const Model& model, Parameter p);
};

// G^k at s with its derivatives in (xi, U, W) and in the parameter, by automatic
// differentiation. No domain check: G is evaluated wherever its formula is finite,
// including its analytic extension a little beyond the planes xi = 0 and xi = 1.
struct ParameterJacobian {
    std::vector<CanonicalState<double>> orbit;  // s, G(s), ..., G^(k-1)(s)
    CanonicalState<double> image{};             // G^k(s)
    double lambda = 1.0;                        // product of the k multipliers
    Eigen::Matrix3d dG = Eigen::Matrix3d::Zero();    // d G^k / d(xi, U, W)
    Eigen::Vector3d dG_dp = Eigen::Vector3d::Zero();  // d G^k / dp
    bool finite = false;                        // every number above is finite
};

ParameterJacobian parameter_jacobian(const CanonicalState<double>& s, const Model& model, Parameter p, int k);
// The same with the derivative along a path of coefficients, at path.at(value).
ParameterJacobian parameter_jacobian(const CanonicalState<double>& s, const ParameterPath& path, double value, int k);

// grip_slide (SPEC.md 1b): an impact of the cycle passes from gripping to sliding, where
// G^k is continuous but its Jacobian jumps (a border-collision bifurcation).
enum class BranchEvent : std::uint8_t { none, fold, period_doubling, neimark_sacker, branch_point, boundary, end, grip_slide };

std::string_view name(BranchEvent e);

// One point of a branch.
struct BranchPoint {
    double parameter = 0.0;
    CanonicalState<double> point{};  // the point of the cycle followed along the branch
    // As in fixed-points (Cycle): the cycle's point with the smallest xi, the product of the
    // multipliers over the cycle, the eigenvalues of D(G^k) there and the stability class.
    CanonicalState<double> representative{};
    double lambda = 0.0;
    std::array<std::complex<double>, 3> eigenvalues{};
    Stability stability = Stability::marginal;
    double residual = 0.0;   // max |G^k(point) - point| over the three coordinates
    double arclength = 0.0;  // signed, from the start, in (xi, U, W, p)
    BranchEvent event = BranchEvent::none;
    // Events: width of the final bracket of the location in arclength, which bounds the
    // error of `parameter` (|dp/ds| <= 1); 0 where the point is solved at p = bound.
    double bracket = 0.0;
    // Events: what happened ("xi -> 0", "alpha = max", "step size below 1e-08", ...).
    std::string note;
};

struct ContinuationSettings {
    // Bounds of the parameter. A branch that runs along a bound (the elastic family at
    // alpha = 1) may step beyond it by rounding: the bound counts as crossed 1e-12 beyond.
    double min = 0.0;
    double max = 1.0;
    double initial_step = 0.01;  // arclength steps in (xi, U, W, p)
    double min_step = 1e-7;
    double max_step = 0.05;
    int max_points = 2000;  // per direction
};

// A branch through a cycle, from one end to the other: points[start] is the start.
struct Branch {
    int period = 1;
    Domain domain = Domain::interior;
    std::vector<BranchPoint> points;
    std::size_t start = 0;
};

// Follows the branch of `start` (a cycle of `model`, e.g. from make_cycle; its parameter
// value inside [min, max]) in both directions until an end event. The corner plane's
// cycles (start.corner) are followed on the plane. nullopt if the start is not a regular
// point of the branch equations (the corrector cannot refine it).
std::optional<Branch> continue_cycle(const Cycle& start, const Model& model, Parameter parameter,
                                     const ContinuationSettings& settings);
// The same along a path of coefficients, from s = s0 (start: a cycle of path.at(s0)); the
// settings' bounds apply to s.
std::optional<Branch> continue_cycle(const Cycle& start, const ParameterPath& path, double s0,
                                     const ContinuationSettings& settings);

}  // namespace superball
