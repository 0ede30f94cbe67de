#include "threads.hpp"

#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace superball {

void run_on_threads(unsigned n, const std::function<void(unsigned)>& body)
{
    std::mutex m;
    std::exception_ptr first;
    const auto guarded = [&](unsigned i) {
        try {
            body(i);
        } catch (...) {
            const std::lock_guard lock(m);
            if (!first) first = std::current_exception();
        }
    };
    {
        std::vector<std::jthread> others;
        others.reserve(n > 0 ? n - 1 : 0);
        for (unsigned i = 1; i < n; ++i) others.emplace_back(guarded, i);
        if (n > 0) guarded(0);
    }  // joined
    if (first) std::rethrow_exception(first);
}

}  // namespace superball
