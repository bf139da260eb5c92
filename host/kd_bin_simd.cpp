// The binned stage's two kernels (kd_binning.cpp holds the stage's logic): the histogram fill,
// one pass over a node's items binning their bounds on all three axes, and the sweep over the
// bin planes of all three axes at once. Each has a portable form and a vector form that computes
// the same values in the same order: the bins and planes, and so the trees, do not depend on
// which one ran.
#include <algorithm>
#include <cstddef>

#include "host/kd_builder.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if SAARCOR_KD_AVX
#include <immintrin.h>
#endif

namespace saarcor::host::kd {
namespace {

void zero_bins(const BinGrid& g, BinHist& hist_lo, BinHist& hist_hi) {
  std::fill(&hist_lo[0][0], &hist_lo[0][0] + g.nb_max * kHistLanes, 0u);
  std::fill(&hist_hi[0][0], &hist_hi[0][0] + g.nb_max * kHistLanes, 0u);
}

#if defined(__SSE2__)
// The three lanes' byte offsets of vector o (bin * 16 + lane * 4) into off[0..2].
inline void lane_offsets(__m128i o, std::uint32_t off[3]) {
#if defined(__x86_64__)
  const auto o01 = static_cast<std::uint64_t>(_mm_cvtsi128_si64(o));
  off[0] = static_cast<std::uint32_t>(o01);
  off[1] = static_cast<std::uint32_t>(o01 >> 32);
  off[2] = static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_unpackhi_epi64(o, o)));
#else
  alignas(16) std::uint32_t idx[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(idx), o);
  off[0] = idx[0];
  off[1] = idx[1];
  off[2] = idx[2];
#endif
}

// The same arithmetic as fill_bins_scalar four lanes at a time (IEEE single): lanes lo0 lo1 lo2
// key0 and key0 key1 key2 id (id lane: times 0, unused).
void fill_bins_sse(const BinGrid& g, const BinItem* items, std::uint32_t n, BinHist& hist_lo,
                   BinHist& hist_hi, float tlo[3], float tkey[3]) {
  static_assert(sizeof(BinItem) == 32 && offsetof(BinItem, key) == 12);
  const __m128 base_a = _mm_setr_ps(g.base[0], g.base[1], g.base[2], g.base[0]);
  const __m128 scale_a = _mm_setr_ps(g.scale[0], g.scale[1], g.scale[2], 0.0f);
  const __m128 top_a = _mm_setr_ps(g.top[0], g.top[1], g.top[2], 0.0f);
  const __m128 zero = _mm_setzero_ps();
  __m128 vlo = _mm_set1_ps(std::numeric_limits<float>::infinity());
  __m128 vkey = _mm_set1_ps(-std::numeric_limits<float>::infinity());
  const __m128i lane_bytes = _mm_setr_epi32(0, 4, 8, 12);
  auto* lo_bytes = reinterpret_cast<unsigned char*>(&hist_lo[0][0]);
  auto* hi_bytes = reinterpret_cast<unsigned char*>(&hist_hi[0][0]);
  for (std::uint32_t i = 0; i < n; ++i) {
    const float* p = items[i].lo;
    const __m128 a = _mm_loadu_ps(p);
    const __m128 c = _mm_loadu_ps(p + 3);
    vlo = _mm_min_ps(vlo, a);
    vkey = _mm_max_ps(vkey, c);
    const __m128 fa =
        _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(a, base_a), scale_a), zero), top_a);
    const __m128 fc =
        _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(c, base_a), scale_a), zero), top_a);
    // Byte offsets into the histograms (bin * 16 + lane * 4) computed in the register, so that
    // each increment needs no index arithmetic of its own.
    std::uint32_t off[6];
    lane_offsets(_mm_add_epi32(_mm_slli_epi32(_mm_cvttps_epi32(fa), 4), lane_bytes), off);
    lane_offsets(_mm_add_epi32(_mm_slli_epi32(_mm_cvttps_epi32(fc), 4), lane_bytes), off + 3);
    for (int k = 0; k < 3; ++k) {
      ++*reinterpret_cast<std::uint32_t*>(lo_bytes + off[k]);
      ++*reinterpret_cast<std::uint32_t*>(hi_bytes + off[3 + k]);
    }
  }
  alignas(16) float l4[4];
  alignas(16) float k4[4];
  _mm_store_ps(l4, vlo);
  _mm_store_ps(k4, vkey);
  for (int k = 0; k < 3; ++k) {
    tlo[k] = l4[k];
    tkey[k] = k4[k];
  }
}
#else
void fill_bins_scalar(const BinGrid& g, const BinItem* items, std::uint32_t n, BinHist& hist_lo,
                      BinHist& hist_hi, float tlo[3], float tkey[3]) {
  for (int k = 0; k < 3; ++k) {
    tlo[k] = std::numeric_limits<float>::infinity();
    tkey[k] = -std::numeric_limits<float>::infinity();
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const BinItem& it = items[i];
    for (int k = 0; k < 3; ++k) {
      const float lo = it.lo[k];
      const float key = it.key[k];
      tlo[k] = std::min(tlo[k], lo);
      tkey[k] = std::max(tkey[k], key);
      const int j =
          static_cast<int>(std::min(std::max((lo - g.base[k]) * g.scale[k], 0.0f), g.top[k]));
      const int h =
          static_cast<int>(std::min(std::max((key - g.base[k]) * g.scale[k], 0.0f), g.top[k]));
      ++hist_lo[j][k];
      ++hist_hi[h][k];
    }
  }
}
#endif

