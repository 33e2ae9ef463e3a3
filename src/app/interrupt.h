// SIGINT and SIGTERM during the phases that can stop early (object lights, VPLs, the
// render): while an InterruptScope lives, the signal only sets a flag that those phases
// check (per block of paths, lights or pixels), so the CLI can keep the old output, write
// what it has and exit 128 + the signal (130 for SIGINT, 143 for SIGTERM). Outside a
// scope the signals have their default effect (the process ends at once; nothing has been
// written yet).
#pragma once

#include <atomic>

namespace lc::app {

// Set by the first SIGINT/SIGTERM caught in a scope; handed to the phases as `cancel`.
std::atomic<bool>& interruptFlag();
// The signal that set the flag (0: none).
int interruptSignal();
// The exit status of a run stopped by that signal: 128 + signal.
int interruptExitStatus();

class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
};

}  // namespace lc::app
