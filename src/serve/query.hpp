// The parameters of an API request, and the errors the server answers with.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace superball::serve {

// A request the server refuses: the HTTP status (400 bad input, 404 no such path, 413 too
// large, 503 over the time limit or too busy) and a message that names the parameter and
// what is accepted. Answered as {"error": message}.
struct RequestError : std::runtime_error {
    RequestError(int status, const std::string& message) : std::runtime_error(message), status(status) {}
    int status;
};

// A request the API refuses as bad (HTTP 400), saying why.
[[noreturn]] inline void refuse(const std::string& message) { throw RequestError(400, message); }

// The query string, as decoded by the HTTP library (a key may come more than once).
using Parameters = std::multimap<std::string, std::string>;

// The parameters of a request, read by type. Messages spell the keys as the API does
// ("e_wall"), with the command line's and the job file's wording.
class Query {
public:
    // Throws RequestError(400) naming the first parameter not among `accepted`, with a
    // did-you-mean, before anything else is looked at.
    Query(const Parameters& parameters, std::vector<std::string> accepted);

    bool has(std::string_view key);
    std::optional<std::string> text(std::string_view key);
    // Any double, NaN and infinities included: the caller decides what is in range, with
    // the same checks as the command line.
    std::optional<double> number(std::string_view key);
    // A finite double ("x_min = inf is not finite: accepted a finite number").
    std::optional<double> finite(std::string_view key);
    // An integer in [lo, hi]; `accepted` spells the range for messages ("nx >= 1").
    std::optional<std::int64_t> integer(std::string_view key, std::int64_t lo, std::int64_t hi, std::string_view accepted);
    // A value among `choices`.
    std::optional<std::string> choice(std::string_view key, const std::vector<std::string>& choices);

private:
    const std::string* single(std::string_view key) const;

    const Parameters& parameters_;
    const std::vector<std::string> accepted_;
};

// Keys of the model (e, alpha, e_wall, ...) and max_bounces; of a start point (xi, U, W,
// x, u, v, omega, g, radius); of a view (x, y, the coordinates, x_min, ...; nx, ny when
// `sizes`), model included.
std::vector<std::string> model_keys();
std::vector<std::string> start_keys();
std::vector<std::string> view_keys(bool sizes);
// The keys of all the lists.
std::vector<std::string> keys(std::initializer_list<std::vector<std::string>> lists);

// The joined list "a, b or c".
std::string either(const std::vector<std::string>& words);

}  // namespace superball::serve
