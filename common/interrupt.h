// Ctrl-C and SIGTERM as a request to stop: the long-running commands
// (render, crossval, sweep, bench, stability) install handlers that only
// record the signal; the renderers' tile loops and the commands' scene and
// cell loops poll the record and stop at their next check, so every output
// already written stays whole and no temporary file is left (SPEC §7: no
// partial output). The command then says on stderr what it finished, and
// main() exits with interruptedExitStatus() (cli/exit_status.h).
//
// Where the checks are (how soon a request is honoured):
// - the rasterizer's and the ray caster's tile loops (raster/rasterizer.cpp,
//   raster/shadow_map.cpp, raytrace/primary_visibility.cpp): a tile whose
//   turn comes after the request is skipped, so a render stops within about
//   one tile per thread; after the loop the caller throws Interrupted;
// - between the stages of a crossval scene, between scenes, sweep cells,
//   bench rounds and stability cases.
// File writes (common/image.cpp) do not poll: a write that has started
// finishes and renames its temporary file into place, and the next check
// stops the command, so no temporary file is left behind.
//
// A second Ctrl-C or SIGTERM after the first ends the process at once with
// the default action (the handler restores it when the first arrives): the
// way out if a check is far away, at the price of what the checks protect.
//
// A render also stops on its own CancelToken (RasterOptions::cancel,
// RayOptions::cancel), polled at the same checks: serve cancels a request's
// render when a newer request of the same client arrives, and the render
// throws Cancelled within about one tile per thread. A render without a
// token (nullptr) stops on a signal alone.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>

namespace rastray {

// Thrown by throwIfInterrupted() once a stop was requested. `finished`
// says what the command completed ("nothing written" unless a command
// replaced it with its own account; see withFinished()).
class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, std::string finished);
  int signal() const { return signal_; }
  const std::string& finished() const { return finished_; }
  // The same interruption with a command's own account of what it finished.
  Interrupted withFinished(std::string finished) const { return Interrupted(signal_, std::move(finished)); }
  // "interrupted by SIGINT: <finished>"
  std::string message() const;

 private:
  int signal_;
  std::string finished_;
};

// Installs the SIGINT and SIGTERM handlers (sigaction, SA_RESTART). Call
// once a command that polls has started; commands that do not poll keep
// the default action (a killed process).
void installInterruptHandlers();

// Whether a stop was requested: one relaxed atomic load, cheap enough per
// tile (never call it per sample: render speed must not change).
bool interruptRequested();
// The signal that requested the stop, 0 if none.
int interruptSignal();
// Throws Interrupted when a stop was requested.
void throwIfInterrupted();

// A request to stop one render; cancel() is thread-safe and may come from
// any thread (serve's request handlers). Never reset: one token per render.
class CancelToken {
 public:
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> cancelled_{false};
};

// Thrown by throwIfStopped() when the render's own token was cancelled (a
// signal throws Interrupted: the whole command stops).
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

// Whether a render with this token (nullptr: none) should stop: a signal
// arrived or the token was cancelled. Two relaxed loads: per tile, never
// per sample.
inline bool stopRequested(const CancelToken* token) {
  return interruptRequested() || (token && token->cancelled());
}
// Throws Interrupted for a signal, else Cancelled for a cancelled token.
void throwIfStopped(const CancelToken* token);

// For tests in process: records `signal` as if it had arrived (0 clears
// the request), without installing or invoking a handler.
void setInterruptForTesting(int signal);

}  // namespace rastray
