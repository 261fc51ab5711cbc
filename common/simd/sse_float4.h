#pragma once
// Thin, explicit wrapper over SSE4.1 intrinsics: four float lanes (F4), a
// lane mask (M4) and four indices (I4). Only the SIMD kernels include this;
// the scalar twins are plain C++. Every operation maps to one or two
// instructions, so the kernels read as arithmetic while the generated code
// stays predictable.

#include <smmintrin.h>

#include <cstdint>

#include "common/float4.h"
#include "common/simd/isa_namespace.h"

namespace fishtank::simd {
inline namespace FISHTANK_SIMD_ISA_NAMESPACE {

struct M4 {
  __m128 v;
};

struct F4 {
  __m128 v;

  static F4 splat(float s) { return {_mm_set1_ps(s)}; }
  static F4 zero() { return {_mm_setzero_ps()}; }
  static F4 load(const Float4& f) { return {_mm_load_ps(&f.x)}; }
  static F4 loadu(const float* f) { return {_mm_loadu_ps(f)}; }
  // Four floats stored as their bits (16-byte aligned); the intrinsic's load may alias any type.
  static F4 load_bits(const std::uint32_t* bits) { return {_mm_load_ps(reinterpret_cast<const float*>(bits))}; }
  void store(Float4& f) const { _mm_store_ps(&f.x, v); }
  void storeu(float* f) const { _mm_storeu_ps(f, v); }
};

inline F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
inline F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
inline F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
inline F4 operator/(F4 a, F4 b) { return {_mm_div_ps(a.v, b.v)}; }
inline F4& operator+=(F4& a, F4 b) { return a = a + b; }
inline F4& operator-=(F4& a, F4 b) { return a = a - b; }
inline F4 sqrt(F4 a) { return {_mm_sqrt_ps(a.v)}; }
// 1/sqrt(a) to about 1e-7 relative: the 12-bit estimate plus one Newton step,
// r (1.5 - a r^2 / 2). Written as (-a/2) r^2 + 1.5, the same bits, so that
// SSE's two-operand add takes 1.5 from memory instead of a register copy.
inline F4 rsqrt(F4 a) {
  __m128 r = _mm_rsqrt_ps(a.v);
  __m128 neg_half_a_r2 = _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(-0.5f), a.v), _mm_mul_ps(r, r));
  return {_mm_mul_ps(r, _mm_add_ps(neg_half_a_r2, _mm_set1_ps(1.5f)))};
}
inline F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }
inline F4 min(F4 a, F4 b) { return {_mm_min_ps(a.v, b.v)}; }
inline F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }  // clears the sign bit
// a * b + c, rounded twice as in the scalar twin: SSE4.1 has no fused form.
inline F4 mul_add(F4 a, F4 b, F4 c) { return a * b + c; }
// c - a * b, rounded twice.
inline F4 neg_mul_add(F4 a, F4 b, F4 c) { return c - a * b; }
// The largest of the four lanes.
inline float max_lane(F4 a) {
  const __m128 m = _mm_max_ps(a.v, _mm_movehl_ps(a.v, a.v));  // max(0, 2), max(1, 3)
  return _mm_cvtss_f32(_mm_max_ss(m, _mm_shuffle_ps(m, m, 1)));
}
inline M4 operator<(F4 a, F4 b) { return {_mm_cmplt_ps(a.v, b.v)}; }
inline M4 operator>(F4 a, F4 b) { return {_mm_cmpgt_ps(a.v, b.v)}; }
inline M4 operator==(F4 a, F4 b) { return {_mm_cmpeq_ps(a.v, b.v)}; }
inline M4 operator|(M4 a, M4 b) { return {_mm_or_ps(a.v, b.v)}; }
inline M4 operator&(M4 a, M4 b) { return {_mm_and_ps(a.v, b.v)}; }
inline bool any(M4 m) { return _mm_movemask_ps(m.v) != 0; }
// Lanes where the mask is off become zero.
inline F4 keep(M4 m, F4 a) { return {_mm_and_ps(m.v, a.v)}; }
// a where the mask is on, b elsewhere.
inline F4 select(M4 m, F4 a, F4 b) { return {_mm_blendv_ps(b.v, a.v, m.v)}; }

// Rows a,b,c,d (each x,y,z,w) become columns: xs, ys, zs, ws of the four.
inline void transpose(F4 a, F4 b, F4 c, F4 d, F4& xs, F4& ys, F4& zs, F4& ws) {
  __m128 t0 = _mm_unpacklo_ps(a.v, b.v);  // ax bx ay by
  __m128 t1 = _mm_unpacklo_ps(c.v, d.v);  // cx dx cy dy
  __m128 t2 = _mm_unpackhi_ps(a.v, b.v);  // az bz aw bw
  __m128 t3 = _mm_unpackhi_ps(c.v, d.v);  // cz dz cw dw
  xs.v = _mm_movelh_ps(t0, t1);
  ys.v = _mm_movehl_ps(t1, t0);
  zs.v = _mm_movelh_ps(t2, t3);
  ws.v = _mm_movehl_ps(t3, t2);
}

inline int bits(M4 m) { return _mm_movemask_ps(m.v); }  // lane L's flag in bit L

// Four 32-bit indices, for building lists.
struct I4 {
  __m128i v;
  static I4 iota(std::uint32_t first) {  // first, first + 1, first + 2, first + 3
    return {_mm_add_epi32(_mm_set1_epi32(static_cast<int>(first)), _mm_setr_epi32(0, 1, 2, 3))};
  }
  static I4 splat(std::uint32_t s) { return {_mm_set1_epi32(static_cast<int>(s))}; }
  void store(std::uint32_t* out) const { _mm_store_si128(reinterpret_cast<__m128i*>(out), v); }
};

// counts plus one in the lanes where m is set (a set lane is all ones: -1).
inline I4 count_where(M4 m, I4 counts) { return {_mm_sub_epi32(counts.v, _mm_castps_si128(m.v))}; }

// The lanes of a whose bit is set in mask, packed to the front in lane order
// and stored at out; all 16 bytes are written, whatever the count.
inline void compress_store(I4 a, int mask, std::uint32_t* out) {
  // Byte shuffles that gather the chosen 32-bit lanes, one per 4-bit mask.
  alignas(16) static constexpr std::uint8_t kGather[16][16] = {
      {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},       {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
      {4, 5, 6, 7, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},       {0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 0, 1, 2, 3},
      {8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},     {0, 1, 2, 3, 8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3},
      {4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3},     {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 2, 3},
      {12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},   {0, 1, 2, 3, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
      {4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},   {0, 1, 2, 3, 4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3},
      {8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3}, {0, 1, 2, 3, 8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3},
      {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3}, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
  };
  const __m128i gather = _mm_load_si128(reinterpret_cast<const __m128i*>(kGather[mask]));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_shuffle_epi8(a.v, gather));
}

// The same for floats (the intrinsic's store may alias any type).
inline void compress_store(F4 a, int mask, float* out) {
  compress_store(I4{_mm_castps_si128(a.v)}, mask, reinterpret_cast<std::uint32_t*>(out));
}

}  // namespace FISHTANK_SIMD_ISA_NAMESPACE
}  // namespace fishtank::simd
