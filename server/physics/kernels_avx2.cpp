// AVX2 + FMA level of the step kernels: eight balls per vector, one neighbour
// of each per block (kernels_simd_ball.h). Fused multiply-adds round once
// where the other variants round twice: states agree to float rounding.

#include "common/simd/avx_float8.h"
#include "server/physics/kernels_simd_ball.h"

namespace fishtank {
namespace {

using simd::F8;

template <>
struct Lanes<F8> {
  static constexpr std::uint32_t kCount = 8;
  // AVX shuffles stay within 128-bit halves: at[l] goes to lane l of the low half, at[l + 4] of the high.
  static void load(const Float4* rows, const std::uint32_t* at, F8& x, F8& y, F8& z, F8& w) {
    simd::transpose(F8::load_pair(listed(rows, at[0]), listed(rows, at[4])),
                    F8::load_pair(listed(rows, at[1]), listed(rows, at[5])),
                    F8::load_pair(listed(rows, at[2]), listed(rows, at[6])),
                    F8::load_pair(listed(rows, at[3]), listed(rows, at[7])), x, y, z, w);
  }
  static void store(F8 x, F8 y, F8 z, F8 w, Float4* rows, const std::uint32_t* at) {
    F8 a, b, c, d;
    simd::transpose(x, y, z, w, a, b, c, d);  // the transpose is its own inverse
    a.store_pair(listed(rows, at[0]), listed(rows, at[4]));
    b.store_pair(listed(rows, at[1]), listed(rows, at[5]));
    c.store_pair(listed(rows, at[2]), listed(rows, at[6]));
    d.store_pair(listed(rows, at[3]), listed(rows, at[7]));
  }
  static float largest(F8 a) { return simd::max_lane(max(a.lo(), a.hi())); }
};

}  // namespace

const Kernels kAvx2Kernels{"avx2", "avx2+fma", true, 8, step<F8>, accelerations<F8>, build_lists<8>};

}  // namespace fishtank
