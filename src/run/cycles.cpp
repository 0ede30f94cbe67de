#include "cycles.hpp"

#include <algorithm>
#include <string>

namespace superball {

namespace {

// Newton's method converged from start `start` for G^`k` at `point`.
struct Hit {
    std::uint64_t start;
    int k;
    Domain domain;
    CanonicalState<double> point;
};

constexpr std::size_t hit_doubles = 6;

// This rank's share of the starts: every rank draws the whole sequence (cheap next to
// Newton's method) and keeps the indices i = rank mod size, so the starts, and the order
// in which rank 0 examines what they found, are those of a serial run.
std::vector<double> search_share(const ModelMatrices& m, const CycleSearch& opt, int rank, int size)
{
    std::vector<double> hits;
    SeededStarts draw(opt.seed);
    for (std::int64_t i = 0; i < opt.starts; ++i) {
        const CanonicalState<double> start = draw.next();
        if (i % size != rank) continue;
        for (int k = 1; k <= opt.max_period; ++k) {
            for (const Domain domain : {Domain::interior, Domain::corner}) {
                if (domain == Domain::corner && !opt.corner) continue;
                if (const auto p = newton_cycle(start, m, k, domain)) {
                    hits.insert(hits.end(), {static_cast<double>(i), static_cast<double>(k),
                                             static_cast<double>(domain), p->xi, p->U, p->W});
                }
            }
        }
    }
    return hits;
}

std::vector<Hit> unpack(const std::vector<double>& data)
{
    std::vector<Hit> hits;
    for (std::size_t i = 0; i + hit_doubles <= data.size(); i += hit_doubles) {
        hits.push_back({static_cast<std::uint64_t>(data[i]), static_cast<int>(data[i + 1]),
                        static_cast<Domain>(static_cast<int>(data[i + 2])), {data[i + 3], data[i + 4], data[i + 5]}});
    }
    // Serial order: by start, then period, then domain. distinct_cycles keeps the first of
    // repeated cycles, so the output does not depend on the number of ranks.
    std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
        if (a.start != b.start) return a.start < b.start;
        if (a.k != b.k) return a.k < b.k;
        return a.domain < b.domain;
    });
    return hits;
}

// The distinct cycles of every rank's hits.
std::vector<Cycle> cycles_of(const ModelMatrices& m, const std::vector<double>& all)
{
    std::vector<Cycle> found;
    for (const Hit& h : unpack(all)) {
        if (auto c = make_cycle(h.point, m, h.k, h.domain)) found.push_back(std::move(*c));
    }
    return distinct_cycles(found);
}

}  // namespace

void check_cycle_search(const CycleSearch& search, const KeySpelling& spell)
{
    if (search.max_period < 1 || search.max_period > max_cycle_period) {
        throw InputError(spell("period") + " = " + std::to_string(search.max_period) + " is out of range: accepted 1.." +
                         std::to_string(max_cycle_period));
    }
    if (search.starts < 1) {
        throw InputError(spell("starts") + " = " + std::to_string(search.starts) + " is out of range: accepted " +
                         spell("starts") + " >= 1");
    }
}

std::vector<Cycle> find_cycles(const Model& model, const CycleSearch& search, const mpi::Comm& comm)
{
    const ModelMatrices m = ModelMatrices::of(model);
    const std::vector<double> all = comm.gather(search_share(m, search, comm.rank(), comm.size()));
    if (!comm.is_root()) return {};
    return cycles_of(m, all);
}

std::vector<Cycle> find_cycles(const Model& model, const CycleSearch& search)
{
    const ModelMatrices m = ModelMatrices::of(model);
    return cycles_of(m, search_share(m, search, 0, 1));
}

}  // namespace superball
