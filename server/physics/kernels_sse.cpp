// SSE4.1 twin of the step kernels: four balls per vector, one per lane, and
// one neighbour of each per block (kernels_simd_ball.h). See kernels.h for the
// passes and kernels_scalar.cpp for the same arithmetic one pair at a time.
//
// Against one ball's neighbours four at a time, this needs no sums over lanes,
// adds each ball's forces in list order as the scalar twin does, and serves
// four balls per instruction in walls, kick and drift; grouped by list
// length, its blocks are as full, and the blocks in which no lane touches
// need no force (on the settled tank 1.91 blocks of four per ball, 1.61 of
// them with a force, against 2.21 blocks for one ball's neighbours four at a
// time: technical report, section 4). 1/|d| comes from the
// reciprocal-square-root estimate plus a Newton step (1e-7 relative) instead
// of sqrt and divide, which the scalar twin uses, so the twins agree to float
// rounding, not bit for bit.

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
