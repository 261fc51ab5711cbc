#pragma once
// The SIMD wrappers are compiled once per instruction set (kernels_sse.cpp
// with -msse4.1, kernels_avx2.cpp with -mavx2). Their inline functions live
// in an inline namespace named after the set, so each file's copies get
// their own symbols: where the compiler keeps a copy out of line (a debug
// build), the linker can never hand the AVX2 copy to the SSE kernels and
// crash a processor without AVX2.

#if defined(__AVX2__)
#define FISHTANK_SIMD_ISA_NAMESPACE avx2
#else
#define FISHTANK_SIMD_ISA_NAMESPACE sse41
#endif
