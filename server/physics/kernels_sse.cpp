// SSE4.1 twin of the step kernels: four balls per vector, one neighbour of
// each per block (kernels_simd_ball.h). Four balls rather than one ball's four
// neighbours: no sums across lanes, forces added in the scalar twin's order.
// 1/|d| is an estimate with a Newton step, so the twins agree to float rounding.

#include "server/physics/kernels_simd_ball.h"

namespace fishtank {
namespace {

template <>
struct Lanes<F4> {
  static constexpr std::uint32_t kCount = 4;
  static void load(const Float4* rows, const std::uint32_t* at, F4& x, F4& y, F4& z, F4& w) {
    simd::transpose(F4::load(listed(rows, at[0])), F4::load(listed(rows, at[1])), F4::load(listed(rows, at[2])),
                    F4::load(listed(rows, at[3])), x, y, z, w);
  }
  static void store(F4 x, F4 y, F4 z, F4 w, Float4* rows, const std::uint32_t* at) {
    F4 a, b, c, d;
    simd::transpose(x, y, z, w, a, b, c, d);  // the transpose is its own inverse
    a.store(listed(rows, at[0]));
    b.store(listed(rows, at[1]));
    c.store(listed(rows, at[2]));
    d.store(listed(rows, at[3]));
  }
  static float largest(F4 a) { return simd::max_lane(a); }
};

}  // namespace

const Kernels kSseKernels{"sse", "sse4.1", true, 4, step<F4>, accelerations<F4>, build_lists<4>};

}  // namespace fishtank
