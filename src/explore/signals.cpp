#include "signals.hpp"

#include <unistd.h>

#include <csignal>

namespace superball {

namespace {

volatile std::sig_atomic_t received = 0;
struct sigaction previous_int{}, previous_term{};

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
    sigaction(SIGINT, &sa, &previous_int);
    sigaction(SIGTERM, &sa, &previous_term);
}

StopSignals::~StopSignals()
{
    sigaction(SIGINT, &previous_int, nullptr);
    sigaction(SIGTERM, &previous_term, nullptr);
}

bool StopSignals::requested() { return received != 0; }
int StopSignals::which() { return received; }

}  // namespace superball
