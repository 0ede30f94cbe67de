// Material model of the floor-wall superball problem (SPEC.md sections 1 and 1b).
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <string_view>

namespace superball {

// Coefficients of one surface: `e` for the normal velocity, `alpha` for the tangential
// velocity of the contact point in an impact that grips (Cross/Garwin; Walton's beta0),
// and the Coulomb friction coefficient `mu` that caps the tangential impulse at mu times
// the normal one (Walton's law, SPEC.md 1b). An infinite mu never caps it: the Cross model.
struct Surface {
    double e = 1.0;
    double alpha = 1.0;
    double mu = std::numeric_limits<double>::infinity();
};

// The ball's moment of inertia I = kappa m a^2 (SPEC.md 1b, job key `inertia`): 2/5 a solid
// homogeneous ball (the superball), 2/3 a thin spherical shell.
inline constexpr double solid_ball_inertia = 0.4;
inline constexpr double thin_shell_inertia = 2.0 / 3.0;

struct Model {
    Surface wall;
    Surface floor;
    double inertia = solid_ball_inertia;

    // The published analysis often uses one material for both surfaces.
    static constexpr Model uniform(double e, double alpha) { return {{e, alpha}, {e, alpha}}; }

    // Some impact may slide (a finite mu): the counting kernels then take the friction
    // limit of every impact; otherwise every impact grips, as in the Cross model.
    constexpr bool frictional() const
    {
        constexpr double inf = std::numeric_limits<double>::infinity();
        return wall.mu < inf || floor.mu < inf;
    }
};

// Physical ranges; written so that NaN is out of range.
constexpr bool e_in_range(double e) { return e > 0.0 && e <= 1.0; }
constexpr bool alpha_in_range(double alpha) { return alpha >= -1.0 && alpha <= 1.0; }
constexpr bool mu_in_range(double mu) { return mu >= 0.0; }  // infinity included
constexpr bool inertia_in_range(double kappa) { return kappa > 0.0 && kappa <= thin_shell_inertia; }
constexpr bool in_range(const Surface& s) { return e_in_range(s.e) && alpha_in_range(s.alpha) && mu_in_range(s.mu); }
constexpr bool in_range(const Model& m) { return in_range(m.wall) && in_range(m.floor) && inertia_in_range(m.inertia); }

inline constexpr const char* e_range_text = "0 < e <= 1";
inline constexpr const char* alpha_range_text = "-1 <= alpha <= 1";
inline constexpr const char* mu_range_text = "0 <= mu <= inf (inf: no friction limit, the Cross model)";
// 2/3 as the double it is compared with: 0.6666666666666666 is accepted, 0.6667 is not.
inline constexpr const char* inertia_range_text = "0 < inertia <= 2/3 (0.6666666666666666, a thin shell)";

// A coefficient's physical range by its name (e, e_wall, alpha, alpha_floor, mu, mu_wall,
// inertia, ...), for the checks and messages of every layer that names coefficients (job
// files, results, continuation parameters).
constexpr bool coefficient_in_range(std::string_view name, double value)
{
    if (name.starts_with("alpha")) return alpha_in_range(value);
    if (name.starts_with("mu")) return mu_in_range(value);
    if (name == "inertia") return inertia_in_range(value);
    return e_in_range(value);
}

constexpr const char* coefficient_range_text(std::string_view name)
{
    if (name.starts_with("alpha")) return alpha_range_text;
    if (name.starts_with("mu")) return mu_range_text;
    if (name == "inertia") return inertia_range_text;
    return e_range_text;
}

// Every coefficient of a model, one value each, in the order of job/job.hpp's
// model_coefficient_names(): e_wall, alpha_wall, e_floor, alpha_floor, mu_wall, mu_floor,
// inertia.
inline constexpr std::size_t model_coefficient_count = 7;
constexpr std::array<double, model_coefficient_count> model_coefficients(const Model& m)
{
    return {m.wall.e, m.wall.alpha, m.floor.e, m.floor.alpha, m.wall.mu, m.floor.mu, m.inertia};
}

}  // namespace superball
