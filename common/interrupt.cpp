#include "common/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

namespace rastray {

namespace {

// Written by the handler, read by every thread: a lock-free atomic is both
// async-signal-safe (C++17 [support.signal]) and visible across threads,
// which a volatile sig_atomic_t alone is not guaranteed to be.
std::atomic<int> requested{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");

// Only async-signal-safe calls: an atomic store, sigaction and write.
extern "C" void onStopSignal(int signal) {
  int none = 0;
  requested.compare_exchange_strong(none, signal, std::memory_order_relaxed);
  // The next SIGINT or SIGTERM takes the default action: a second Ctrl-C
  // gets out at once.
  struct sigaction dfl;
  std::memset(&dfl, 0, sizeof dfl);
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(SIGINT, &dfl, nullptr);
  sigaction(SIGTERM, &dfl, nullptr);
  static const char line[] = "\nrastray: stopping at the next check (again to quit at once)\n";
  const ssize_t ignored = ::write(STDERR_FILENO, line, sizeof line - 1);
  (void)ignored;
}

const char* signalName(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "a signal";
  }
}

}  // namespace

Interrupted::Interrupted(int signal, std::string finished)
    : std::runtime_error("interrupted"), signal_(signal), finished_(std::move(finished)) {}

std::string Interrupted::message() const {
  return std::string("interrupted by ") + signalName(signal_) + ": " + finished_;
}

void installInterruptHandlers() {
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = &onStopSignal;
  sigemptyset(&action.sa_mask);
  // Both signals blocked while the handler runs, so the two restorations
  // of the default action happen together.
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  // A read or write the signal lands in is restarted, not failed with EINTR.
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool interruptRequested() { return requested.load(std::memory_order_relaxed) != 0; }

int interruptSignal() { return requested.load(std::memory_order_relaxed); }

void throwIfInterrupted() {
  const int signal = interruptSignal();
  if (signal != 0) throw Interrupted(signal, "nothing written");
}

void throwIfStopped(const CancelToken* token) {
  throwIfInterrupted();
  if (token && token->cancelled()) throw Cancelled();
}

void setInterruptForTesting(int signal) { requested.store(signal, std::memory_order_relaxed); }

}  // namespace rastray
