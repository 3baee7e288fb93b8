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

}  // namespace lc
