#include "count.hpp"

#include <cmath>

namespace superball {

std::optional<Outcome> outcome_from_name(std::string_view s)
{
    for (int i = 0; i < outcome_count; ++i) {
        const auto o = static_cast<Outcome>(i);
        if (name(o) == s) return o;
    }
    return std::nullopt;
}

namespace {

// The loop of SPEC.md section 3 from state c after n wall impacts.
template <ImpactLaw law>
BounceCount iterate(CanonicalState<double> c, std::uint32_t n, const ModelMatrices& m, std::uint32_t max_bounces)
{
    for (;;) {
        // xi is never NaN here: a step that could make it so is refused below.
        if (!(c.xi < 1.0)) return {n, Outcome::missed};
        // Capped means the ball would hit the wall once more: a ball whose next
        // excursion misses is reported as missed even at the cap.
        if (n >= max_bounces) return {n, Outcome::capped};
        const CanonicalStep<double> step = canonical_map<law>(c, m);
        // Overflow or division by zero (map.hpp, representable): no answer, not a miss.
        if (!representable(step)) return {0, Outcome::invalid};
        c = step.next;
        ++n;
        if (c.U >= 0.0) return {n, Outcome::left};
    }
}

// Without friction every impact grips: the Cross model's arithmetic alone (the same bits as
// Walton's law with infinite mu, without computing the friction limit).
BounceCount iterate(const CanonicalState<double>& c, std::uint32_t n, const ModelMatrices& m, std::uint32_t max_bounces)
{
    if (m.frictional) return iterate<ImpactLaw::walton>(c, n, m, max_bounces);
    return iterate<ImpactLaw::cross>(c, n, m, max_bounces);
}

}  // namespace

BounceCount count(const CanonicalState<double>& start, const ModelMatrices& m, std::uint32_t max_bounces)
{
    if (!is_launch(start)) return {0, Outcome::invalid};
    return iterate(start, 0, m, max_bounces);
}

BounceCount count_on_plane(const CanonicalState<double>& start, const ModelMatrices& m, std::uint32_t max_bounces)
{
    const bool plane = start.xi == 0.0 || start.xi == 1.0;
    if (!plane || !std::isfinite(start.U) || !std::isfinite(start.W) || !(start.U < 0.0)) return {0, Outcome::invalid};
    if (max_bounces == 0) return {0, Outcome::capped};
    // G evaluated on the plane is its limit from inside (core/boundary_planes.md): the
    // first excursion is taken even at xi = 1, where count() would report a miss.
    const CanonicalStep<double> step = canonical_map(start, m);
    if (!representable(step)) return {0, Outcome::invalid};
    const CanonicalState<double> c = step.next;
    if (c.U >= 0.0) return {1, Outcome::left};
    return iterate(c, 1, m, max_bounces);
}

namespace {

// Writes `one(start)` of every start into the two output arrays.
template <class Count>
void count_into(const StartsView& starts, Count one, std::span<std::uint32_t> wall_bounces,
                std::span<std::uint8_t> outcomes)
{
    for (std::size_t i = 0; i < starts.size(); ++i) {
        const BounceCount r = one(starts[i]);
        wall_bounces[i] = r.wall_bounces;
        outcomes[i] = static_cast<std::uint8_t>(r.outcome);
    }
}

}  // namespace

void count_each_on_plane(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                         std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    count_into(starts, [&](const CanonicalState<double>& s) { return count_on_plane(s, m, max_bounces); }, wall_bounces,
               outcomes);
}

void count_each(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    count_into(starts, [&](const CanonicalState<double>& s) { return count(s, m, max_bounces); }, wall_bounces, outcomes);
}

BounceCount count(const PhysicalState<double>& start, const Model& m, double g, std::uint32_t max_bounces)
{
    if (!is_launch(start) || !(g > 0.0)) return {0, Outcome::invalid};
    return count(to_canonical(start, g), m, max_bounces);
}

}  // namespace superball
