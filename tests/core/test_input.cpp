// The checks of user input shared by the command line, job files and Python (core/input.hpp):
// which start a set of keys makes, the bounce limit as given, and the order of the checks.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/input.hpp"

namespace superball {
namespace {

std::string plain(std::string_view key) { return std::string(key); }

template <class F>
std::string refusal(F&& f)
{
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

TEST(ResolveStartKeys, OnlyWhichKeysAreSetMatters)
{
    // Values that resolve_start would refuse (a NaN, a launch away from the wall): the keys
    // alone are checked here.
    StartInput canonical;
    canonical.xi = -1.0;
    canonical.U = 5.0;
    canonical.W = std::nan("");
    const StartKind c = resolve_start_keys(canonical, plain);
    EXPECT_FALSE(c.physical);
    EXPECT_EQ(c.frame.g, 1.0);
    EXPECT_EQ(c.frame.radius, 1.0);

    StartInput physical;
    physical.x = physical.u = physical.v = physical.omega = 0.0;
    physical.radius = 0.03;
    const StartKind p = resolve_start_keys(physical, plain);
    EXPECT_TRUE(p.physical);
    EXPECT_EQ(p.frame.g, Frame{}.g);  // the default
    EXPECT_EQ(p.frame.radius, 0.03);
}

TEST(ResolveStartKeys, RefusesMixedMissingAndIncompleteStarts)
{
    StartInput none;
    EXPECT_EQ(refusal([&] { resolve_start_keys(none, plain); }),
              "no start point: give xi U W (canonical) or x u v omega (physical)");
    StartInput mixed;
    mixed.xi = mixed.x = 0.1;
    EXPECT_EQ(refusal([&] { resolve_start_keys(mixed, plain); }),
              "give either a canonical start (xi U W) or a physical one (x u v omega), not both");
    StartInput no_w;
    no_w.xi = 0.1;
    no_w.U = -1.0;
    EXPECT_EQ(refusal([&] { resolve_start_keys(no_w, plain); }), "W is not set: a canonical start needs it");
    no_w.W = 0.0;
    no_w.g = 9.81;
    EXPECT_EQ(refusal([&] { resolve_start_keys(no_w, plain); }), "g and radius apply to physical starts only");
    StartInput physical;
    physical.x = physical.u = physical.v = 0.1;
    physical.g = -2.0;
    // The frame before the missing key, as resolve_start always checked them.
    EXPECT_EQ(refusal([&] { resolve_start_keys(physical, plain); }), "g = -2 is out of range: accepted g > 0");
    physical.g.reset();
    EXPECT_EQ(refusal([&] { resolve_start_keys(physical, plain); }), "omega is not set: a physical start needs it");
}

TEST(ResolveMaxBounces, AcceptsOneTo2To32MinusOneAsGiven)
{
    EXPECT_EQ(resolve_max_bounces("1", plain), 1u);
    EXPECT_EQ(resolve_max_bounces("1000", plain), 1000u);
    EXPECT_EQ(resolve_max_bounces("4294967295", plain), 4294967295u);
    const std::string range = " is out of range: accepted 1 to 4294967295";
    for (const std::string given : {"0", "-3", "-0", "4294967296", "18446744073709551616", "99999999999999999999999"}) {
        EXPECT_EQ(refusal([&] { resolve_max_bounces(given, plain); }), "max_bounces = " + given + range) << given;
    }
    for (const std::string given : {"", "-", "1.5", "1e3", "many", "+5", " 5", "5 "}) {
        EXPECT_EQ(refusal([&] { resolve_max_bounces(given, plain); }), "max_bounces = " + given + " is not an integer")
            << given;
    }
}

TEST(ResolveOneStart, ChecksTheModelThenTheStartThenTheLimit)
{
    StartInput start;  // no start
    ModelInput model;  // no coefficient
    EXPECT_EQ(refusal([&] { resolve_one_start(model, start, "0", plain); }),
              "e_wall is not set: give e (both surfaces) or e_wall");
    model.e = model.alpha = 0.9;
    EXPECT_EQ(refusal([&] { resolve_one_start(model, start, "0", plain); }).substr(0, 14), "no start point");
    start.xi = 0.1;
    start.U = -1.0;
    start.W = 0.0;
    EXPECT_EQ(refusal([&] { resolve_one_start(model, start, "0", plain); }),
              "max_bounces = 0 is out of range: accepted 1 to 4294967295");
    const OneStartSetup s = resolve_one_start(model, start, "70000", plain);
    EXPECT_EQ(s.max_bounces, 70000u);
    EXPECT_FALSE(s.start.physical);
    EXPECT_EQ(s.model.wall.e, 0.9);
}

}  // namespace
}  // namespace superball
