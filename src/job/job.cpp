#include "job.hpp"

namespace superball {

std::vector<std::string> coordinate_names(Coordinates c)
{
    if (c == Coordinates::canonical) return {"xi", "U", "W"};
    return {"x", "u", "v", "omega"};
}

std::vector<std::string> coefficient_names() { return {"e", "alpha", "e_wall", "alpha_wall", "e_floor", "alpha_floor"}; }

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
    double* const coefficient[4] = {&m.wall.e, &m.wall.alpha, &m.floor.e, &m.floor.alpha};
    for (std::size_t k = 0; k < 4; ++k) {
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
