#pragma once
// Thin wrapper over 256-bit AVX/FMA intrinsics: eight float lanes (F8) and a
// lane mask (M8), the wide sibling of sse_float4.h. Only the AVX2 kernels
// include it. A 256-bit register is two 128-bit halves, and the in-lane
// shuffles act on each half separately, so "rows" here are pairs of Float4
// (one in each half) and a transpose yields lanes in the order
// (row0.lo, row1.lo, row2.lo, row3.lo, row0.hi, row1.hi, row2.hi, row3.hi).

#include <immintrin.h>

#include "common/float4.h"
#include "common/simd/isa_namespace.h"
#include "common/simd/sse_float4.h"

namespace fishtank::simd {
inline namespace FISHTANK_SIMD_ISA_NAMESPACE {

struct M8 {
  __m256 v;
};

struct F8 {
  __m256 v;

  static F8 splat(float s) { return {_mm256_set1_ps(s)}; }
  static F8 zero() { return {_mm256_setzero_ps()}; }
  // Eight floats stored as their bits (32-byte aligned); the intrinsic's load may alias any type.
  static F8 load_bits(const std::uint32_t* bits) { return {_mm256_load_ps(reinterpret_cast<const float*>(bits))}; }
  // lo in the low half, hi in the high half: two aligned loads.
  static F8 load_pair(const Float4& lo, const Float4& hi) {
    return {_mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(&lo.x)), _mm_load_ps(&hi.x), 1)};
  }
  F4 lo() const { return {_mm256_castps256_ps128(v)}; }
  F4 hi() const { return {_mm256_extractf128_ps(v, 1)}; }
  // The low half to lo, the high half to hi: two aligned stores.
  void store_pair(Float4& lo_out, Float4& hi_out) const {
    _mm_store_ps(&lo_out.x, lo().v);
    _mm_store_ps(&hi_out.x, hi().v);
  }
};

inline F8 operator+(F8 a, F8 b) { return {_mm256_add_ps(a.v, b.v)}; }
inline F8 operator-(F8 a, F8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
inline F8 operator*(F8 a, F8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
inline F8 operator/(F8 a, F8 b) { return {_mm256_div_ps(a.v, b.v)}; }
inline F8& operator+=(F8& a, F8 b) { return a = a + b; }
inline F8& operator-=(F8& a, F8 b) { return a = a - b; }
inline F8 sqrt(F8 a) { return {_mm256_sqrt_ps(a.v)}; }
// a * b + c in one rounding.
inline F8 mul_add(F8 a, F8 b, F8 c) { return {_mm256_fmadd_ps(a.v, b.v, c.v)}; }
// c - a * b in one rounding.
inline F8 neg_mul_add(F8 a, F8 b, F8 c) { return {_mm256_fnmadd_ps(a.v, b.v, c.v)}; }
// 1/sqrt(a) to about 1e-7 relative: the 12-bit estimate plus one Newton step,
// r (1.5 - a r^2 / 2), as in sse_float4.h.
inline F8 rsqrt(F8 a) {
  __m256 r = _mm256_rsqrt_ps(a.v);
  __m256 neg_half_a_r2 = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(-0.5f), a.v), _mm256_mul_ps(r, r));
  return {_mm256_mul_ps(r, _mm256_add_ps(neg_half_a_r2, _mm256_set1_ps(1.5f)))};
}
inline F8 max(F8 a, F8 b) { return {_mm256_max_ps(a.v, b.v)}; }
inline F8 min(F8 a, F8 b) { return {_mm256_min_ps(a.v, b.v)}; }
inline F8 abs(F8 a) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.v)}; }  // clears the sign bit
inline M8 operator<(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
inline M8 operator>(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
inline M8 operator==(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
inline M8 operator|(M8 a, M8 b) { return {_mm256_or_ps(a.v, b.v)}; }
inline M8 operator&(M8 a, M8 b) { return {_mm256_and_ps(a.v, b.v)}; }
inline bool any(M8 m) { return _mm256_movemask_ps(m.v) != 0; }
inline int bits(M8 m) { return _mm256_movemask_ps(m.v); }  // lane L's flag in bit L
// Lanes where the mask is off become zero.
inline F8 keep(M8 m, F8 a) { return {_mm256_and_ps(m.v, a.v)}; }
// a where the mask is on, b elsewhere.
inline F8 select(M8 m, F8 a, F8 b) { return {_mm256_blendv_ps(b.v, a.v, m.v)}; }

// Four rows of two Float4 each become columns: xs, ys, zs, ws of the eight.
inline void transpose(F8 a, F8 b, F8 c, F8 d, F8& xs, F8& ys, F8& zs, F8& ws) {
  __m256 t0 = _mm256_unpacklo_ps(a.v, b.v);  // ax bx ay by, per half
  __m256 t1 = _mm256_unpacklo_ps(c.v, d.v);  // cx dx cy dy
  __m256 t2 = _mm256_unpackhi_ps(a.v, b.v);  // az bz aw bw
  __m256 t3 = _mm256_unpackhi_ps(c.v, d.v);  // cz dz cw dw
  xs.v = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0));
  ys.v = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2));
  zs.v = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0));
  ws.v = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

}  // namespace FISHTANK_SIMD_ISA_NAMESPACE
}  // namespace fishtank::simd
