// Interrupts while a command writes (Ctrl-C, `kill`): SIGINT and SIGTERM remove what the
// command was writing (the temporaries of every uncommitted OutputSet, util/output_set.h)
// and end the process with exit status 130; outputs already moved into place stay, and an
// OutputSet being committed finishes first, so an output is either all old or all new
// (docs/architecture.md, "Outputs").
//
// How: the signal handler only wakes a cleanup thread (async-signal-safe sem_post); that
// thread takes the commit lock for good (no output is moved in after it), removes every
// registered temporary, prints one line and calls _exit(130). A second signal during the
// cleanup ends the process at once. Without InstallInterruptCleanup (library users, the
// Python module, tests) signals keep their default action; what a killed process leaves
// is removed by the next writer of that folder (RemoveStaleTemporaries).
#pragma once

#include <mutex>
#include <string>

namespace arco {

// Installs the SIGINT/SIGTERM handlers and starts the cleanup thread (once; later calls do
// nothing). The CLI's Main calls it before parsing. The cleanup thread blocks the signals,
// so code that waits for them itself (view/server.cc's sigtimedwait, with the signals
// blocked in its own threads) still receives them.
void InstallInterruptCleanup();

// True once SIGINT or SIGTERM arrived with the cleanup installed: the process is ending.
bool Interrupted();

// Returns at once, or blocks for good when Interrupted(): the cleanup thread ends the
// process. For the CLI's error and exit paths, so that an error caused by a temporary
// that the cleanup removed is not printed and the exit status stays 130.
void WaitIfInterrupted();

// A path (file or folder) to remove if the process is interrupted: OutputSet registers
// its temporaries while they exist; a command may register a scratch folder of its own.
// Registering the same path twice needs two untracks.
void TrackTemporary(const std::string& path);
void UntrackTemporary(const std::string& path);

// Held while outputs are moved into place (OutputSet::Commit), while a temporary is
// registered and created (OutputSet::AddFile, AddFolder) and while folders are made
// (MakeDirectories): an interrupt waits for it, so the cleanup never sees half a commit nor
// misses a temporary, and no folder inside a removed temporary brings it back; once the
// cleanup has started, taking it blocks for good.
std::unique_lock<std::mutex> HoldOffInterrupts();

}  // namespace arco
