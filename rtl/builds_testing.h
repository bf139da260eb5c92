// Test-only: which Verilated builds exist. The sanitizer build verilates each unit's prototype
// build and the waveform test's fault build only (rtl/CMakeLists.txt says why); a test that needs
// another build (another parameter set, an injected fault) is skipped there and runs in the
// release preset.
#pragma once

#include <gtest/gtest.h>

#if defined(SAARCOR_SANITIZED)
#define SAARCOR_RTL_VARIANT_BUILDS 0
#else
#define SAARCOR_RTL_VARIANT_BUILDS 1
#endif

// In a TEST body: skip unless the variant and fault builds were verilated.
#define SAARCOR_REQUIRE_VARIANT_BUILDS()                                         \
  do {                                                                           \
    if (!SAARCOR_RTL_VARIANT_BUILDS)                                             \
      GTEST_SKIP() << "the sanitizer build verilates the prototype builds only " \
                      "(rtl/CMakeLists.txt); the release preset runs this test"; \
  } while (0)
