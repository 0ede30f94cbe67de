// Material model of the floor-wall superball problem (SPEC.md section 1).
#pragma once

namespace superball {

// Coefficients of restitution of one surface: `e` for the normal velocity,
// `alpha` for the tangential velocity of the contact point (Cross/Garwin).
struct Surface {
    double e = 1.0;
    double alpha = 1.0;
};

struct Model {
    Surface wall;
    Surface floor;

    // The published analysis often uses one material for both surfaces.
    static constexpr Model uniform(double e, double alpha) { return {{e, alpha}, {e, alpha}}; }
};

// Physical ranges; written so that NaN is out of range.
constexpr bool e_in_range(double e) { return e > 0.0 && e <= 1.0; }
constexpr bool alpha_in_range(double alpha) { return alpha >= -1.0 && alpha <= 1.0; }
constexpr bool in_range(const Surface& s) { return e_in_range(s.e) && alpha_in_range(s.alpha); }
constexpr bool in_range(const Model& m) { return in_range(m.wall) && in_range(m.floor); }

inline constexpr const char* e_range_text = "0 < e <= 1";
inline constexpr const char* alpha_range_text = "-1 <= alpha <= 1";

}  // namespace superball
