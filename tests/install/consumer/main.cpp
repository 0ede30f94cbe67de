// Counts launches with the installed library's public API and reads a result file it is
// given:
//   consumer RESULT.h5   prints "count 8 left", the threads' count, the version and the
//                        result's grid; exits 1 if the counts disagree.
#include <superball/superball.hpp>

#include <cstdio>
#include <stdexcept>
#include <vector>

int main(int argc, char** argv)
{
    namespace api = superball::api;
    const api::Coefficients model{0.9, 0.9, {}, {}, {}, {}};
    const api::Count one = api::count(0.05, -1.0, -2.0, model, 1000);
    std::printf("count %u %s\n", one.wall_bounces, one.outcome == api::Outcome::left ? "left" : "other");
    const std::vector<double> xi(10000, 0.05), U(10000, -1.0), W(10000, -2.0);
    std::vector<std::uint32_t> counts(xi.size());
    std::vector<api::Outcome> outcomes(xi.size());
    api::count(xi, U, W, model, 1000, counts, outcomes, 2);
    std::printf("threads %u\n", counts.back());
    std::printf("%s\n", api::version().c_str());
    try {
        api::count(0.05, -1.0, -2.0, api::Coefficients{1.5, 0.9, {}, {}, {}, {}}, 1000);
        return 1;
    } catch (const std::invalid_argument& e) {
        std::printf("refused: %s\n", e.what());
    }
    if (argc > 1) {
        const api::Result result(argv[1]);
        std::uint64_t points = 1;
        for (const std::uint64_t n : result.shape()) points *= n;
        std::printf("points %llu\n", static_cast<unsigned long long>(points));
        std::vector<std::uint32_t> b(points);
        std::vector<api::Outcome> o(points);
        std::vector<std::uint64_t> start(result.shape().size(), 0);
        result.read(start, result.shape(), b, o);
        std::printf("read %u %s\n", b.front(), result.complete() ? "complete" : "partial");
    }
    return counts.back() == one.wall_bounces && one.wall_bounces == 8 ? 0 : 1;
}
