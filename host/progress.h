// Progress display for long renders: percentage and ETA on stderr, only when
// stderr is a terminal and the render has already taken over a second.
#pragma once

#include <chrono>
#include <cstdio>
#include <mutex>

#include <unistd.h>

namespace lc {

class Progress {
public:
    explicit Progress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
    ~Progress() { finish(); }
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    // Thread-safe; `fraction` in [0, 1].
    void update(double fraction) {
        if (!enabled_) return;
        std::lock_guard lock(mutex_);
        double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
        if (elapsed < 1.0 || elapsed - last_print_ < 0.2) return;
        last_print_ = elapsed;
        double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
        std::fprintf(stderr, "\r%5.1f%%  elapsed %.1fs  ETA %.1fs   ", 100.0 * fraction, elapsed, eta);
        printed_ = true;
    }

    void finish() {
        if (printed_) std::fprintf(stderr, "\r%60s\r", "");
        printed_ = false;
    }

private:
    using Clock = std::chrono::steady_clock;
    bool enabled_;
    bool printed_ = false;
    double last_print_ = 0.0;
    Clock::time_point start_ = Clock::now();
    std::mutex mutex_;
};

}  // namespace lc
