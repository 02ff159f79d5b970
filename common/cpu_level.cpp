// SPDX-License-Identifier: Apache-2.0
#include "common/cpu_level.h"

namespace mogao {

bool cpu_has_x86_64_v3() {
#if MOGAO_HAS_X86_64_V3
    // libgcc reads CPUID (and XGETBV for the AVX state) in a constructor; this may run before it.
    __builtin_cpu_init();
    return __builtin_cpu_supports("x86-64-v3") != 0;
#else
    return false;
#endif
}

}  // namespace mogao
