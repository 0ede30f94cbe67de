// Two-parameter continuation of an event: the curve of fold, period-doubling,
// Neimark-Sacker or branch points of a branch of cycles in the plane of two coefficients
// (what AUTO users do after a one-parameter diagram).
//
// Method (secant predictor, corrector on a transversal line; first derivatives only): from
// the last two curve points E_{j-1}, E_j in the plane, the predictor is Q = E_j + h d (d the
// unit secant, the state extrapolated alike); the corrector continues the cycle through Q
// along the line Q + s n, n perpendicular to d (continue_cycle on that ParameterPath, for
// |s| <= 2h) and takes the event of the same kind nearest to s = 0, located there by the
// bracketing solve of continuation.hpp to 1e-10 in s. So every curve point is an event of
// a one-parameter branch, located as precisely as in `continue`, and the curve is followed
// through turns in either coefficient. The first step is taken along the second
// coefficient (lines along the first). Step control: the step h grows when the event falls
// near the prediction (|s| < h/4), halves when no event is found, and the curve ends when
// h falls below min_step (the event is gone: the branch ended, or the event changed kind,
// e.g. a Neimark-Sacker pair became real at a 1:1 resonance) or the next step leaves the
// box of the two coefficients' bounds.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "continuation.hpp"

namespace superball {

struct EventCurvePoint {
    double first = 0.0;   // the two coefficients
    double second = 0.0;
    BranchPoint point;    // the cycle and its eigenvalues there (point.parameter is `first`)
};

struct EventCurve {
    BranchEvent event = BranchEvent::none;
    int period = 1;
    Domain domain = Domain::interior;
    std::vector<EventCurvePoint> points;  // from one end to the other
    std::size_t start = 0;                // the event the curve started from
    std::string first_end, last_end;      // why each end stopped
};

struct EventCurveSettings {
    double min1 = 0.0, max1 = 1.0;  // bounds of the first and second coefficients
    double min2 = 0.0, max2 = 1.0;
    double initial_step = 0.005;    // steps in the plane of the two coefficients
    double min_step = 1e-5;
    double max_step = 0.02;
    int max_points = 400;  // per direction
};

// Follows the event branch.points[index] (fold, period_doubling, neimark_sacker or
// branch_point) of a branch continued in `first` from `model` as a curve in the plane
// (first, second). nullopt if that point is no such event or the first step finds none.
std::optional<EventCurve> continue_event(const Branch& branch, std::size_t index, const Model& model, Parameter first,
                                         Parameter second, const EventCurveSettings& settings);

// Whether two coefficients can span a plane: different, and not one the other's surface
// (e and e_wall both move the wall's e).
bool independent(Parameter a, Parameter b);

}  // namespace superball
