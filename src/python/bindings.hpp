// What the files of superball._core share.
#pragma once

#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <string_view>

#include "core/input.hpp"

namespace superball {

// Keys as the Python API spells them: its argument names.
inline std::string python_key(std::string_view key) { return std::string(key); }

// fixed_points() and continue_branch() (dynamics.cpp).
void add_dynamics(pybind11::module_& m);

}  // namespace superball

// The model's coefficients as the package passes them to _core: one dict (`model=`, made by
// superball._model) of e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall,
// mu_floor, inertia, each a float or None (not given), rather than ten arguments of every
// function.
namespace pybind11::detail {
template <>
struct type_caster<superball::ModelInput> {
    PYBIND11_TYPE_CASTER(superball::ModelInput, const_name("dict[str, float | None]"));
    bool load(handle src, bool)
    {
        if (!isinstance<dict>(src)) return false;
        const auto given = reinterpret_borrow<dict>(src);
        std::size_t known = 0;
        for (const auto& [key, member] : superball::model_input_keys) {
            if (!given.contains(key)) continue;
            ++known;
            const object v = given[key];
            if (!v.is_none()) value.*member = v.cast<double>();
        }
        return known == given.size();  // no other key
    }
};
}  // namespace pybind11::detail
