#include "signals.hpp"

#include <unistd.h>

#include <csignal>
#include <iterator>

namespace superball {

namespace {

volatile std::sig_atomic_t received = 0;
// SIGUSR1/SIGUSR2 too: mpirun forwards those to every rank on every node, where it turns
// a SIGTERM of its own into killing the ranks.
constexpr int stop_signals[] = {SIGINT, SIGTERM, SIGUSR1, SIGUSR2};
struct sigaction previous[std::size(stop_signals)]{};

extern "C" void on_stop_signal(int sig)
{
    if (received != 0) {
        constexpr char msg[] = "superball: second signal, stopping now; the result can be resumed with --resume\n";
        [[maybe_unused]] const auto n = write(STDERR_FILENO, msg, sizeof msg - 1);
        _exit(128 + sig);
    }
    received = sig;
}

}  // namespace

StopSignals::StopSignals()
{
    received = 0;
    struct sigaction sa{};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    for (std::size_t i = 0; i < std::size(stop_signals); ++i) sigaction(stop_signals[i], &sa, &previous[i]);
}

StopSignals::~StopSignals()
{
    for (std::size_t i = 0; i < std::size(stop_signals); ++i) sigaction(stop_signals[i], &previous[i], nullptr);
}

bool StopSignals::requested() { return received != 0; }
int StopSignals::which() { return received; }

}  // namespace superball
