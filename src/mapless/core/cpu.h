// What the CPU the process runs on can do, for the kernels built twice (the renderer's, the dense
// LK's): the baseline build everywhere, an AVX2 build chosen at run time where this says so.
#pragma once

namespace mapless {

// True on an x86-64 CPU (and operating system) that runs AVX2; false elsewhere (ARM, other
// compilers). Asked once, then remembered.
bool CpuHasAvx2();

}  // namespace mapless
