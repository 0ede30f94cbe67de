// Models and states shared by the tests of the dynamics of G (test_dynamics.cpp,
// test_continuation.cpp). Header only.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/map.hpp"
#include "core/model.hpp"

namespace superball::test {

// Models with all kinds of coefficients, the two surfaces differing. The last one is only
// used for G: its launches rarely survive two excursions.
inline std::vector<Model> models(int k = 1)
{
    std::vector<Model> all{Model::uniform(1.0, 1.0),         Model::uniform(0.9, 0.9),
                           Model{{0.8, 0.6}, {0.95, 0.3}},   Model{{0.95, 0.8}, {0.85, 0.5}},
                           Model{{0.6, 0.99}, {1.0, -0.2}},  Model{{0.7, -0.5}, {0.9, 1.0}}};
    if (k > 1) all.pop_back();
    return all;
}

// Random states at which G (or G^k) is the motion and not close to its singular sets,
// where finite differences would need tiny steps: the rebound off the wall p ~ 0, the
// floor bounce u' ~ 0 (U' changes sign), xi' ~ 1.
inline std::vector<CanonicalState<double>> admissible_states(const ModelMatrices& m, int k, int count, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<CanonicalState<double>> out;
    for (int attempt = 0; attempt < 1000000 && static_cast<int>(out.size()) < count; ++attempt) {
        const CanonicalState<double> s{0.02 + 0.96 * unit(rng), -std::pow(10.0, -1.0 + 2.0 * unit(rng)),
                                       4.0 * (2.0 * unit(rng) - 1.0)};
        bool ok = true;
        CanonicalState<double> c = s;
        for (int i = 0; i < k && ok; ++i) {
            const double p = m.wall.c_sW * c.W + m.wall.c_ss * (1.0 - 2.0 * c.xi);
            const CanonicalStep<double> g = canonical_map(c, m);
            ok = std::abs(p) > 0.05 && g.next.U < -0.05 && g.next.xi > 0.02 && g.next.xi < 0.98 && std::abs(g.next.W) < 50;
            c = g.next;
        }
        if (ok) out.push_back(s);
    }
    EXPECT_EQ(static_cast<int>(out.size()), count) << "too few admissible states for k = " << k;
    return out;
}

}  // namespace superball::test
