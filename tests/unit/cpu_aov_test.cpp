// film.aovs on the CPU reference: the bodies are tests/support/AovSuite.h.
#include "support/AovSuite.h"

namespace pyrolume::test {
INSTANTIATE_BACKEND_SUITE(Aovs, "cpu");
}  // namespace pyrolume::test
