// The sanitized build (-DSURFTRACK_SANITIZE=ON, run by scripts/ci-checks.sh) runs every test, but
// several times slower than the normal build. There the exhaustive and randomized tests check a
// fixed subset of their cases, about one in kCaseStride, picked by a hash of the case number so
// that the subset is spread over the configurations rather than a prefix of them: every code path
// those tests reach still runs under the sanitizers. The normal build checks every case.
// Tests of one whole volume take a smaller one there (inputSize).
#pragma once

#include <cstdint>

namespace surftrack::testing {

#ifdef SURFTRACK_SANITIZED
inline constexpr bool kSanitizedBuild = true;
inline constexpr unsigned kCaseStride = 8;
#else
inline constexpr bool kSanitizedBuild = false;
inline constexpr unsigned kCaseStride = 1;
#endif

/// The size of a test's input: `normal` in the normal build, the smaller `sanitized` in the
/// sanitized one (for the tests whose one input is a whole volume rather than many cases).
constexpr int inputSize(int normal, int sanitized) { return kSanitizedBuild ? sanitized : normal; }

/// Whether case i is checked in this build: always in the normal build; case 0 and about one in
/// kCaseStride of the others (splitmix64 of i) in the sanitized build.
inline bool caseChecked(std::uint64_t i) {
  if (kCaseStride == 1 || i == 0) return true;
  std::uint64_t z = i + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return (z ^ (z >> 31)) % kCaseStride == 0;
}

/// A lower bound on a total over all cases, scaled for the subset (with a margin of two for the
/// hash's spread); the bound itself in the normal build.
constexpr std::uint64_t subsetMinimum(std::uint64_t bound) { return bound / (2 * kCaseStride - 1); }

}  // namespace surftrack::testing
