#include "query.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <iterator>
#include <cmath>

#include "core/input.hpp"
#include "job/job.hpp"
#include "job/spelling.hpp"

namespace superball::serve {

std::string either(const std::vector<std::string>& words)
{
    std::string out;
    for (std::size_t k = 0; k < words.size(); ++k) {
        out += k == 0 ? "" : k + 1 == words.size() ? " or " : ", ";
        out += words[k];
    }
    return out;
}

namespace {

// A parameter's value as it was written, quoted when it is not a plain word or number.
std::string as_written(std::string_view value)
{
    for (const char c : value) {
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+' || c == '_')) return quote(value);
    }
    return value.empty() ? "\"\"" : std::string(value);
}

}  // namespace

Query::Query(const Parameters& parameters, std::vector<std::string> accepted)
    : parameters_(parameters), accepted_(std::move(accepted))
{
    for (const auto& [key, value] : parameters_) {
        if (std::find(accepted_.begin(), accepted_.end(), key) != accepted_.end()) continue;
        const std::string spelled = "unknown parameter " + as_written(key);
        if (const auto near = suggestion(key, accepted_)) {
            refuse(spelled + " (did you mean " + *near + "?): accepted " + either(accepted_));
        }
        refuse(spelled + ": accepted " + (accepted_.empty() ? "no parameters" : either(accepted_)));
    }
}

const std::string* Query::single(std::string_view key) const
{
    if (std::find(accepted_.begin(), accepted_.end(), key) == accepted_.end()) {
        throw std::logic_error("Query: " + std::string(key) + " is read but not among the accepted keys");
    }
    const auto [first, last] = parameters_.equal_range(std::string(key));
    if (first == last) return nullptr;
    if (std::next(first) != last) {
        refuse(std::string(key) + " is given " + std::to_string(std::distance(first, last)) + " times: accepted once");
    }
    return &first->second;
}

bool Query::has(std::string_view key) { return single(key) != nullptr; }

std::optional<std::string> Query::text(std::string_view key)
{
    const std::string* value = single(key);
    if (!value) return std::nullopt;
    return *value;
}

std::optional<double> Query::number(std::string_view key)
{
    const std::string* value = single(key);
    if (!value) return std::nullopt;
    const char* begin = value->data();
    const char* end = begin + value->size();
    double x = 0;
    const auto r = std::from_chars(begin, end, x);
    if (value->empty() || r.ec != std::errc() || r.ptr != end) {
        // from_chars refuses out-of-range values such as 1e999; strtod calls them inf.
        if (r.ec == std::errc::result_out_of_range && r.ptr == end) return std::strtod(value->c_str(), nullptr);
        refuse(std::string(key) + " = " + as_written(*value) + " is not a number: accepted a decimal number such as -1.5e-3");
    }
    return x;
}

std::optional<double> Query::finite(std::string_view key)
{
    const std::optional<double> x = number(key);
    if (x && !std::isfinite(*x)) {
        refuse(std::string(key) + " = " + format_double(*x) + " is not finite: accepted a finite number");
    }
    return x;
}

std::optional<std::int64_t> Query::integer(std::string_view key, std::int64_t lo, std::int64_t hi, std::string_view accepted)
{
    const std::string* value = single(key);
    if (!value) return std::nullopt;
    const char* begin = value->data();
    const char* end = begin + value->size();
    std::int64_t n = 0;
    const auto r = std::from_chars(begin, end, n);
    if (r.ptr != end || value->empty() || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range)) {
        refuse(std::string(key) + " = " + as_written(*value) + " is not an integer: accepted " + std::string(accepted));
    }
    if (r.ec == std::errc::result_out_of_range || n < lo || n > hi) {
        refuse(std::string(key) + " = " + *value + " is out of range: accepted " + std::string(accepted));
    }
    return n;
}

std::optional<std::string> Query::choice(std::string_view key, const std::vector<std::string>& choices)
{
    std::optional<std::string> value = text(key);  // returned: not const, so it moves
    if (!value) return std::nullopt;
    for (const std::string& c : choices) {
        if (*value == c) return value;
    }
    const std::string spelled = std::string(key) + " = " + as_written(*value) + " is not accepted";
    if (const auto near = suggestion(*value, choices)) refuse(spelled + " (did you mean " + *near + "?): accepted " + either(choices));
    refuse(spelled + ": accepted " + either(choices));
}

std::vector<std::string> model_keys()
{
    std::vector<std::string> k = coefficient_names();
    k.emplace_back("max_bounces");
    return k;
}

std::vector<std::string> start_keys() { return {"xi", "U", "W", "x", "u", "v", "omega", "g", "radius"}; }

std::vector<std::string> view_keys(bool sizes)
{
    std::vector<std::string> k = {"x", "y", "xi", "U", "W", "x_min", "x_max", "y_min", "y_max"};
    if (sizes) k.insert(k.end(), {"nx", "ny"});
    return keys({k, model_keys()});
}

std::vector<std::string> keys(std::initializer_list<std::vector<std::string>> lists)
{
    std::vector<std::string> out;
    for (const auto& l : lists) out.insert(out.end(), l.begin(), l.end());
    return out;
}

}  // namespace superball::serve
