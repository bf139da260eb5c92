// The exact stage's events (Wald & Havran 2006): sorted once per subtree, split into the
// children's lists in order at every node, and made anew only for the straddlers' clipped bounds.
#include <algorithm>

#include "host/kd_builder.h"
#if SAARCOR_KD_AVX
#include <immintrin.h>
#endif

namespace saarcor::host::kd {
namespace {

// The exact stage's leaf decisions sort a few events per axis, hundreds of thousands of times:
// by ranks (each key's count of smaller keys; keys are unique, one event per type and item), with
// no branch on the keys. n <= kRankSortMax.
constexpr std::size_t kRankSortMax = 32;
void rank_sort_scalar(Key* data, std::size_t n) {
  Key sorted[kRankSortMax];
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t rank = 0;
    for (std::size_t j = 0; j < n; ++j) {
      rank += data[j] < data[i];
    }
    sorted[rank] = data[i];
  }
  std::copy(sorted, sorted + n, data);
}
#if SAARCOR_KD_AVX
// The same ranks four comparisons at a time where the processor has AVX2 (signed 64-bit compares
// on keys with the top bit flipped; the slots past n hold the largest value, never below a key).
__attribute__((target("avx2"))) void rank_sort_avx2(Key* data, std::size_t n) {
  constexpr std::size_t kLanes = 4;
  alignas(32) Key biased[kRankSortMax];
  const std::size_t groups = (n + kLanes - 1) / kLanes;
  constexpr Key kFlip = Key{1} << 63;
  for (std::size_t i = 0; i < groups * kLanes; ++i) {
    biased[i] = i < n ? data[i] ^ kFlip : ~kFlip;
  }
  Key sorted[kRankSortMax];
  for (std::size_t i = 0; i < n; ++i) {
    const __m256i x = _mm256_set1_epi64x(static_cast<long long>(biased[i]));
    __m256i count = _mm256_setzero_si256();
    for (std::size_t g = 0; g < groups; ++g) {
      const __m256i v = _mm256_load_si256(reinterpret_cast<const __m256i*>(biased + g * kLanes));
      count = _mm256_sub_epi64(count, _mm256_cmpgt_epi64(x, v));  // -1 where v < x
    }
    const __m128i c2 =
        _mm_add_epi64(_mm256_castsi256_si128(count), _mm256_extracti128_si256(count, 1));
    const auto rank =
        static_cast<std::size_t>(_mm_cvtsi128_si64(_mm_add_epi64(c2, _mm_unpackhi_epi64(c2, c2))));
    sorted[rank] = data[i];
  }
  std::copy(sorted, sorted + n, data);
}
#endif
void rank_sort(Key* data, std::size_t n) {
#if SAARCOR_KD_AVX
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) {
    rank_sort_avx2(data, n);
    return;
  }
#endif
  rank_sort_scalar(data, n);
}

}  // namespace

void radix_sort(Key* data, std::size_t n, std::vector<Key>& scratch) {
  constexpr int kDigit = 12;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  if (n <= kRankSortMax) {
    rank_sort(data, n);
    return;
  }
  if (n < 1024) {  // the 4096-bucket passes cost more than a comparison sort here
    std::sort(data, data + n);
    return;
  }
  scratch.resize(n);
  Key* src = data;
  Key* dst = scratch.data();
  std::vector<std::size_t> count(kBuckets);
  for (int shift = kIdBits; shift < 64; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < n; ++i)
      ++count[(src[i] >> shift) & (kBuckets - 1)];
    if (count[(src[0] >> shift) & (kBuckets - 1)] == n) continue;  // one bucket: nothing to do
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t t = c;
      c = sum;
      sum += t;
    }
    for (std::size_t i = 0; i < n; ++i)
      dst[count[(src[i] >> shift) & (kBuckets - 1)]++] = src[i];
    std::swap(src, dst);
  }
  if (src != data) std::copy(src, src + n, data);
}

std::size_t split_events(const Key* ev, std::size_t n, const std::uint8_t* side,
                         const std::vector<Key>& add_left, const std::vector<Key>& add_right,
                         Key* left, Key* right, std::size_t* right_count) {
  constexpr Key kNone = ~Key{0};  // sentinel above every real key
  const Key* al = add_left.data();
  const Key* al_end = al + add_left.size();
  const Key* ar = add_right.data();
  const Key* ar_end = ar + add_right.size();
  Key next_l = al < al_end ? *al : kNone;
  Key next_r = ar < ar_end ? *ar : kNone;
  std::size_t l = 0;
  std::size_t r = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Key key = ev[i];
    // New events that sort before this one (rare: predictable branches).
    while (next_l < key) {
      left[l++] = next_l;
      next_l = ++al < al_end ? *al : kNone;
    }
    while (next_r < key) {
      right[r++] = next_r;
      next_r = ++ar < ar_end ? *ar : kNone;
    }
    // Branch-free filter: written to both outputs, the cursors advance only for the item's
    // side (straddlers advance neither).
    const std::uint8_t s = side[key_id(key)];
    left[l] = key;
    right[r] = key;
    l += s & 1u;
    r += s >> 1;
  }
  while (al < al_end)
    left[l++] = *al++;
  while (ar < ar_end)
    right[r++] = *ar++;
  *right_count = r;
  return l;
}

// A straddler's piece in one child: its clipped bounds rounded outward onto the grid, as one
// planar event or a start and an end per axis (appended unsorted to out[axis]).
void Builder::add_clipped(std::uint32_t id, const float lo[3], const float hi[3],
                          std::vector<Key>* out) {
  for (int k = 0; k < 3; ++k) {
    const float a = grid_.down(lo[k]);
    const float b = grid_.up(hi[k]);
    if (a == b) {
      out[k].push_back(make_key(ordered(a), kPlanar, id));
    } else {
      out[k].push_back(make_key(ordered(a), kStart, id));
      out[k].push_back(make_key(ordered(b), kEnd, id));
    }
  }
}

}  // namespace saarcor::host::kd
