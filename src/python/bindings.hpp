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

inline ModelInput model_input(std::optional<double> e, std::optional<double> alpha, std::optional<double> e_wall,
                              std::optional<double> alpha_wall, std::optional<double> e_floor,
                              std::optional<double> alpha_floor)
{
    return {e, alpha, e_wall, alpha_wall, e_floor, alpha_floor};
}

// fixed_points() and continue_branch() (dynamics.cpp).
void add_dynamics(pybind11::module_& m);

}  // namespace superball
