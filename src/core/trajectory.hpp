// The full event list of a launch, for inspection and plotting (superball trajectory).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "count.hpp"

namespace superball {

enum class EventKind : std::uint8_t {
    launch,  // t = 0, the start state
    wall,    // impact with the wall (x = 0)
    floor,   // floor bounce that sends the ball back toward the wall (or away: outcome left)
    land,    // next floor contact after the motion ended (missed or left): recorded, not applied
};

constexpr std::string_view name(EventKind k)
{
    switch (k) {
        case EventKind::launch: return "launch";
        case EventKind::wall: return "wall";
        case EventKind::floor: return "floor";
        case EventKind::land: return "land";
    }
    return "unknown";
}

struct Event {
    EventKind kind;
    std::uint32_t wall_bounces;  // wall impacts up to and including this event
    double t;                    // time since launch
    double x, y;                 // centre of the ball
    Velocities<double> before;   // (u, v, W) arriving
    Velocities<double> after;    // (u, v, W) leaving
    // Wall and floor impacts: whether the impact slid (Walton's law, SPEC.md 1b) and its
    // tangential factor beta (alpha where it gripped).
    Contact contact{};
};

// A point on a flight parabola; `segment` is the index of the event the flight starts from.
struct PathPoint {
    std::uint32_t segment;
    double t, x, y, u, v;
};

struct Trajectory {
    std::vector<Event> events;
    std::vector<PathPoint> path;  // empty unless samples were asked for
    BounceCount result;
    // The events stop early when the motion has shrunk by more than `representable_scale`
    // (vertical speed relative to the launch's): a motion that converges into the corner
    // would otherwise underflow to 0 and NaN. `result` is exact all the same.
    bool truncated = false;
};

// Vertical speed ratio v_n / v_0 below which trajectory() stops recording events:
// lengths scale as its square, 1e-200, still far from underflow.
inline constexpr double representable_scale = 1e-100;

// Follows a physical launch through its impacts. The decisions (miss, leave, cap) are
// taken on the canonical state iterated alongside, so the result always equals
// count() for the same start, to the last bit. `samples_per_flight` >= 2 adds that many
// evenly spaced points (ends included) on every flight.
Trajectory trajectory(const PhysicalState<double>& start, const Model& m, double g, std::uint32_t max_bounces,
                      int samples_per_flight = 0);

}  // namespace superball
