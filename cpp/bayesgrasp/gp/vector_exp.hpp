// Short SIMD vectors of doubles (GCC vector extensions, the widest the target has) and a
// vectorised exp for non-positive arguments: the kernel values of the GP code (SE kernel:
// exp(-r2 / 2)) are made with it in batches.
#pragma once

#include <cmath>
#include <cstring>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace bayesgrasp::gp::detail {

#if defined(__AVX512F__)
constexpr int kW = 8;  // doubles per vector
#elif defined(__AVX__)
constexpr int kW = 4;
#else
constexpr int kW = 2;
#endif
typedef double vd __attribute__((vector_size(kW * sizeof(double))));

inline vd vload(const double* p) {
  vd v;
  std::memcpy(&v, p, sizeof(vd));
  return v;
}
inline void vstore(double* p, const vd& v) { std::memcpy(p, &v, sizeof(vd)); }
inline vd vbroadcast(double x) {
  vd v;
  for (int l = 0; l < kW; ++l) v[l] = x;
  return v;
}

// exp(x) for a vector of x <= 0, to a few ulp: x = (16 n' + j) ln2/16 + r with |r| <= ln2/32,
// exp(x) = 2^n' 2^(j/16) e^r, e^r by its Taylor polynomial of degree 6 (truncation below
// 5e-16 relative), 2^(j/16) from a 16-entry table. With AVX-512 the power of two is applied by
// VSCALEFPD, which also flushes exp(x) below the smallest normal to 0 without a branch; else
// x < -700 (exp(x) < 1e-304) gives 0.
struct Exp2Table {
  alignas(64) double t[16];
  Exp2Table() {
    for (int j = 0; j < 16; ++j) t[j] = std::exp2(j / 16.0);
  }
};
inline const Exp2Table kExp2Table;
typedef long long vi __attribute__((vector_size(kW * sizeof(double))));

inline vd exp_nonpositive(vd x) {
  constexpr double k16_ln2 = 23.083120654223414;            // 16 / ln 2
  constexpr double ln2_16_hi = 6.93147180369123816490e-01 / 16;  // ln2 / 16 = hi + lo, hi with
  constexpr double ln2_16_lo = 1.90821492927058770002e-10 / 16;  // trailing zero bits (n hi exact)
  constexpr double shifter = 6755399441055744.0;             // 1.5 * 2^52
#if !defined(__AVX512F__)
  const vi tiny = x < vbroadcast(-700.0);
  x = tiny ? vbroadcast(-700.0) : x;
#else
  x = x < vbroadcast(-1e12) ? vbroadcast(-1e12) : x;  // keeps n in the shifter's range
#endif
  const vd t = x * vbroadcast(k16_ln2) + vbroadcast(shifter);
  const vd nd = t - vbroadcast(shifter);  // 16 n' + j, as a double
  const vd r = (x - nd * vbroadcast(ln2_16_hi)) - nd * vbroadcast(ln2_16_lo);
  vd p = vbroadcast(1.0 / 720.0);
  p = p * r + vbroadcast(1.0 / 120.0);
  p = p * r + vbroadcast(1.0 / 24.0);
  p = p * r + vbroadcast(1.0 / 6.0);
  p = p * r + vbroadcast(0.5);
  p = p * r + vbroadcast(1.0);
  p = p * r + vbroadcast(1.0);
  vi n;
  std::memcpy(&n, &t, sizeof(vi));  // low mantissa bits of t: n = 16 n' + j (two's complement)
  vd s;
#if defined(__AVX512F__)
  // two-register permute (vpermt2pd, which reads the low 4 bits of each index) instead of a gather
  s = (vd)_mm512_permutex2var_pd(_mm512_load_pd(kExp2Table.t), (__m512i)n, _mm512_load_pd(kExp2Table.t + 8));
#else
  const vi j = n & 15;
  for (int l = 0; l < kW; ++l) s[l] = kExp2Table.t[j[l]];
#endif
  vd y = p * s;
#if defined(__AVX512F__)
  // y * 2^floor(nd / 16) = y * 2^n'
  return (vd)_mm512_scalef_pd((__m512d)y, (__m512d)(nd * vbroadcast(1.0 / 16.0)));
#else
  n -= 0x18000000000000LL;  // the shifter's mantissa bits
  vi yb;
  std::memcpy(&yb, &y, sizeof(vi));
  yb += (n >> 4) << 52;  // times 2^floor(n / 16)
  std::memcpy(&y, &yb, sizeof(vd));
  return tiny ? vbroadcast(0.0) : y;
#endif
}


/// out[i] = exp(x[i]) for n values x[i] <= 0 (in place allowed).
inline void exp_nonpositive(const double* x, double* out, long n) {
  long i = 0;
  for (; i + kW <= n; i += kW) vstore(out + i, exp_nonpositive(vload(x + i)));
  for (; i < n; ++i) out[i] = std::exp(x[i]);
}

}  // namespace bayesgrasp::gp::detail
