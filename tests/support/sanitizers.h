#pragma once
// Tests that check what a long computation comes to (a training's scores, a registration to a subpixel) run
// in the release tree only. Under the sanitizers each costs 20-50 s of CI's wait while checking no memory
// access or undefined behaviour that the shorter tests of the same code (named at each use) do not already
// check.
#include <gtest/gtest.h>

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif

// In a test body: skips the test under the sanitizers, saying so in the test's output.
#define LUMIGAUSS_OUTCOME_ONLY_IN_RELEASE()                                      \
    if (kSanitizedBuild)                                                         \
    GTEST_SKIP() << "an outcome check of a long computation: release tree only " \
                    "(tests/support/sanitizers.h)"
