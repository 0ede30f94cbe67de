// How long a thread a process starts waits for a core, and then writes, while BUSY other
// processes compute on this machine: rank 0's appender starts a thread per write
// (io/partial_file.cpp, ChunkAppender), and when 64 ranks share 2 cores that wait, not the
// page cache, is what a write costs. tests/scale/validate.sh --oversubscribed puts it in
// the local platform as the file system's latency per operation, so that its simulation
// runs on the machine the real runs had. And how long a message takes to a process that
// waits for it asleep (a rank waiting for a block, rank 0 between requests), which has to
// be woken and given a core: half the round trip through two pipes to a sleeping child.
// Prints the medians of SAMPLES each:
//
//   core_wait_s=S wake_s=W
//
//   core_wait BUSY [SAMPLES]
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <string>
#include <thread>
#include <vector>

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: core_wait BUSY [SAMPLES]\n");
        return 2;
    }
    const int busy = std::atoi(argv[1]);
    const int samples = argc > 2 ? std::max(1, std::atoi(argv[2])) : 21;
    std::vector<pid_t> children;
    for (int i = 0; i < busy; ++i) {
        const pid_t pid = fork();
        if (pid == 0) {
            volatile unsigned long spin = 0;
            for (;;) spin = spin + 1;  // a rank counting: never sleeps
        }
        if (pid < 0) break;
        children.push_back(pid);
    }
    // The sleeping peer: echoes every byte back.
    int ping[2], pong[2];
    if (pipe(ping) != 0 || pipe(pong) != 0) return 1;
    const pid_t echo = fork();
    if (echo == 0) {
        close(ping[1]);  // so that the parent's close ends the loop
        close(pong[0]);
        char c;
        while (read(ping[0], &c, 1) == 1) {
            if (write(pong[1], &c, 1) != 1) break;
        }
        _exit(0);
    }
    close(ping[0]);
    close(pong[1]);
    std::string path = "/tmp/core_wait-XXXXXX";
    const int fd = mkstemp(path.data());
    std::vector<char> bytes(16384, 1);
    std::vector<double> waits;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the children running
    for (int i = 0; i < samples && fd >= 0; ++i) {
        const auto start = std::chrono::steady_clock::now();
        auto write = std::async(std::launch::async, [&] { return pwrite(fd, bytes.data(), bytes.size(), 0); });
        write.get();
        waits.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::vector<double> wakes;
    for (int i = 0; i < samples && echo > 0; ++i) {
        const auto start = std::chrono::steady_clock::now();
        char c = 'x';
        if (write(ping[1], &c, 1) != 1 || read(pong[0], &c, 1) != 1) break;
        wakes.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 2);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    close(ping[1]);
    close(pong[0]);
    if (echo > 0) waitpid(echo, nullptr, 0);
    for (const pid_t pid : children) kill(pid, SIGKILL);
    for (const pid_t pid : children) waitpid(pid, nullptr, 0);
    if (fd >= 0) {
        close(fd);
        unlink(path.c_str());
    }
    if (waits.empty() || wakes.empty()) {
        std::fprintf(stderr, "core_wait: could not start the busy processes or the file\n");
        return 1;
    }
    std::sort(waits.begin(), waits.end());
    std::sort(wakes.begin(), wakes.end());
    std::printf("core_wait_s=%.6g wake_s=%.6g\n", waits[waits.size() / 2], wakes[wakes.size() / 2]);
    return 0;
}
