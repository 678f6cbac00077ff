// common/parallel.h, as the raster loops (binning, tiles, shadow maps) use
// it: the caller's writes before the loop reach every body, and every body's
// writes reach the caller after it, on two threads at once.
//
// Regression test for the ThreadSanitizer build (label `threads`): with
// plain tbb::parallel_for over Debian's uninstrumented libtbb, TSan reported
// the bodies' reads of `input` (and of `arrived`'s construction) as races
// with the caller's writes, and the caller's reads of `output` as races with
// the bodies', since it cannot see TBB's fork and join.
#include <gtest/gtest.h>
#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "common/parallel.h"

#include "tests/test_labels.h"

// Tests here render on 2 or more threads (the ThreadSanitizer stage runs them), except those marked quick.
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

TEST(ParallelFor, TwoThreadsSeeTheCallersWritesAndTheCallerSeesTheirs) {
  if (tbb::this_task_arena::max_concurrency() < 2) GTEST_SKIP() << "needs 2 hardware threads";
  constexpr int kPerHalf = 4096;
  std::vector<int> input(2 * kPerHalf), output(2 * kPerHalf, 0);
  for (int i = 0; i < 2 * kPerHalf; ++i) input[size_t(i)] = 3 * i;
  std::atomic<int> arrived{0};
  std::atomic<bool> together{true};
  parallelFor(tbb::blocked_range<int>(0, 2, 1), [&](const tbb::blocked_range<int>& r) {
    for (int half = r.begin(); half != r.end(); ++half) {
      // The two halves wait for each other (10 s at most), so they run at
      // the same time on two threads.
      arrived.fetch_add(1);
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (arrived.load() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
      if (arrived.load() < 2) together = false;
      for (int i = half * kPerHalf; i < (half + 1) * kPerHalf; ++i) output[size_t(i)] = input[size_t(i)] + 1;
    }
  });
  EXPECT_TRUE(together.load()) << "the two halves did not run at the same time";
  for (int i = 0; i < 2 * kPerHalf; ++i) ASSERT_EQ(output[size_t(i)], 3 * i + 1) << i;
}

// The index form, as the tile loops use it: every index once.
RASTRAY_TEST_LABELS_OF(ParallelFor, IndexFormVisitsEveryIndexOnce, "quick");
TEST(ParallelFor, IndexFormVisitsEveryIndexOnce) {
  std::vector<int> seen(1000, 0);
  parallelFor(0, int(seen.size()), [&](int i) { seen[size_t(i)] += 1; });
  for (size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], 1) << i;
}

}  // namespace
}  // namespace rastray
