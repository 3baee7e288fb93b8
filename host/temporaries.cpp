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

// The replacement journal (ReplacementJournal): its steps' files and
// backups, filled before g_steps counts them, so a handler reads whole steps
// only; names are freed as g_tracked's are.
struct Step {
    std::atomic<char*> file{nullptr};
    std::atomic<char*> backup{nullptr};
};
Step g_steps[kTrackedSlots];
std::atomic<int> g_step_count{0};
std::atomic<bool> g_journal_finished{false};
std::atomic<bool> g_journal_taken{false};

char* copy_of(const std::string& name) noexcept {
    char* copy = new (std::nothrow) char[name.size() + 1];
    if (copy != nullptr) std::memcpy(copy, name.c_str(), name.size() + 1);
    return copy;
}

// Undone or kept whatever the step had done: renaming the backup onto the
// file restores it whether the new file is in place (replaced) or not (the
// backup, a hard link to the file or the file moved aside, made only);
// where the backup was never made the rename fails and the file is as it
// was. A step without a backup had no file to
// keep: removing the file removes the new one, if placed. Only unlink and
// rename: both async-signal-safe.
void undo_or_keep_steps() {
    const bool finished = g_journal_finished.load();
    const int count = g_step_count.load();
    for (int i = count; i-- > 0;) {
        const char* file = g_steps[i].file.load();
        const char* backup = g_steps[i].backup.load();
        if (file == nullptr) continue;
        if (finished) {
            if (backup != nullptr) ::unlink(backup);
        } else if (backup != nullptr) {
            ::rename(backup, file);
            ::unlink(backup);  // a hard link to the file itself: the rename left it
        } else {
            ::unlink(file);
        }
    }
}

extern "C" void remove_temporaries_and_reraise(int signal_number) {
    g_handlers_running.fetch_add(1);
    undo_or_keep_steps();
    for (std::atomic<char*>& slot : g_tracked)
        if (const char* name = slot.load()) ::unlink(name);
    // SA_RESETHAND put back the default action: this ends the process as
    // the signal would have, with the status a shell reports for it.
    ::raise(signal_number);
}

}  // namespace

int track_temporary(const std::filesystem::path& file) noexcept {
    char* copy = copy_of(file.native());
    if (copy == nullptr) return -1;
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

ReplacementJournal::ReplacementJournal() noexcept {
    bool expected = false;
    active_ = g_journal_taken.compare_exchange_strong(expected, true);
}

void ReplacementJournal::begin(const std::filesystem::path& file, const std::filesystem::path& backup) noexcept {
    const int i = g_step_count.load();
    if (!active_ || i >= kTrackedSlots) return;
    char* file_copy = copy_of(file.native());
    char* backup_copy = backup.empty() ? nullptr : copy_of(backup.native());
    if (file_copy == nullptr || (!backup.empty() && backup_copy == nullptr)) {
        delete[] file_copy;
        delete[] backup_copy;
        return;
    }
    g_steps[i].backup.store(backup_copy);
    g_steps[i].file.store(file_copy);
    g_step_count.store(i + 1);
}

void ReplacementJournal::finish() noexcept {
    if (active_) g_journal_finished.store(true);
}

ReplacementJournal::~ReplacementJournal() {
    if (!active_) return;
    // Uncounted first, so a handler that starts now reads no step; then the
    // names, freed only where no handler is reading them.
    const int count = g_step_count.exchange(0);
    for (int i = 0; i < count; ++i) {
        char* file = g_steps[i].file.exchange(nullptr);
        char* backup = g_steps[i].backup.exchange(nullptr);
        if (g_handlers_running.load() == 0) {
            delete[] file;
            delete[] backup;
        }
    }
    g_journal_finished.store(false);
    g_journal_taken.store(false);
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
