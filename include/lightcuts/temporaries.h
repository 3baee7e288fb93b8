// Temporary files removed when a signal ends the program. Every writer of
// an output in this library (OutputSet, the image writers of image.h)
// writes to a temporary beside it and renames it into place; a signal
// between the two would leave the temporary behind unless the program has
// called remove_temporaries_on_signal.
#pragma once

#include <filesystem>

namespace lc {

// Makes SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE and SIGXFSZ remove every
// tracked temporary before the signal ends the process as it would have,
// and the crashes SIGABRT, SIGSEGV and SIGBUS too where no handler has them
// yet (a sanitizer's is left in place). A signal the process
// ignores (SIGHUP under nohup, say) stays ignored. For programs, not
// libraries: it replaces the signals' handlers. At most 64 temporaries are
// tracked at a time; more are still removed on every other way out.
void remove_temporaries_on_signal();

// Tracks a temporary this process is writing, for remove_temporaries_on_signal.
// Returns a handle for untrack_temporary; -1 when the table is full. Never
// track a file that must survive: the handler removes it.
int track_temporary(const std::filesystem::path& file) noexcept;
// Stops tracking (handle -1: nothing). Call after the temporary was removed
// or renamed, so a signal between the two finds nothing left behind.
void untrack_temporary(int handle) noexcept;

// The steps of a commit that replaces several files one rename at a time
// (OutputSet::commit), for remove_temporaries_on_signal: a signal before
// finish() puts every file begun back as it was (the file it replaced,
// kept under its backup name, a hard link or the file moved aside, renamed
// back onto it; a file that was not there removed), and one after finish()
// keeps the new files and removes the backups. Each step holds whatever a
// signal interrupts: before, during or after its renames. One journal at a
// time per process: a second one, while the first lives, records nothing
// (active() is false). At most 64 steps are recorded; more are not undone
// by a signal.
class ReplacementJournal {
public:
    ReplacementJournal() noexcept;
    ~ReplacementJournal();
    ReplacementJournal(const ReplacementJournal&) = delete;
    ReplacementJournal& operator=(const ReplacementJournal&) = delete;

    bool active() const noexcept { return active_; }
    // Before anything is renamed for `file`: `backup` is where the file it
    // replaces will be moved, or empty where there is none to keep.
    void begin(const std::filesystem::path& file, const std::filesystem::path& backup) noexcept;
    // Every file is in place: a signal from now on keeps them.
    void finish() noexcept;

private:
    bool active_ = false;
};

}  // namespace lc
