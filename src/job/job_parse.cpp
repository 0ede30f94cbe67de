// Job files (SPEC.md section 4): TOML text -> a validated Job, and the job's fingerprint.
//
// Validation functions below throw InputError with messages that do not name the source;
// parse_job adds it once, so every message starts with the file name.
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "job.hpp"
#include "spelling.hpp"

namespace superball {
namespace {

constexpr std::int64_t max_tile_points = std::int64_t{1} << 24;

const std::vector<std::string> top_level_keys = {"model", "grid", "run"};
const std::vector<std::string> model_keys = [] {
    std::vector<std::string> keys = coefficient_names();
    keys.insert(keys.end(), {"g", "radius"});
    return keys;
}();
const std::vector<std::string> range_keys = {"min", "max", "n"};
const std::vector<std::string> run_keys = {"max_bounces", "output",      "tile_points", "refine",
                                           "compression", "alignment", "checkpoint_seconds", "writers"};

[[noreturn]] void fail(const std::string& message) { throw InputError(message); }

const std::string writers_accepted = "\"auto\" or a count of writers from 1 to " + std::to_string(max_writers);

std::vector<std::string> grid_keys(Coordinates c)
{
    std::vector<std::string> keys = coordinate_names(c);
    keys.insert(keys.begin(), "coordinates");
    return keys;
}

bool contains(const std::vector<std::string>& names, std::string_view s)
{
    return std::find(names.begin(), names.end(), s) != names.end();
}

std::string join(const std::vector<std::string>& names, std::string_view separator = ", ")
{
    std::string out;
    for (const std::string& n : names) {
        if (!out.empty()) out += separator;
        out += n;
    }
    return out;
}

// --- Describing values as the user wrote them ------------------------------------------

std::string type_name(const toml::node& n)
{
    switch (n.type()) {
        case toml::node_type::string: return "a string";
        case toml::node_type::integer: return "an integer";
        case toml::node_type::floating_point: return "a floating-point number";
        case toml::node_type::boolean: return "a boolean";
        case toml::node_type::date: return "a date";
        case toml::node_type::time: return "a time";
        case toml::node_type::date_time: return "a date-time";
        case toml::node_type::array: return "an array";
        case toml::node_type::table: return "a table";
        case toml::node_type::none: break;
    }
    return "nothing";
}

// TOML tells floats from integers by the spelling: keep "2.0" from reading as "2", since
// the message may be complaining that it is not an integer.
std::string float_text(double x)
{
    std::string text = format_double(x);
    if (text.find_first_not_of("-0123456789") == std::string::npos) text += ".0";
    return text;
}

std::string as_written(const toml::node& n)
{
    if (const auto* s = n.as_string()) return quote(s->get());
    if (const auto* i = n.as_integer()) return std::to_string(i->get());
    if (const auto* f = n.as_floating_point()) return float_text(f->get());
    if (const auto* b = n.as_boolean()) return b->get() ? "true" : "false";
    if (n.is_array()) return "[...]";
    if (n.is_table()) return "{...}";
    std::ostringstream os;
    if (const auto* d = n.as_date()) os << d->get();
    if (const auto* t = n.as_time()) os << t->get();
    if (const auto* dt = n.as_date_time()) os << dt->get();
    return os.str();
}

[[noreturn]] void wrong_type(std::string_view key, const toml::node& n, std::string_view expected)
{
    fail(std::string(key) + " = " + as_written(n) + " is " + type_name(n) + ": expected " + std::string(expected));
}

// --- Unknown keys ------------------------------------------------------------------------

std::string unknown_key_message(std::string_view spelled, std::string_view key, const std::vector<std::string>& known,
                                std::string_view (*spell_known)(std::string_view) = nullptr)
{
    const auto spell = [&](const std::string& k) { return spell_known ? std::string(spell_known(k)) : k; };
    if (const auto near = suggestion(key, known)) {
        return std::string(spelled) + " (did you mean " + spell(*near) + "?)";
    }
    std::vector<std::string> accepted;
    std::transform(known.begin(), known.end(), std::back_inserter(accepted), spell);
    return std::string(spelled) + " (accepted: " + join(accepted) + ")";
}

// The unknown key that comes first in the file (tables iterate in key order).
std::optional<std::string> first_unknown_key(const toml::table& table, const std::vector<std::string>& known)
{
    std::optional<std::string> first;
    toml::source_position first_at{};
    for (const auto& [key, node] : table) {
        if (contains(known, key.str())) continue;
        const toml::source_position at = key.source().begin;
        if (!first || at < first_at) {
            first = std::string(key.str());
            first_at = at;
        }
    }
    return first;
}

// `prefix` spells the table for messages: "[grid] " or "[grid] xi.".
void reject_unknown_keys(const toml::table& table, std::string_view prefix, const std::vector<std::string>& known)
{
    if (const auto key = first_unknown_key(table, known)) {
        fail("unknown key " + unknown_key_message(std::string(prefix) + *key, *key, known));
    }
}

std::string_view table_spelling(std::string_view key)
{
    if (key == "model") return "[model]";
    if (key == "grid") return "[grid]";
    return "[run]";
}

// A top-level key that belongs to a table is a common slip (a key above the first header).
std::optional<std::string> owning_table(std::string_view key)
{
    if (contains(model_keys, key)) return "[model]";
    if (contains(run_keys, key)) return "[run]";
    if (contains(grid_keys(Coordinates::canonical), key) || contains(grid_keys(Coordinates::physical), key)) return "[grid]";
    return std::nullopt;
}

void reject_unknown_top_level(const toml::table& root)
{
    const auto key = first_unknown_key(root, top_level_keys);
    if (!key) return;
    const toml::node& node = *root.get(*key);
    if (node.is_table()) {
        fail("unknown table " +
             unknown_key_message("[" + *key + "]", *key, top_level_keys, [](std::string_view k) { return table_spelling(k); }));
    }
    if (const auto owner = owning_table(*key)) fail("key " + *key + " is outside any table: it belongs in " + *owner);
    fail("unknown key " + *key + " outside any table (accepted: the tables [model], [grid] and [run])");
}

// --- Typed values ------------------------------------------------------------------------

double number(const toml::node& n, std::string_view key)
{
    if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
    if (const auto* f = n.as_floating_point()) return f->get();
    wrong_type(key, n, "a number");
}

double finite_number(const toml::node& n, std::string_view key)
{
    const double x = number(n, key);
    if (!std::isfinite(x)) fail(std::string(key) + " = " + as_written(n) + " is not finite: accepted a finite number");
    return x;
}

// An integer in [lo, hi]; `accepted` spells the range for the message.
std::int64_t integer_in(const toml::node& n, std::string_view key, std::int64_t lo, std::int64_t hi, std::string_view accepted)
{
    const auto* i = n.as_integer();
    if (!i) wrong_type(key, n, "an integer, " + std::string(accepted));
    const std::int64_t value = i->get();
    if (value < lo || value > hi) {
        fail(std::string(key) + " = " + std::to_string(value) + " is out of range: accepted " + std::string(accepted));
    }
    return value;
}

const toml::table* table_at(const toml::table& root, std::string_view key)
{
    const toml::node* node = root.get(key);
    if (!node) return nullptr;
    if (!node->is_table()) wrong_type(key, *node, "a table " + std::string(table_spelling(key)));
    return node->as_table();
}

// --- [grid] ------------------------------------------------------------------------------

Coordinates parse_coordinates_kind(const toml::table* grid)
{
    const toml::node* node = grid ? grid->get("coordinates") : nullptr;
    if (!node) return Coordinates::canonical;
    const char* accepted = "\"canonical\" or \"physical\"";
    const auto* s = node->as_string();
    if (!s) wrong_type("[grid] coordinates", *node, std::string("a string, ") + accepted);
    if (s->get() == "canonical") return Coordinates::canonical;
    if (s->get() == "physical") return Coordinates::physical;
    const std::string spelled = "[grid] coordinates = " + as_written(*node);
    if (const auto near = suggestion(s->get(), {"canonical", "physical"})) {
        fail(spelled + " is not accepted (did you mean \"" + *near + "\"?): accepted " + accepted);
    }
    fail(spelled + " is not accepted: accepted " + accepted);
}

// `table_name`: "[grid]" or "[model]", for messages.
Range parse_range(const toml::table& table, std::string_view name, std::string_view table_name = "[grid]")
{
    const std::string where = std::string(table_name) + " " + std::string(name);
    const std::string prefix = where + ".";
    reject_unknown_keys(table, prefix, range_keys);
    const auto required = [&](std::string_view key) -> const toml::node& {
        const toml::node* node = table.get(key);
        if (!node) fail(prefix + std::string(key) + " is not set: a range needs min, max and n");
        return *node;
    };
    const double min = finite_number(required("min"), prefix + "min");
    const double max = finite_number(required("max"), prefix + "max");
    const std::int64_t n = integer_in(required("n"), prefix + "n", 1, std::numeric_limits<std::int64_t>::max(), "n >= 1");
    if (!(min < max)) {
        fail(where + " has min = " + format_double(min) + " and max = " + format_double(max) + ": accepted min < max");
    }
    // Samples are computed from max - min, which must not overflow.
    if (!std::isfinite(max - min)) {
        fail(where + " has min = " + format_double(min) + " and max = " + format_double(max) +
             ": max - min overflows, accepted a finite width");
    }
    // So must (i + 0.5)(max - min), the product in Range::sample (largest at the last sample).
    const Range range{min, max, static_cast<std::uint64_t>(n)};
    if (!std::isfinite(range.sample(range.n - 1))) {
        fail(where + " has min = " + format_double(min) + " and max = " + format_double(max) + " with n = " +
             std::to_string(n) + ": the samples overflow, accepted (n - 0.5)(max - min) finite");
    }
    return range;
}

Coordinate parse_coordinate(const toml::table* grid, const std::string& name)
{
    const std::string key = "[grid] " + name;
    const toml::node* node = grid ? grid->get(name) : nullptr;
    if (!node) fail(key + " is not set: give a fixed value or a range { min = ..., max = ..., n = ... }");
    if (const auto* table = node->as_table()) return {name, std::nullopt, parse_range(*table, name)};
    if (node->is_number()) return {name, finite_number(*node, key), std::nullopt};
    wrong_type(key, *node, "a number (fixed) or a range { min, max, n }");
}

// A key of the other kind of grid needs a different fix than a typo does.
void reject_unknown_grid_keys(const toml::table& grid, Coordinates kind)
{
    const std::vector<std::string> known = grid_keys(kind);
    const auto key = first_unknown_key(grid, known);
    if (!key) return;
    const Coordinates other = kind == Coordinates::canonical ? Coordinates::physical : Coordinates::canonical;
    if (contains(coordinate_names(other), *key)) {
        fail("[grid] " + *key + " is a coordinate of " + std::string(name(other)) + " grids, but this grid is " +
             std::string(name(kind)) + " (coordinates: " + join(coordinate_names(kind)) + "; set [grid] coordinates = \"" +
             std::string(name(other)) + "\" for " + join(coordinate_names(other)) + ")");
    }
    fail("unknown key " + unknown_key_message("[grid] " + *key, *key, known));
}

void check_points(const std::vector<Coordinate>& grid)
{
    std::uint64_t points = 1;
    bool overflow = false;
    std::string sizes;
    for (const Coordinate& c : grid) {
        if (!c.is_range()) continue;
        // The product of three int64 sizes can wrap around.
        overflow = overflow || __builtin_mul_overflow(points, c.range->n, &points);
        sizes += (sizes.empty() ? "" : " x ") + std::to_string(c.range->n);
    }
    if (overflow || points > max_grid_points) {
        fail("[grid] has " + sizes + " = " + (overflow ? "more than 2^64" : std::to_string(points)) +
             " points: accepted at most " + std::to_string(max_grid_points) + " (2^40)");
    }
}

// `parameters`: the swept model coefficients, which count toward the range axes.
std::vector<Coordinate> parse_grid(const toml::table* grid, Coordinates kind, const std::vector<Coordinate>& parameters)
{
    if (grid) reject_unknown_grid_keys(*grid, kind);
    std::vector<Coordinate> coordinates;
    for (const std::string& name : coordinate_names(kind)) coordinates.push_back(parse_coordinate(grid, name));

    std::vector<std::string> ranges;
    for (const Coordinate& c : coordinates) {
        if (c.is_range()) ranges.push_back(c.name);
    }
    if (ranges.empty() && parameters.empty()) {
        fail("[grid] has no range: accepted 1 to 3 of " + join(coordinate_names(kind)) +
             " as { min, max, n } (or a model coefficient swept as a range)");
    }
    if (ranges.size() > 3) {
        fail("[grid] has " + std::to_string(ranges.size()) + " ranges (" + join(ranges) +
             "): accepted 1 to 3, give one of them a fixed value");
    }
    std::vector<std::string> all;
    for (const Coordinate& p : parameters) all.push_back("[model] " + p.name);
    for (const std::string& r : ranges) all.push_back(r);
    if (all.size() > 4) {
        fail("the job has " + std::to_string(all.size()) + " range axes (" + join(all) +
             "): accepted at most 4 in all, give some a fixed value");
    }
    std::vector<Coordinate> axes = parameters;
    axes.insert(axes.end(), coordinates.begin(), coordinates.end());
    check_points(axes);
    return coordinates;
}

// --- [model] -----------------------------------------------------------------------------

std::optional<double> optional_number(const toml::table* table, std::string_view key)
{
    const toml::node* node = table ? table->get(key) : nullptr;
    if (!node) return std::nullopt;
    return number(*node, "[model] " + std::string(key));
}

double positive_finite(const toml::table* model, std::string_view key, double fallback)
{
    const toml::node* node = model ? model->get(key) : nullptr;
    if (!node) return fallback;
    const std::string spelled = "[model] " + std::string(key);
    const double x = number(*node, spelled);
    if (!(x > 0.0 && std::isfinite(x))) {
        fail(spelled + " = " + as_written(*node) + " is out of range: accepted finite " + std::string(key) + " > 0");
    }
    return x;
}

// A coefficient given as { min, max, n } is swept (issue 6): it becomes a range axis.
// The model is resolved twice, with every swept coefficient at its min and at its max:
// the accepted values form intervals, so the ends decide for every sample between them.
void parse_model(const toml::table* model, Coordinates kind, Job& job)
{
    const auto spell = [](std::string_view key) { return "[model] " + std::string(key); };
    if (!model) {
        job.model = resolve_model({}, spell);
        return;
    }
    reject_unknown_keys(*model, "[model] ", model_keys);
    if (kind == Coordinates::canonical) {
        for (const char* key : {"g", "radius"}) {
            if (model->contains(key)) {
                fail(std::string("[model] ") + key + " applies to physical grids only (this grid is canonical)");
            }
        }
    }
    const std::vector<std::string> names = coefficient_names();
    std::vector<int> axis(names.size(), -1);  // per coefficient key: its parameter axis, or -1
    for (std::size_t k = 0; k < names.size(); ++k) {
        const toml::node* node = model->get(names[k]);
        if (const auto* table = node ? node->as_table() : nullptr) {
            axis[k] = static_cast<int>(job.parameters.size());
            job.parameters.push_back({names[k], std::nullopt, parse_range(*table, names[k], "[model]")});
        }
    }
    const auto value = [&](std::size_t k, bool at_max) -> std::optional<double> {
        if (axis[k] < 0) return optional_number(model, names[k]);
        const Range& r = *job.parameters[static_cast<std::size_t>(axis[k])].range;
        return at_max ? r.max : r.min;
    };
    for (const bool at_max : {false, true}) {
        const ModelInput in{value(0, at_max), value(1, at_max), value(2, at_max), value(3, at_max), value(4, at_max),
                            value(5, at_max), value(6, at_max), value(7, at_max), value(8, at_max), value(9, at_max)};
        const Model m = resolve_model(in, [&](std::string_view key) {
            const auto k = static_cast<std::size_t>(std::find(names.begin(), names.end(), key) - names.begin());
            return spell(key) + (k < names.size() && axis[k] >= 0 ? (at_max ? ".max" : ".min") : "");
        });
        if (!at_max) job.model = m;
    }
    // Which axis sets each coefficient of the model (model_coefficient_names()): a per-surface
    // key wins over the shared one; inertia is its own.
    const std::size_t shared[swept_coefficients] = {0, 1, 0, 1, 6, 6, 9}, specific[swept_coefficients] = {2, 3, 4, 5, 7, 8, 9};
    for (std::size_t c = 0; c < swept_coefficients; ++c) {
        job.swept[c] = model->contains(names[specific[c]]) ? axis[specific[c]] : axis[shared[c]];
    }
    // A shared key swept while both per-surface keys are set: nothing would follow it.
    const std::size_t wall_key[3] = {2, 3, 7}, floor_key[3] = {4, 5, 8}, shared_key[3] = {0, 1, 6};
    for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t key = shared_key[k];
        if (axis[key] >= 0 && model->contains(names[wall_key[k]]) && model->contains(names[floor_key[k]])) {
            fail("[model] " + names[key] + " is a range, but " + names[wall_key[k]] + " and " + names[floor_key[k]] +
                 " are set too: nothing would follow it");
        }
    }
}

Frame parse_frame(const toml::table* model)
{
    const Frame defaults{};
    return {positive_finite(model, "g", defaults.g), positive_finite(model, "radius", defaults.radius)};
}

// --- [run] -------------------------------------------------------------------------------

void parse_run(const toml::table* run, Job& job)
{
    if (!run) return;
    reject_unknown_keys(*run, "[run] ", run_keys);
    if (const toml::node* n = run->get("max_bounces")) {
        job.max_bounces = static_cast<std::uint32_t>(
            integer_in(*n, "[run] max_bounces", 1, max_max_bounces, "1 <= max_bounces <= " + std::to_string(max_max_bounces)));
    }
    if (const toml::node* n = run->get("output")) {
        const auto* s = n->as_string();
        if (!s) wrong_type("[run] output", *n, "a string (a file path)");
        if (s->get().empty()) fail("[run] output = \"\" is empty: accepted a file path, or leave output out");
        job.output = s->get();
    }
    if (const toml::node* n = run->get("tile_points")) {
        job.tile_points = static_cast<std::uint64_t>(
            integer_in(*n, "[run] tile_points", 1, max_tile_points, "1 <= tile_points <= " + std::to_string(max_tile_points)));
    }
    if (const toml::node* n = run->get("refine")) {
        constexpr const char* accepted = "0 (every point) or a power of two from 2 to 64 (the coarse stride)";
        const auto r = integer_in(*n, "[run] refine", 0, 64, accepted);
        if ((r & (r - 1)) != 0) fail("[run] refine = " + std::to_string(r) + " is out of range: accepted " + accepted);
        job.refine = static_cast<std::uint32_t>(r);
    }
    if (const toml::node* n = run->get("compression")) {
        job.compression = static_cast<int>(
            integer_in(*n, "[run] compression", 0, 9, "0 (uncompressed) to 9 (deflate level; 1 fastest, 9 smallest)"));
    }
    if (const toml::node* n = run->get("alignment")) {
        constexpr const char* accepted = "a power of two from 4096 to 1073741824 bytes (the file system's stripe size)";
        const auto a = integer_in(*n, "[run] alignment", 4096, std::int64_t{1} << 30, accepted);
        if ((a & (a - 1)) != 0) fail("[run] alignment = " + std::to_string(a) + " is out of range: accepted " + accepted);
        job.alignment = static_cast<std::uint64_t>(a);
    }
    if (const toml::node* n = run->get("checkpoint_seconds")) {
        const double c = finite_number(*n, "[run] checkpoint_seconds");
        if (!(c >= 0.01 && c <= 86400.0)) {
            fail("[run] checkpoint_seconds = " + as_written(*n) + " is out of range: accepted 0.01 to 86400 (seconds)");
        }
        job.checkpoint_seconds = c;
    }
    if (const toml::node* n = run->get("writers")) {
        if (const auto* text = n->as_string()) {
            job.writers = writers_from_text(text->get(), "[run] writers");
        } else {
            job.writers = static_cast<std::uint32_t>(integer_in(*n, "[run] writers", 1, max_writers, writers_accepted));
        }
    }
}

Job validate(const toml::table& root)
{
    reject_unknown_top_level(root);
    const toml::table* model = table_at(root, "model");
    const toml::table* grid = table_at(root, "grid");
    const toml::table* run = table_at(root, "run");

    Job job;
    job.coordinates = parse_coordinates_kind(grid);
    parse_model(model, job.coordinates, job);
    if (job.coordinates == Coordinates::physical) job.frame = parse_frame(model);
    job.grid = parse_grid(grid, job.coordinates, job.parameters);
    parse_run(run, job);
    return job;
}

std::string syntax_error_message(std::string_view source, const toml::parse_error& e)
{
    const toml::source_position at = e.source().begin;
    return std::string(source) + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) +
           ": TOML syntax error: " + std::string(e.description());
}

}  // namespace

