#include "layout.hpp"

namespace superball::layout {

namespace {

std::filesystem::path with_suffix(const std::filesystem::path& p, std::string_view suffix)
{
    std::filesystem::path out = p;
    out += suffix;
    return out;
}

}  // namespace

std::filesystem::path partial_path(const std::filesystem::path& output) { return with_suffix(output, ".partial"); }

std::filesystem::path finishing_path(const std::filesystem::path& output) { return with_suffix(output, ".finishing"); }

std::filesystem::path sidecar_path(const std::filesystem::path& output)
{
    std::filesystem::path out = output;
    out.replace_extension(".xmf");
    return out;
}

VariableText variable_text(std::string_view name)
{
    // Canonical coordinates (SPEC.md section 2) are dimensionless; physical ones in SI.
    static constexpr struct {
        std::string_view name;
        VariableText text;
    } table[] = {
        {"xi", {"launch distance over free-flight range, xi = g x / (2 |u| v)", "1"}},
        {"U", {"launch direction, U = u / v", "1"}},
        {"W", {"spin over vertical speed, W = a omega / v", "1"}},
        {"x", {"distance of the ball's centre from the wall at launch", "m"}},
        {"u", {"horizontal velocity at launch (negative: toward the wall)", "m/s"}},
        {"v", {"vertical velocity at launch", "m/s"}},
        {"omega", {"spin at launch (positive from Ox to Oy)", "rad/s"}},
        {"e", {"normal coefficient of restitution, wall and floor", "1"}},
        {"alpha", {"tangential coefficient of restitution, wall and floor", "1"}},
        {"e_wall", {"normal coefficient of restitution of the wall", "1"}},
        {"alpha_wall", {"tangential coefficient of restitution of the wall", "1"}},
        {"e_floor", {"normal coefficient of restitution of the floor", "1"}},
        {"alpha_floor", {"tangential coefficient of restitution of the floor", "1"}},
        {"mu", {"Coulomb friction coefficient, wall and floor", "1"}},
        {"mu_wall", {"Coulomb friction coefficient of the wall", "1"}},
        {"mu_floor", {"Coulomb friction coefficient of the floor", "1"}},
        {"inertia", {"moment of inertia of the ball over m a^2", "1"}},
    };
    for (const auto& row : table) {
        if (row.name == name) return row.text;
    }
    return {name, "1"};
}

}  // namespace superball::layout
