#include "app/interrupt.h"

#include <csignal>

namespace lc::app {

namespace {
std::atomic<bool> gInterrupted{false};
std::atomic<int> gSignal{0};
extern "C" void onSignal(int sig) {
  int none = 0;
  gSignal.compare_exchange_strong(none, sig);
  gInterrupted.store(true);
}
}  // namespace

std::atomic<bool>& interruptFlag() { return gInterrupted; }
int interruptSignal() { return gSignal.load(); }
int interruptExitStatus() { return 128 + (gSignal.load() ? gSignal.load() : SIGINT); }

InterruptScope::InterruptScope() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
}

InterruptScope::~InterruptScope() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

}  // namespace lc::app