std::uint32_t writers_from_text(std::string_view text, std::string_view key)
{
    if (text == "auto") return 0;
    std::uint32_t n = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
    if (ec != std::errc{} || end != text.data() + text.size() || n < 1 || n > max_writers) {
        fail(std::string(key) + " = \"" + std::string(text) + "\" is not accepted: accepted " + writers_accepted);
    }
    return n;
}

Job parse_job(std::string_view text, std::string_view source)
{
    const std::string where = source.empty() ? std::string("<job>") : std::string(source);
    toml::table root;
    try {
        root = toml::parse(text, where);
    } catch (const toml::parse_error& e) {
        throw InputError(syntax_error_message(where, e));
    }
    try {
        Job job = validate(root);
        job.text = std::string(text);
        return job;
    } catch (const InputError& e) {
        throw InputError(where + ": " + e.what());
    }
}

Job load_job(const std::filesystem::path& path)
{
    const auto cannot_read = [&](const std::string& reason) {
        return InputError("cannot read job file " + path.string() + ": " + reason);
    };
    std::error_code ec;
    // An ifstream opens a directory without complaint on Linux and then reads nothing.
    if (std::filesystem::is_directory(path, ec)) throw cannot_read(std::make_error_code(std::errc::is_a_directory).message());
    std::ifstream in(path, std::ios::binary);
    if (!in) throw cannot_read(std::error_code(errno, std::generic_category()).message());
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) throw cannot_read(std::error_code(errno, std::generic_category()).message());
    return parse_job(text, path.string());
}

