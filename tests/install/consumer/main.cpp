// Counts launches with the installed library and reads a result file it is given:
//   consumer RESULT.h5   prints "count 8 left", the version and the result's grid.
#include <cstdio>

#include "core/count.hpp"
#include "core/kernels.hpp"
#include "io/result_reader.hpp"
#include "job/provenance.hpp"
#include "run/count_threads.hpp"

int main(int argc, char** argv)
{
    using namespace superball;
    const BounceCount one = count(CanonicalState<double>{0.05, -1.0, -2.0}, Model::uniform(0.9, 0.9), 1000);
    std::printf("count %u %s\n", one.wall_bounces, std::string(name(one.outcome)).c_str());
    Starts starts;
    for (int i = 0; i < 10000; ++i) starts.push_back({0.05, -1.0, -2.0});
    std::vector<std::uint32_t> counts(starts.size());
    std::vector<std::uint8_t> outcomes(starts.size());
    count_on_threads([&](std::size_t first, std::size_t n, Starts&) { return starts.view().subview(first, n); },
                     ModelMatrices::of(Model::uniform(0.9, 0.9)), 1000, counts, outcomes, {best_kernel().count, 2});
    std::printf("threads %u\n", counts.back());
    std::printf("%s\n", software_source().c_str());
    if (argc > 1) {
        const ResultReader reader(argv[1]);
        std::printf("points %llu\n", static_cast<unsigned long long>(reader.info().points()));
    }
    return counts.back() == 8 ? 0 : 1;
}