// One axis's sweep over its bin planes (find_binned_split): the children's half areas step by
// da, the counts by the histograms. A plane with an empty side is never better than the
// empty-space plane at the items' bound below, so only planes with items on both sides are
// weighed, without the bonus: compared as aL * nL + aR * nR (the even position is within a
// quarter bin of s_j); the first least one is kept (its counts are summed again once it wins).
struct BinScan {
  const std::uint32_t* hist_lo;  // this axis's lane of BinHist (stride kHistLanes)
  const std::uint32_t* hist_hi;
  int nc = 0;
  double da = 0.0;
  double al = 0.0;
  double ar = 0.0;
  std::uint32_t nl = 0;
  std::uint32_t not_right = 0;
  double best_m = std::numeric_limits<double>::infinity();
  int best_j = -1;
  void step(int j, std::uint32_t n) {
    nl += hist_lo[j * kHistLanes];
    not_right += hist_hi[j * kHistLanes];
    al += da;
    ar -= da;
    const std::uint32_t nr = n - not_right;
    const double m = al * nl + ar * nr;
    const bool better = (nl != 0) & (nr != 0) & (m < best_m);
    best_m = better ? m : best_m;
    best_j = better ? j : best_j;
  }
};

// The portable sweep: three BinScans side by side (three independent chains of additions: each
// axis's half areas step by repeated addition, so one axis alone waits on its adds).
void sweep_bins_portable(const BinHist& hist_lo, const BinHist& hist_hi, std::uint32_t n,
                         BinSweep& sw) {
  BinScan sc[3] = {{&hist_lo[0][0], &hist_hi[0][0]},
                   {&hist_lo[0][1], &hist_hi[0][1]},
                   {&hist_lo[0][2], &hist_hi[0][2]}};
  for (int k = 0; k < 3; ++k) {
    sc[k].nc = sw.nc[k];
    sc[k].da = sw.da[k];
    sc[k].al = sw.al[k];
    sc[k].ar = sw.ar[k];
  }
  const int nc_common = std::min({sc[0].nc, sc[1].nc, sc[2].nc});
  for (int j = 0; j < nc_common; ++j) {
    sc[0].step(j, n);
    sc[1].step(j, n);
    sc[2].step(j, n);
  }
  for (int k = 0; k < 3; ++k) {
    for (int j = nc_common; j < sc[k].nc; ++j)
      sc[k].step(j, n);
    sw.best_m[k] = sc[k].best_m;
    sw.best_j[k] = sc[k].best_j;
  }
}