std::string fingerprint(const Job& job)
{
    // One key per line in a fixed order; doubles round-trip exactly, so two jobs share a
    // fingerprint iff they compute the same grid with the same model.
    std::string out = "superball job fingerprint 1\n";
    out += "coordinates = " + std::string(name(job.coordinates)) + "\n";
    for (const Coordinate& c : job.grid) {
        out += c.name + " = ";
        if (c.is_range()) {
            out += "{ min = " + format_double(c.range->min) + ", max = " + format_double(c.range->max) +
                   ", n = " + std::to_string(c.range->n) + " }\n";
        } else {
            out += format_double(c.fixed.value_or(std::nan(""))) + "\n";
        }
    }
    for (const Coordinate& p : job.parameters) {
        out += "swept " + p.name + " = { min = " + format_double(p.range->min) + ", max = " + format_double(p.range->max) +
               ", n = " + std::to_string(p.range->n) + " }\n";
    }
    out += "e_wall = " + format_double(job.model.wall.e) + "\n";
    out += "alpha_wall = " + format_double(job.model.wall.alpha) + "\n";
    out += "e_floor = " + format_double(job.model.floor.e) + "\n";
    out += "alpha_floor = " + format_double(job.model.floor.alpha) + "\n";
    // SPEC.md 1b, only where not the defaults: a job of the Cross model of a solid ball keeps
    // the fingerprint it had before they existed (its partial files resume).
    const Model defaults{};
    if (job.model.wall.mu != defaults.wall.mu || job.swept[4] >= 0) out += "mu_wall = " + format_double(job.model.wall.mu) + "\n";
    if (job.model.floor.mu != defaults.floor.mu || job.swept[5] >= 0) {
        out += "mu_floor = " + format_double(job.model.floor.mu) + "\n";
    }
    if (job.model.inertia != defaults.inertia || job.swept[6] >= 0) out += "inertia = " + format_double(job.model.inertia) + "\n";
    if (job.coordinates == Coordinates::physical) {
        out += "g = " + format_double(job.frame.g) + "\n";
        out += "radius = " + format_double(job.frame.radius) + "\n";
    }
    out += "max_bounces = " + std::to_string(job.max_bounces) + "\n";
    // Refinement can change results: a refined file is another job than a full one.
    if (job.refine != 0) out += "refine = " + std::to_string(job.refine) + "\n";
    return out;
}

}  // namespace superball
