#include "job.hpp"

namespace superball {

std::vector<std::string> coordinate_names(Coordinates c)
{
    if (c == Coordinates::canonical) return {"xi", "U", "W"};
    return {"x", "u", "v", "omega"};
}

std::vector<std::string> coefficient_names()
{
    std::vector<std::string> names;
    for (const ModelKey& key : model_input_keys) names.emplace_back(key.name);
    return names;
}

std::vector<std::string> model_coefficient_names()
{
    return {"e_wall", "alpha_wall", "e_floor", "alpha_floor", "mu_wall", "mu_floor", "inertia"};
}

bool is_friction_coefficient(std::string_view name) { return name.starts_with("mu") || name == "inertia"; }


std::vector<const Coordinate*> Job::range_axes() const
{
    std::vector<const Coordinate*> axes;
    for (const Coordinate& c : parameters) axes.push_back(&c);
    for (const Coordinate& c : grid) {
        if (c.is_range()) axes.push_back(&c);
    }
    return axes;
}

Model Job::model_at(std::span<const double> parameter_values) const
{
    Model m = model;
    // In the order of model_coefficient_names().
    double* const coefficient[swept_coefficients] = {&m.wall.e,  &m.wall.alpha, &m.floor.e, &m.floor.alpha,
                                                     &m.wall.mu, &m.floor.mu,   &m.inertia};
    for (std::size_t k = 0; k < swept_coefficients; ++k) {
        if (swept[k] >= 0) *coefficient[k] = parameter_values[static_cast<std::size_t>(swept[k])];
    }
    return m;
}

std::uint64_t Job::points() const
{
    std::uint64_t n = 1;
    for (const Coordinate* c : range_axes()) n *= c->range->n;
    return n;
}

}  // namespace superball