#if SAARCOR_KD_AVX
// The same sweep with the three axes in one 256-bit register (lane k = axis k): each lane the
// step's binary64 operations in the same order (counts are exact integers either way), the least
// value kept by a min and its index following it where the value drops strictly: the same
// planes. Every lane runs to the longest axis's last plane: from an axis's own last bin on its
// right count is 0 (every key lies in a bin below nb[k]; the histograms are zero above), which
// rules those planes out as the step does, and a flat axis (all items in bin 0) never has one.
__attribute__((target("avx"))) void sweep_bins_avx(const BinHist& hist_lo, const BinHist& hist_hi,
                                                   int nb_max, std::uint32_t n, BinSweep& sw) {
  // The plane index as a double, loaded per plane instead of counted in a register.
  static const auto kIndex = [] {
    std::array<double, kMaxBins> idx{};
    for (int j = 0; j < kMaxBins; ++j) {
      idx[j] = j;
    }
    return idx;
  }();
  const __m256d da = _mm256_setr_pd(sw.da[0], sw.da[1], sw.da[2], 0.0);
  const __m256d zero = _mm256_setzero_pd();
  __m256d al = _mm256_setr_pd(sw.al[0], sw.al[1], sw.al[2], 0.0);
  __m256d ar = _mm256_setr_pd(sw.ar[0], sw.ar[1], sw.ar[2], 0.0);
  __m128i nl = _mm_setzero_si128();
  __m128i nr = _mm_set1_epi32(static_cast<int>(n));
  __m256d bm = _mm256_set1_pd(std::numeric_limits<double>::infinity());
  __m256d bj = _mm256_set1_pd(-1.0);
  // Few registers, so that the running minimum stays in one (with sixteen live values GCC kept
  // it on the stack: a store and a reload in the loop's chain). A plane with an empty side gets
  // an all-ones pattern (a NaN) instead of infinity: min(NaN, best) is best and NaN < best is
  // false, as inf would give; the other planes' values pass unchanged (m | 0).
  for (int j = 0; j + 1 < nb_max; ++j) {
    nl = _mm_add_epi32(nl, _mm_load_si128(reinterpret_cast<const __m128i*>(hist_lo[j])));
    nr = _mm_sub_epi32(nr, _mm_load_si128(reinterpret_cast<const __m128i*>(hist_hi[j])));
    const __m256d nld = _mm256_cvtepi32_pd(nl);
    const __m256d nrd = _mm256_cvtepi32_pd(nr);
    al = _mm256_add_pd(al, da);
    ar = _mm256_sub_pd(ar, da);
    const __m256d m = _mm256_add_pd(_mm256_mul_pd(al, nld), _mm256_mul_pd(ar, nrd));
    const __m256d empty =
        _mm256_or_pd(_mm256_cmp_pd(nld, zero, _CMP_EQ_OQ), _mm256_cmp_pd(nrd, zero, _CMP_EQ_OQ));
    const __m256d mv = _mm256_or_pd(m, empty);
    const __m256d lt = _mm256_cmp_pd(mv, bm, _CMP_LT_OQ);
    // Selections as and / andnot / or: GCC turns blendv on a comparison into per-lane branches.
    bj = _mm256_or_pd(_mm256_and_pd(lt, _mm256_broadcast_sd(&kIndex[j])), _mm256_andnot_pd(lt, bj));
    bm = _mm256_min_pd(mv, bm);
  }
  // Lanes taken out by shuffles: stored to an array, the minimum's register shared the array's
  // stack slot and the loop kept it there (a store and a reload per plane).
  const __m128d m01 = _mm256_castpd256_pd128(bm);
  const __m128d m23 = _mm256_extractf128_pd(bm, 1);
  const __m128d j01 = _mm256_castpd256_pd128(bj);
  const __m128d j23 = _mm256_extractf128_pd(bj, 1);
  sw.best_m[0] = _mm_cvtsd_f64(m01);
  sw.best_m[1] = _mm_cvtsd_f64(_mm_unpackhi_pd(m01, m01));
  sw.best_m[2] = _mm_cvtsd_f64(m23);
  sw.best_j[0] = static_cast<int>(_mm_cvtsd_f64(j01));
  sw.best_j[1] = static_cast<int>(_mm_cvtsd_f64(_mm_unpackhi_pd(j01, j01)));
  sw.best_j[2] = static_cast<int>(_mm_cvtsd_f64(j23));
}
#endif

}  // namespace

void fill_bins(const BinGrid& g, const BinItem* items, std::uint32_t n, BinHist& hist_lo,
               BinHist& hist_hi, float tlo[3], float tkey[3]) {
  zero_bins(g, hist_lo, hist_hi);
#if defined(__SSE2__)
  fill_bins_sse(g, items, n, hist_lo, hist_hi, tlo, tkey);
#else
  fill_bins_scalar(g, items, n, hist_lo, hist_hi, tlo, tkey);
#endif
}

void sweep_bins(const BinHist& hist_lo, const BinHist& hist_hi, int nb_max, std::uint32_t n,
                BinSweep& sw) {
#if SAARCOR_KD_AVX
  static const bool avx = __builtin_cpu_supports("avx");
  if (avx) {
    sweep_bins_avx(hist_lo, hist_hi, nb_max, n, sw);
    return;
  }
#endif
  (void)nb_max;
  sweep_bins_portable(hist_lo, hist_hi, n, sw);
}

}  // namespace saarcor::host::kd
