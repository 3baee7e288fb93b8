// Temporaries removed on a signal (include/lightcuts/temporaries.h).
#include "lightcuts/temporaries.h"

#include <atomic>
#include <csignal>
#include <filesystem>
#include <cstring>
#include <new>
#include <string>

#include <unistd.h>

namespace lc {

namespace {

// The temporaries remove_temporaries_on_signal's handler removes: copies of
// their names in a fixed table it can read without locks or allocation.
// A name is freed by untrack_temporary only while no handler runs: the
// handler counts itself in before it reads the table, and untrack clears the
// slot before it reads the count (sequentially consistent atomics, so one of
// the two sees the other). A name a handler may still read is left alone;
// the process is ending then anyway.
constexpr int kTrackedSlots = 64;
std::atomic<char*> g_tracked[kTrackedSlots];
std::atomic<int> g_handlers_running{0};

extern "C" void remove_temporaries_and_reraise(int signal_number) {
    g_handlers_running.fetch_add(1);
    for (std::atomic<char*>& slot : g_tracked)
        if (const char* name = slot.load()) ::unlink(name);
    // SA_RESETHAND put back the default action: this ends the process as
    // the signal would have, with the status a shell reports for it.
    ::raise(signal_number);
}

}  // namespace

int track_temporary(const std::filesystem::path& file) noexcept {
    const std::string& name = file.native();
    char* copy = new (std::nothrow) char[name.size() + 1];
    if (copy == nullptr) return -1;
    std::memcpy(copy, name.c_str(), name.size() + 1);
    for (int i = 0; i < kTrackedSlots; ++i) {
        char* expected = nullptr;
        if (g_tracked[i].compare_exchange_strong(expected, copy)) return i;
    }
    delete[] copy;
    return -1;
}

void untrack_temporary(int handle) noexcept {
    if (handle < 0 || handle >= kTrackedSlots) return;
    char* name = g_tracked[handle].exchange(nullptr);
    if (g_handlers_running.load() == 0) delete[] name;
}

void remove_temporaries_on_signal() {
    // Besides the three that stop a program from outside: SIGQUIT (Ctrl-\),
    // SIGPIPE (a message to a pipe whose reader has gone, as in
    // `lightcuts render ... 2>&1 | head`) and SIGXFSZ (a write past the
    // file-size limit, `ulimit -f`).
    // And the crashes, SIGABRT (a library's failed assertion: tinyexr's on
    // a failed allocation), SIGSEGV and SIGBUS, where no other handler has
    // them (a sanitizer's stays).
    for (int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXFSZ, SIGABRT, SIGSEGV, SIGBUS}) {
        struct sigaction current {};
        if (::sigaction(signal_number, nullptr, &current) != 0 || current.sa_handler == SIG_IGN) continue;
        const bool crash = signal_number == SIGABRT || signal_number == SIGSEGV || signal_number == SIGBUS;
        if (crash && ((current.sa_flags & SA_SIGINFO) != 0 || current.sa_handler != SIG_DFL)) continue;
        struct sigaction action {};
        action.sa_handler = remove_temporaries_and_reraise;
        sigemptyset(&action.sa_mask);
        action.sa_flags = SA_RESETHAND;
        ::sigaction(signal_number, &action, nullptr);
    }
}

}  // namespace lc
