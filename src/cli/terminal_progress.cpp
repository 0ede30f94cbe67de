#include "terminal_progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cmath>

namespace superball {

namespace {
std::string duration_text(double s)
{
    if (!(s < 1e9)) return "?";
    const long long t = std::llround(s);  // s >= 0: a duration
    if (t >= 3600) return fmt::format("{}h{:02}m", t / 3600, (t % 3600) / 60);
    if (t >= 60) return fmt::format("{}m{:02}s", t / 60, t % 60);
    return fmt::format("{}s", t);
}
}  // namespace

TerminalProgress::TerminalProgress(std::FILE* out, bool quiet) : out_(out), quiet_(quiet), live_(isatty(fileno(out)) != 0) {}

void TerminalProgress::started(const RunStart& s)
{
    total_tiles_ = s.tiles;
    total_points_ = s.grid_points;
    tiles_done_ = s.tiles_done;
    points_done_ = s.points_done;
    start_ = last_report_ = Clock::now();
    if (quiet_) return;
    if (!s.note.empty()) fmt::print(out_, "{}\n", s.note);
    if (s.tiles == 0) return;  // nothing to compute
    fmt::print(out_, "superball explore: {} points ({} tiles of up to {} points) on {} rank{}\n", s.grid_points, s.tiles,
               s.tile_points, s.ranks, s.ranks == 1 ? "" : "s");
    std::fflush(out_);
}

double TerminalProgress::seconds() const
{
    return final_seconds_ >= 0 ? final_seconds_ : std::chrono::duration<double>(Clock::now() - start_).count();
}

void TerminalProgress::tiles_done(std::uint64_t tiles, std::uint64_t points)
{
    tiles_done_ += tiles;
    points_done_ += points;
    points_run_ += points;
    if (quiet_) return;
    const auto now = Clock::now();
    // A terminal line can be redrawn often; a log gets a line every 10 s.
    const auto interval = live_ ? std::chrono::milliseconds(200) : std::chrono::milliseconds(10000);
    if (now - last_report_ >= interval) {
        last_report_ = now;
        report(false);
    }
}

void TerminalProgress::report(bool final)
{
    const double s = seconds();
    const double rate = s > 0 ? static_cast<double>(points_run_) / s : 0.0;
    const double eta = rate > 0 ? static_cast<double>(total_points_ - points_done_) / rate : 1e18;
    const std::string line = fmt::format("tiles {}/{} ({:.1f}%)  {:.3g} points/s  elapsed {}  ETA {}", tiles_done_,
                                         total_tiles_, 100.0 * static_cast<double>(tiles_done_) / static_cast<double>(total_tiles_),
                                         rate, duration_text(s), final ? "0s" : duration_text(eta));
    if (live_) {
        fmt::print(out_, "\r{:<90}", line);
        if (final) fmt::print(out_, "\n");
    } else {
        fmt::print(out_, "{}\n", line);
    }
    std::fflush(out_);
}

void TerminalProgress::computed(double seconds)
{
    final_seconds_ = seconds;
    if (!quiet_ && total_tiles_ > 0) report(true);
}

void TerminalProgress::finishing()
{
    if (quiet_) return;
    fmt::print(out_, "finishing the result: the partial file's tiles indexed where they lie, then renamed\n");
    std::fflush(out_);
}

}  // namespace superball
