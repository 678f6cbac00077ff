// TBB's parallel loops with their ordering guarantees stated to
// ThreadSanitizer.
//
// Debian's libtbb is not built with -fsanitize=thread: TSan sees neither the
// task queue that hands a loop's pieces to the workers nor the wait that joins
// them, so in a TSan build every write the caller makes before a loop and reads
// after it (the image, the bins, the per-thread counters) would be reported as
// a race with the loop's bodies. parallelFor() tells TSan what TBB guarantees
// and nothing more:
//   - everything the caller did before the call happens before every body call
//     (the fork);
//   - every body call happens before the call returns (the join).
// Body calls are NOT ordered among themselves, so two bodies touching the same
// memory are still reported. Outside a TSan build these are the plain TBB
// calls and the annotations compile to nothing.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <type_traits>
#include <utility>

#if defined(__SANITIZE_THREAD__)
#define RASTRAY_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define RASTRAY_TSAN 1
#endif
#endif

#ifdef RASTRAY_TSAN
#include <sanitizer/tsan_interface.h>
#endif

namespace rastray {

// A happens-before edge through an address: everything one thread did before
// tsanRelease(a) happens before what another thread does after a later
// tsanAcquire(a). Use only where TBB itself orders the two (its hand-offs are
// invisible to TSan); no-ops outside a TSan build.
inline void tsanRelease(const void* address) {
#ifdef RASTRAY_TSAN
  __tsan_release(const_cast<void*>(address));
#else
  (void)address;
#endif
}
inline void tsanAcquire(const void* address) {
#ifdef RASTRAY_TSAN
  __tsan_acquire(const_cast<void*>(address));
#else
  (void)address;
#endif
}

namespace detail {

// The fork and join edges of one loop or pipeline: two addresses, so the
// bodies acquire only the fork (never each other's releases into the join).
struct LoopEdges {
  char fork = 0, join = 0;
};

// A body as TBB copies it into its tasks or filters. Its only accesses before
// the fork is acquired are the reads of its own two pointers, here:
// tests/tsan.supp suppresses races whose top frame is in this file (TBB
// hands the copies over invisibly); the body's own accesses, its captures
// included, come after the acquire.
template <typename Body>
struct Annotated {
  const Body* body;
  LoopEdges* edges;
  template <typename... Args>
  decltype(auto) operator()(Args&&... args) const {
    tsanAcquire(&edges->fork);
    using Result = decltype((*body)(std::forward<Args>(args)...));
    if constexpr (std::is_void_v<Result>) {
      (*body)(std::forward<Args>(args)...);
      tsanRelease(&edges->join);
    } else {
      Result result = (*body)(std::forward<Args>(args)...);
      tsanRelease(&edges->join);
      return result;
    }
  }
};

}  // namespace detail

// The fork and join of a tbb::parallel_pipeline: wrap each filter's body
// with stage(), call fork() after making the filters and just before the
// pipeline, join() right after it. The order within a serial filter and from
// one filter to the next is the caller's to state (tsanRelease/tsanAcquire).
class PipelineEdges {
 public:
  template <typename Body>
  detail::Annotated<Body> stage(const Body& body) {
    return {&body, &edges_};
  }
  void fork() { tsanRelease(&edges_.fork); }
  void join() { tsanAcquire(&edges_.join); }

 private:
  detail::LoopEdges edges_;
};

// tbb::parallel_for(range, body), annotated as above.
template <typename Range, typename Body>
void parallelFor(const Range& range, const Body& body) {
#ifdef RASTRAY_TSAN
  detail::LoopEdges edges;
  const detail::Annotated<Body> annotated{&body, &edges};
  tsanRelease(&edges.fork);
  tbb::parallel_for(range, annotated);
  tsanAcquire(&edges.join);
#else
  tbb::parallel_for(range, body);
#endif
}

// tbb::parallel_for(first, last, body) over an index, annotated as above.
template <typename Index, typename Body>
void parallelFor(Index first, Index last, const Body& body) {
#ifdef RASTRAY_TSAN
  detail::LoopEdges edges;
  const detail::Annotated<Body> annotated{&body, &edges};
  tsanRelease(&edges.fork);
  tbb::parallel_for(first, last, annotated);
  tsanAcquire(&edges.join);
#else
  tbb::parallel_for(first, last, body);
#endif
}

}  // namespace rastray
