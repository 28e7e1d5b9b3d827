// The renderer's kernel files compiled for AVX2 (kernel_target.h); nothing on other targets.
#if defined(__x86_64__) || defined(__i386__)
#define MAPLESS_SIM_KERNELS_AVX2
#include "mapless/sim/nearest.cc"      // NOLINT(bugprone-suspicious-include)
#include "mapless/sim/shade.cc"        // NOLINT(bugprone-suspicious-include)
#include "mapless/sim/supersample.cc"  // NOLINT(bugprone-suspicious-include)
#endif
