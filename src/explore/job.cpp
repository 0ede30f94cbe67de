#include "job.hpp"

namespace superball {

std::vector<std::string> coordinate_names(Coordinates c)
{
    if (c == Coordinates::canonical) return {"xi", "U", "W"};
    return {"x", "u", "v", "omega"};
}

std::vector<const Coordinate*> Job::range_axes() const
{
    std::vector<const Coordinate*> axes;
    for (const Coordinate& c : grid) {
        if (c.is_range()) axes.push_back(&c);
    }
    return axes;
}

std::uint64_t Job::points() const
{
    std::uint64_t n = 1;
    for (const Coordinate* c : range_axes()) n *= c->range->n;
    return n;
}

}  // namespace superball
