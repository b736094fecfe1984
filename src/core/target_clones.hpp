#pragma once
// IBROD_TARGET_CLONES: put on a hot, vectorisable function to get an AVX2+FMA clone next to the
// baseline x86-64 one, chosen once by the loader on the running CPU. The default x86-64 target has
// only 2-wide SSE2 vectors, while FFTW picks AVX kernels at run time, so without clones our own
// grid passes would run at half the vector width of the FFTs beside them. FMA changes round-off
// only (like FFTW's own run-time choice of kernels). A -march=native build (IBROD_NATIVE) or a
// compiler without target_clones gets the plain function.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX2__)
#define IBROD_TARGET_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define IBROD_TARGET_CLONES
#endif
