// SIGINT/SIGTERM (and SIGUSR1/SIGUSR2) handling for long runs: the first signal asks for a clean stop (no new
// tiles, tiles in flight finish, the file is closed consistent and resumable), a second
// one ends the process at once (the file stays resumable: every tile marked done is on
// disk).
#pragma once

namespace superball {

// Installs the handlers for the lifetime of the object and restores the previous ones
// after. The flag behind it is process-wide by nature: signals are.
class StopSignals {
public:
    StopSignals();
    ~StopSignals();
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;

    // True once SIGINT, SIGTERM, SIGUSR1 or SIGUSR2 arrived.
    static bool requested();
    // The signal that arrived (0 if none).
    static int which();
};

}  // namespace superball
