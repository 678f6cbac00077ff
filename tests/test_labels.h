// Labels a test file declares for its own tests, so `ctest -L NAME` selects
// them by what they are, not by a pattern kept elsewhere:
//
//   RASTRAY_TEST_LABELS("threads");                   // every test of this file
//   RASTRAY_TEST_LABELS_OF(Suite, Name, "slow");      // one test (all its
//                                                     // instances): replaces
//                                                     // the file's labels
//
// The names (docs/TESTING.md): `slow` (seconds or more: the studies, the
// docs' examples, whole-scene sweeps), `threads` (runs the TBB-parallel
// renderers on 2 or more threads: the ThreadSanitizer stage runs these),
// `browser` (starts Chromium), `quick` (the default for a test not `slow`;
// named in a per-test declaration that takes a test of a `threads` file out
// of that label). Every test also gets its program's module label (common,
// raster, ...). An unknown name stops the test program's listing, so a typo
// cannot drop a test out of a label.
#pragma once

#include <initializer_list>

namespace rastray::test {

// Records labels for the tests defined in `file` (its __FILE__), or for the
// one test "Suite.Name" of it. Returns 0, for a static initialiser.
int declareTestLabels(const char* file, const char* test, std::initializer_list<const char*> labels);

}  // namespace rastray::test

#define RASTRAY_TEST_LABELS_CONCAT2(a, b) a##b
#define RASTRAY_TEST_LABELS_CONCAT(a, b) RASTRAY_TEST_LABELS_CONCAT2(a, b)
#define RASTRAY_TEST_LABELS(...)                                                              \
  [[maybe_unused]] static const int RASTRAY_TEST_LABELS_CONCAT(rastrayTestLabels, __LINE__) = \
      ::rastray::test::declareTestLabels(__FILE__, "", {__VA_ARGS__})
#define RASTRAY_TEST_LABELS_OF(suite, name, ...)                                              \
  [[maybe_unused]] static const int RASTRAY_TEST_LABELS_CONCAT(rastrayTestLabels, __LINE__) = \
      ::rastray::test::declareTestLabels(__FILE__, #suite "." #name, {__VA_ARGS__})
