// The instruction set a renderer kernel file is compiled for (raster.h, "Kernels").
//
// Each kernel file (nearest.cc, shade.cc, supersample.cc) is compiled twice: as itself, for the
// baseline of the target (SSE2 on x86-64), and included by kernels_avx2.cc, which defines
// MAPLESS_SIM_KERNELS_AVX2 first. The kernel functions then live in namespace
// raster::MAPLESS_KERNEL_NS and carry MAPLESS_KERNEL, the function attribute that lets the
// compiler use AVX2 in them. Only functions so marked use AVX2: the inline functions of headers
// (the standard library's, OpenCV's, FastLog2) stay baseline code wherever they are not inlined,
// so no out-of-line copy the linker might share with baseline code needs AVX2.
//
// AVX2 does not include FMA, so the compiler cannot fuse a multiply and an add: every float
// operation rounds as in the baseline build, lane by lane, and both builds of a kernel give the
// same bytes (`RendererKernels.Avx2KernelsGiveTheBaselineBytes`).
#pragma once

#if defined(MAPLESS_SIM_KERNELS_AVX2)
#define MAPLESS_KERNEL_NS avx2
#define MAPLESS_KERNEL __attribute__((target("avx2")))
#else
#define MAPLESS_KERNEL_NS baseline
#define MAPLESS_KERNEL
#endif
