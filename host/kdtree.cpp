// SAH kd-tree builder: Wald & Havran, "On building fast kd-trees for ray tracing, and on doing
// that in O(N log N)" (2006), with perfect splits, below a binned-SAH stage (Wald 2007, Shevtsov
// et al. 2007) at the top. Builds the paper's (section 2) bottom-level trees over an object's
// triangles and the top-level tree over instance bounds; the node layout follows
// docs/memory-image.md (root at 0, children adjacent, split positions in fp24).
//
// How it works (docs/kdtree.md has the long form):
// - Item bounds are rounded outward onto the split grid (the values representable in
//   params.split_format): lower bounds down, upper bounds up. Every candidate plane is a grid
//   value, so it is a value the hardware can store, and the left/right counts are exact for it.
// - Binned stage (nodes with more than params.binned_above items): per node one pass bins every
//   item's bounds on all three axes; candidates are grid values at even spacing plus the two
//   empty-space planes at the items' bounds. One pass then writes the children's item lists,
//   clipping only the straddlers (perfect splits). When the bins find no plane worth a split,
//   the exact stage decides.
// - Exact stage: every item yields, per axis, a start and an end event at its bounds (a planar
//   event when both coincide); the events are sorted once (64-bit keys: position, type, local
//   item id). Per node, one linear sweep per axis finds the SAH-best plane; the items are
//   classified against it, the events split into the children's lists in order (no re-sort), and
//   only the straddlers get new events from their clipped bounds (sorted, then merged in).
// - Memory: the binned stage's item lists and each axis's event list are stacks (a node's
//   children are written above it and popped when the subtree is done): no per-node allocation.
#include "host/kdtree.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
// The bin sweep has a 256-bit path, chosen at run time where the processor has AVX.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SAARCOR_KD_AVX 1
#include <immintrin.h>
#else
#define SAARCOR_KD_AVX 0
#endif

#include "host/float_bounds.h"

namespace saarcor::host {
namespace {

// ---- the split grid ---------------------------------------------------------------------------

// Values representable in a format with E <= 8, M <= 23 (subnormals flushed, as the hardware
// reads them) are binary32 values whose low 23-M mantissa bits are zero and whose exponent lies in
// the format's normal range. Directed rounding onto that grid is therefore a mask on the float
// bits, plus the range ends.
class SplitGrid {
 public:
  explicit SplitGrid(const ff::Format& f)
      : mask_((1u << (23 - f.man_bits)) - 1u),
        min_normal_bits_(std::bit_cast<std::uint32_t>(std::ldexp(1.0f, f.emin()))),
        max_finite_(
            static_cast<float>((2.0 - std::ldexp(1.0, -f.man_bits)) * std::ldexp(1.0, f.emax()))) {}

  float max_finite() const { return max_finite_; }
  // Largest grid value <= v (v finite, |v| <= max_finite()); never -0.
  float down(float v) const { return round(v, 0u); }
  // Smallest grid value >= v; never -0.
  float up(float v) const { return round(v, 0x80000000u); }

 private:
  // On the sign and magnitude bits, without a branch on the sign (coordinates of either sign
  // come in random order): the magnitude is rounded up where the sign bit differs from `up`
  // (towards -inf for a negative value), else down. Magnitude bits order like the magnitudes.
  float round(float v, std::uint32_t up) const {
    const std::uint32_t u = std::bit_cast<std::uint32_t>(v);
    const std::uint32_t sign = u & 0x80000000u;
    const std::uint32_t a = u ^ sign;
    // Down: below the smallest normal the grid has only 0.
    const std::uint32_t mag_down = a >= min_normal_bits_ ? a & ~mask_ : 0u;
    // Up: 0 stays 0, anything else reaches at least the smallest normal (a multiple of mask + 1,
    // so the masked sum never passes it for smaller a); carries into the exponent stay <=
    // max_finite for a <= it.
    const std::uint32_t t = std::max((a + mask_) & ~mask_, min_normal_bits_);
    const std::uint32_t mag_up = a == 0u ? 0u : t;
    const std::uint32_t r = (sign ^ up) != 0u ? mag_up : mag_down;
    return std::bit_cast<float>(r == 0u ? 0u : r | sign);
  }

  std::uint32_t mask_;
  std::uint32_t min_normal_bits_;
  float max_finite_;
};

// ---- events -----------------------------------------------------------------------------------

// Key layout: [63:32] position as an order-preserving integer, [31:30] type, [29:0] item id.
// Sorting keys as integers sorts by (position, type, id); at equal positions ends come before
// planars before starts, as the sweep needs.
using Key = std::uint64_t;
constexpr std::uint32_t kEnd = 0;
constexpr std::uint32_t kPlanar = 1;
constexpr std::uint32_t kStart = 2;
constexpr std::uint32_t kIdBits = 30;
constexpr std::uint32_t kIdMask = (1u << kIdBits) - 1u;
constexpr std::size_t kMaxItems = std::size_t{1} << kIdBits;

inline std::uint32_t ordered(float f) {
  const std::uint32_t u = std::bit_cast<std::uint32_t>(f);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}
inline float unordered(std::uint32_t o) {
  return std::bit_cast<float>((o & 0x80000000u) ? (o & 0x7FFFFFFFu) : ~o);
}
inline Key make_key(std::uint32_t pos_ordered, std::uint32_t type, std::uint32_t id) {
  return (Key{pos_ordered} << 32) | (Key{type} << kIdBits) | id;
}
inline std::uint32_t key_pos(Key k) {
  return static_cast<std::uint32_t>(k >> 32);
}
inline std::uint32_t key_type(Key k) {
  return static_cast<std::uint32_t>(k >> kIdBits) & 3u;
}
inline std::uint32_t key_id(Key k) {
  return static_cast<std::uint32_t>(k) & kIdMask;
}

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

// Stable LSD radix sort on bits [30, 64) (ties keep their order, i.e. ascending id when the input
// is in id order; the id bits are compared only through that stability).
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

// A list used as a stack (one axis's events, or the binned stage's items): a node's list is a
// range; its children go on top and are popped when the subtree is done.
// Large stacks (the root's item list of a big mesh and the lists above it) are asked for in 2 MB
// pages where the kernel gives them on request (Linux: transparent huge pages in "madvise"
// mode): every build touches them afresh, and 4 KB pages cost a page fault each.
constexpr std::size_t kHugePage = std::size_t{2} << 20;
struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <class T>
class Stack {
  static_assert(std::is_trivially_copyable_v<T> && alignof(T) <= 16);

 public:
  T* data() const { return buf_.get(); }
  void ensure(std::size_t n) {
    if (n <= cap_) return;
    const std::size_t cap = std::max(n, cap_ + cap_ / 2);
    std::unique_ptr<T[], FreeDeleter> buf(static_cast<T*>(allocate(cap * sizeof(T))));
    if (top_ > 0) std::copy(buf_.get(), buf_.get() + top_, buf.get());
    buf_ = std::move(buf);
    cap_ = cap;
  }
  std::size_t top_ = 0;

 private:
  static void* allocate(std::size_t bytes) {
    void* p = nullptr;
    if (bytes >= 4 * kHugePage) {
      const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
      p = std::aligned_alloc(kHugePage, rounded);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
      if (p != nullptr) {
        madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without it the build is the same
      }
#endif
    } else {
      p = std::malloc(bytes);
    }
    if (p == nullptr) {
      throw std::bad_alloc();
    }
    return p;
  }
  std::unique_ptr<T[], FreeDeleter> buf_;
  std::size_t cap_ = 0;
};
using Arena = Stack<Key>;

// An item in the binned stage: its bounds (clipped to the node, on the split grid) and its id.
// The upper bound is kept as the largest grid value that does not reach the plane when the item
// lies left of it: key[k] = pred(hi) (the grid value below hi) for an item with extent, hi = lo
// for a planar one (bit k of `planar`). Then "left of grid plane s" is key < s in both cases,
// which the binning counts without a correction.
struct BinItem {
  float lo[3];
  float key[3];
  std::uint32_t id;
  std::uint32_t planar;
};
constexpr int kMaxBins = 256;

struct Box {
  float lo[3];
  float hi[3];
};
// Extents in binary64 (exact for binary32 bounds) and the half surface area from them.
std::array<double, 3> extents(const Box& b) {
  return {static_cast<double>(b.hi[0]) - b.lo[0], static_cast<double>(b.hi[1]) - b.lo[1],
          static_cast<double>(b.hi[2]) - b.lo[2]};
}
double half_area(const std::array<double, 3>& d) {
  return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}
double half_area(const Box& b) {
  return half_area(extents(b));
}

// Item side after classification. kBoth items are dropped from the old lists (they get new
// events from their clipped bounds); the values make the split pass branch-free.
constexpr std::uint8_t kBoth = 0;
constexpr std::uint8_t kLeft = 1;
constexpr std::uint8_t kRight = 2;

// The width of a face slab (Builder::face_slabs) as a share of the root box's extent.
constexpr double kFaceSlabShare = 1.0 / 1024.0;
// A face slab may cost this much more than the leaf: peeling one face of a box whose other faces
// carry planars too pays off only once those are peeled as well (a greedy SAH never sees that).
constexpr double kFaceSlabSlack = 1.5;
// A node whose surface area is below this share of the root's is a leaf: one ray in 2^20 enters
// it, so splitting it gains nothing, yet without this bound the builder subdivides the cells
// around shared vertices (whose triangles' bounds, rounded outward onto the split grid, overlap by
// a grid step) down to single grid steps at the depth limit.
constexpr double kMinAreaShare = 1.0 / (1 << 20);

bool is_empty_leaf(const KdTreeNode& nd) {
  return nd.leaf && nd.count == 0;
}

// The chain link at an inner node whose children are `l` and `r` (KdTreeStats): 1 where one child
// is an empty leaf and the other an inner node with an empty-leaf child, 2 where that inner node
// also cuts on the same axis with its empty child on the same side (mergeable), else 0.
int chain_link(const std::vector<KdTreeNode>& nodes, const KdTreeNode& nd, std::uint32_t l,
               std::uint32_t r) {
  for (int empty_side = 0; empty_side < 2; ++empty_side) {
    if (!is_empty_leaf(nodes[empty_side == 0 ? l : r])) {
      continue;
    }
    const KdTreeNode& other = nodes[empty_side == 0 ? r : l];
    if (other.leaf) {
      continue;
    }
    const bool same_side = is_empty_leaf(nodes[other.child + empty_side]);
    if (!same_side && !is_empty_leaf(nodes[other.child + 1 - empty_side])) {
      continue;
    }
    return same_side && other.axis == nd.axis ? 2 : 1;
  }
  return 0;
}

}  // namespace

// KdBuildParams::kChainsMerged: rewrites the node array with every mergeable chain link replaced
// by one cut. An empty cut at s1 whose non-empty child cuts the same axis at s2 with its empty
// side towards s1 leaves the slab between the node's face and s2 empty, so the node cuts at s2
// instead (strictly inside its box, on the split grid: the child's plane), its children the
// first empty leaf and the child's non-empty child; repeated while the new child is such a cut.
// The array is written in the builder's order (a node's two children allocated together when it
// is reached, then its left subtree, then its right one), so a tree without mergeable links comes
// out unchanged; leaf lists are not moved.
void kd_merge_empty_chains(KdTree& tree) {
  const std::vector<KdTreeNode>& in = tree.nodes;
  // Most trees have no mergeable link (the builder puts an empty cut at the items' outermost
  // bound): one read-only pass over the array, no rewrite.
  const auto mergeable = [&](const KdTreeNode& nd) {
    return !nd.leaf && chain_link(in, nd, nd.child, nd.child + 1) == 2;
  };
  if (std::none_of(in.begin(), in.end(), mergeable)) {
    return;
  }
  std::vector<KdTreeNode> out;
  out.reserve(in.size());
  out.push_back(in[0]);
  struct Pending {
    std::uint32_t old_node;
    std::uint32_t new_node;
  };
  std::vector<Pending> stack{{0, 0}};
  while (!stack.empty()) {
    const Pending pd = stack.back();
    stack.pop_back();
    KdTreeNode nd = in[pd.old_node];
    if (nd.leaf) {
      out[pd.new_node] = nd;
      continue;
    }
    std::uint32_t l = nd.child;
    std::uint32_t r = nd.child + 1;
    while (chain_link(in, nd, l, r) == 2) {
      if (is_empty_leaf(in[l]) && !in[r].leaf && is_empty_leaf(in[in[r].child])) {
        nd.split = in[r].split;
        r = in[r].child + 1;
      } else {
        nd.split = in[l].split;
        l = in[l].child;
      }
    }
    nd.child = static_cast<std::uint32_t>(out.size());
    out[pd.new_node] = nd;
    out.emplace_back();
    out.emplace_back();
    stack.push_back({r, nd.child + 1});
    stack.push_back({l, nd.child});
  }
  tree.nodes = std::move(out);
}

namespace {

struct Split {
  double cost = std::numeric_limits<double>::infinity();
  int axis = -1;
  std::uint32_t pos = 0;  // ordered position
  bool planar_left = true;
  bool face_slab = false;  // a plane of Builder::face_slabs
};

struct BinnedSplit {
  double cost = std::numeric_limits<double>::infinity();
  int axis = -1;
  float pos = 0.0f;
  bool planar_left = false;
  std::uint32_t left = 0;  // items on the left (straddlers included), exact for the plane
  std::uint32_t right = 0;
};

class Builder {
 public:
  // Parameters are checked before anything is derived from them (the grid needs a valid format).
  Builder(const KdBuildParams& params, KdTree& tree, double node_cost)
      : node_cost_(node_cost),
        p_(checked(params)),
        grid_(params.split_format),
        tree_(tree),
        step_rel_(std::ldexp(1.0, -params.split_format.man_bits)),
        min_normal_(std::ldexp(1.0, params.split_format.emin())) {}

  void build_triangles(std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                       std::span<const std::uint8_t> skip);
  void build_boxes(std::span<const Aabb> boxes);

 private:
  static const KdBuildParams& checked(const KdBuildParams& p);
  // Turns `node` into an inner node splitting axis k at `split` and appends its two (adjacent)
  // children; returns the index of the left one. Both build stages end a split here.
  std::uint32_t make_inner(std::uint32_t node, int k, float split) {
    const auto child = static_cast<std::uint32_t>(tree_.nodes.size());
    KdTreeNode& nd = tree_.nodes[node];
    nd.leaf = false;
    nd.axis = static_cast<std::uint8_t>(k);
    nd.split = split;
    nd.child = child;
    tree_.nodes.emplace_back();
    tree_.nodes.emplace_back();
    return child;
  }
  void check_coordinate(float v, const char* what, std::size_t index) const;
  // K_T at a node of half area `area` (> 0): the node bound's cost per node (build_kdtree's
  // search) divided by the node's share of the root's area, so that a node of the whole tree
  // weighs as much in every node's decision (the SAH weighs a node's costs by that share).
  double node_kt(double area) const {
    const double kt = p_.traversal_cost;
    return node_cost_ > 0.0 ? kt + node_cost_ * (root_half_area_ / area) : kt;
  }
  // A plane's cost with leaf steps (KdBuildParams::leaf_step) from the children's half areas
  // and item counts: K_T and K_I * items per non-empty child, by its share of the node's area
  // (the node's own step is paid whether it is split or not). The bonus where a side is empty.
  double leaf_step_cost(double kt, double al, double ar, std::uint32_t nl, std::uint32_t nr,
                        double inv_area) const {
    const double ki = p_.intersection_cost;
    const double c = al * (nl == 0 ? 0.0 : kt + ki * nl) + ar * (nr == 0 ? 0.0 : kt + ki * nr);
    return (nl == 0 || nr == 0 ? p_.empty_bonus : 1.0) * inv_area * c;
  }
  // A plane's cost from the children's half areas and item counts: the SAH's K_T + K_I * (aL nL +
  // aR nR) / area, or with leaf steps leaf_step_cost; the bonus where a side is empty.
  double plane_cost(double kt, double al, double ar, std::uint32_t nl, std::uint32_t nr,
                    double inv_area) const {
    if (p_.leaf_step) return leaf_step_cost(kt, al, ar, nl, nr, inv_area);
    const double bonus = nl == 0 || nr == 0 ? p_.empty_bonus : 1.0;
    return bonus * (kt + p_.intersection_cost * inv_area * (al * nl + ar * nr));
  }
  void start(std::size_t items);
  void add_item(std::uint32_t id, const float lo[3], const float hi[3]);
  // Grid neighbours of a grid value.
  float grid_pred(float x) const { return grid_.down(float_next_down(x)); }
  float grid_succ(float x) const { return grid_.up(float_next_up(x)); }
  // lo, hi on the grid.
  void set_bin_item(BinItem& it, std::uint32_t id, const float lo[3], const float hi[3]) const {
    it.id = id;
    it.planar = 0;
    for (int k = 0; k < 3; ++k) {
      it.lo[k] = lo[k];
      const bool planar = lo[k] == hi[k];
      it.key[k] = planar ? hi[k] : grid_pred(hi[k]);
      it.planar |= static_cast<std::uint32_t>(planar) << k;
    }
  }
  float item_hi(const BinItem& it, int k) const {
    return (it.planar >> k) & 1u ? it.key[k] : grid_succ(it.key[k]);
  }
  void run();
  // `no_empty`: the node is the non-empty child of an empty cut and KdBuildParams::empty_chains
  // forbids chains, so no plane with an empty side is considered for it.
  void bin_node(std::uint32_t node, int depth, const Box& box, std::size_t b, std::uint32_t n,
                bool no_empty);
  BinnedSplit find_binned_split(const Box& box, const BinItem* items, std::uint32_t n,
                                bool no_empty) const;
  void exact_subtree(std::uint32_t node, int depth, const Box& box, std::size_t b, std::uint32_t n,
                     bool no_empty);
  void build_node(std::uint32_t node, int depth, const Box& box, const std::size_t b[3],
                  const std::size_t e[3], std::uint32_t n, bool no_empty);
  // The non-empty child of a cut with `nl`, `nr` items on its sides may not be cut off empty.
  bool forbid_empty_below(std::uint32_t nl, std::uint32_t nr) const {
    return p_.empty_chains == KdBuildParams::kChainsForbidden && (nl == 0 || nr == 0);
  }
  void make_leaf(std::uint32_t node, std::size_t b0, std::size_t e0);
  void emit_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids);
  Split find_split(const Box& box, const std::size_t b[3], const std::size_t e[3], std::uint32_t n,
                   bool no_empty) const;
  void face_slabs(const Box& box, int k, double sum, double prod, std::size_t b, std::size_t e,
                  std::uint32_t n, double kt, double inv_area, bool no_empty, Split& best) const;
  int clip_split(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                 float lhi[3], float rlo[3], float rhi[3]) const;
  void add_clipped(std::uint32_t id, const float lo[3], const float hi[3], std::vector<Key>* out);

  double node_cost_;  // the node bound's cost per node (node_kt), 0 when unbound
  KdBuildParams p_;   // a copy: run() resolves the automatic depth limit
  SplitGrid grid_;
  KdTree& tree_;
  // The split format's grid step relative to the magnitude, and its smallest normal (the bins).
  double step_rel_;
  double min_normal_;

  std::span<const glm::vec3> positions_;
  std::span<const glm::uvec3> tris_;
  std::span<const Aabb> boxes_;
  bool triangles_ = true;

  Stack<BinItem> items_;            // the binned stage's lists
  std::vector<std::uint32_t> gid_;  // exact stage: local item id (in the events) -> item id
  Arena ev_[3];
  std::vector<std::uint8_t> side_;  // by local id
  std::vector<std::uint32_t> both_;
  std::vector<Key> new_left_[3];
  std::vector<Key> new_right_[3];
  std::vector<Key> sort_scratch_;
  std::vector<std::uint32_t> leaf_scratch_;
  std::vector<std::uint32_t> right_scratch_;
  std::vector<std::uint32_t> both_left_;  // straddlers kept on each side
  std::vector<std::uint32_t> both_right_;
  std::uint32_t item_count_ = 0;
  std::uint32_t exact_root_ = 0;  // the node exact_subtree started at (make_leaf)
  Box root_{};
  double min_half_area_ = 0.0;  // nodes below it are leaves (kMinAreaShare of the root's)
  double root_half_area_ = 0.0;
};

const KdBuildParams& Builder::checked(const KdBuildParams& p) {
  const ff::Format& f = p.split_format;
  if (!f.valid()) throw std::runtime_error("kd-tree: invalid split format " + ff::format_name(f));
  if (!(p.traversal_cost >= 0.0f) || !(p.intersection_cost > 0.0f) ||
      !(p.empty_bonus > 0.0f && p.empty_bonus <= 1.0f))
    throw std::runtime_error(
        "kd-tree: cost parameters need traversal >= 0, intersection > 0, 0 < empty bonus <= 1");
  if ((p.max_depth < 0 && p.max_depth != KdBuildParams::kAutoDepth) || p.max_depth > 1000)
    throw std::runtime_error("kd-tree: max depth " + std::to_string(p.max_depth) +
                             " outside 0..1000 (or -1: automatic)");
  if (p.leaf_size < 0)
    throw std::runtime_error("kd-tree: negative leaf size " + std::to_string(p.leaf_size));
  if (p.binned_above < 0)
    throw std::runtime_error("kd-tree: negative binned-above threshold " +
                             std::to_string(p.binned_above));
  if (!(p.max_nodes_per_item >= 0.0f && p.max_nodes_per_item <= 1e6f) || p.node_floor < 0)
    throw std::runtime_error(
        "kd-tree: node bound needs 0 <= nodes per item <= 1e6 (0: no bound) and a floor >= 0");
  if (p.empty_chains < KdBuildParams::kChainsAllowed ||
      p.empty_chains > KdBuildParams::kChainsForbidden) {
    throw std::runtime_error("kd-tree: empty-chain rule " + std::to_string(p.empty_chains) +
                             " outside 0..2");
  }
  if (p.bins < 2 || p.bins > kMaxBins)
    throw std::runtime_error("kd-tree: bins " + std::to_string(p.bins) + " outside 2.." +
                             std::to_string(kMaxBins));
  return p;
}

void Builder::check_coordinate(float v, const char* what, std::size_t index) const {
  if (!std::isfinite(v))
    throw std::runtime_error(std::string("kd-tree: ") + what + " " + std::to_string(index) +
                             " has a non-finite coordinate");
  if (std::fabs(v) > grid_.max_finite())
    throw std::runtime_error(std::string("kd-tree: ") + what + " " + std::to_string(index) +
                             " has coordinate " + std::to_string(v) +
                             " outside the range of split format " +
                             ff::format_name(p_.split_format));
}

void Builder::start(std::size_t items) {
  if (items >= kMaxItems)
    throw std::runtime_error("kd-tree: " + std::to_string(items) + " items exceed the limit of " +
                             std::to_string(kMaxItems - 1));
  // Room for the root list and, stacked above it, the right lists along the recursion path
  // (left lists overwrite their parent's: about 1 + 1/2 + 1/4 + ... times the root's, plus
  // straddlers' duplicates). Untouched pages cost nothing; growing copies everything.
  items_.top_ = 0;
  items_.ensure(std::max<std::size_t>(64, items * 4));
  for (int k = 0; k < 3; ++k) {
    root_.lo[k] = std::numeric_limits<float>::infinity();
    root_.hi[k] = -std::numeric_limits<float>::infinity();
  }
}

void Builder::add_item(std::uint32_t id, const float lo[3], const float hi[3]) {
  float l[3];
  float h[3];
  for (int k = 0; k < 3; ++k) {
    l[k] = grid_.down(lo[k]);
    h[k] = grid_.up(hi[k]);
    root_.lo[k] = std::min(root_.lo[k], l[k]);
    root_.hi[k] = std::max(root_.hi[k], h[k]);
  }
  set_bin_item(items_.data()[items_.top_++], id, l, h);
  ++item_count_;
}

void Builder::build_triangles(std::span<const glm::vec3> positions,
                              std::span<const glm::uvec3> tris,
                              std::span<const std::uint8_t> skip) {
  if (!skip.empty() && skip.size() != tris.size())
    throw std::runtime_error("kd-tree: skip list has " + std::to_string(skip.size()) +
                             " entries for " + std::to_string(tris.size()) + " triangles");
  positions_ = positions;
  tris_ = tris;
  triangles_ = true;
  start(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i) {
    if (!skip.empty() && skip[i] != 0) continue;
    const glm::uvec3 t = tris[i];
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size())
      throw std::runtime_error("kd-tree: triangle " + std::to_string(i) +
                               " indexes a vertex beyond the " + std::to_string(positions.size()) +
                               " positions");
    // Only the vertices of used triangles matter (and must be finite and storable). One
    // comparison per coordinate in the common case (false for a NaN), the message otherwise.
    const float lim = grid_.max_finite();
    for (const unsigned v : {t.x, t.y, t.z}) {
      const glm::vec3 a = glm::abs(positions[v]);
      if (!(a.x <= lim && a.y <= lim && a.z <= lim))
        for (int k = 0; k < 3; ++k)
          check_coordinate(positions[v][k], "vertex", v);
    }
    const glm::vec3 lo = glm::min(glm::min(positions[t.x], positions[t.y]), positions[t.z]);
    const glm::vec3 hi = glm::max(glm::max(positions[t.x], positions[t.y]), positions[t.z]);
    const float l[3] = {lo.x, lo.y, lo.z};
    const float h[3] = {hi.x, hi.y, hi.z};
    add_item(static_cast<std::uint32_t>(i), l, h);
  }
  run();
}

void Builder::build_boxes(std::span<const Aabb> boxes) {
  boxes_ = boxes;
  triangles_ = false;
  start(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      // An empty box (inf, -inf) is allowed and left out; anything else must be finite.
      if (std::isnan(boxes[i].lo[k]) || std::isnan(boxes[i].hi[k]))
        throw std::runtime_error("kd-tree: box " + std::to_string(i) +
                                 " has a non-finite coordinate");
    }
    if (boxes[i].empty()) continue;
    for (int k = 0; k < 3; ++k) {
      check_coordinate(boxes[i].lo[k], "box", i);
      check_coordinate(boxes[i].hi[k], "box", i);
    }
    const float l[3] = {boxes[i].lo.x, boxes[i].lo.y, boxes[i].lo.z};
    const float h[3] = {boxes[i].hi.x, boxes[i].hi.y, boxes[i].hi.z};
    add_item(static_cast<std::uint32_t>(i), l, h);
  }
  run();
}

void Builder::run() {
  tree_.nodes.clear();
  tree_.items.clear();
  // Large meshes reach about 2.5 nodes per item: room for 3 saves a copy of the whole array.
  tree_.nodes.reserve(std::size_t{item_count_} * 3 + 1);
  tree_.items.reserve(std::size_t{item_count_} * 3);
  tree_.nodes.emplace_back();
  if (item_count_ == 0) {
    tree_.nodes[0].leaf = true;
    tree_.bounds = Aabb{};
    return;
  }
  tree_.bounds.lo = glm::vec3(root_.lo[0], root_.lo[1], root_.lo[2]);
  tree_.bounds.hi = glm::vec3(root_.hi[0], root_.hi[1], root_.hi[2]);
  const std::size_t n = items_.top_;
  p_.max_depth = kd_max_depth(p_, item_count_);
  root_half_area_ = half_area(root_);
  min_half_area_ = root_half_area_ * kMinAreaShare;
  bin_node(0, 0, root_, 0, static_cast<std::uint32_t>(n), false);
  if (p_.empty_chains == KdBuildParams::kChainsMerged) {
    kd_merge_empty_chains(tree_);
  }
}

// The exact stage for a subtree: events from the items' bounds (already on the grid), with
// local ids 0..n-1 so that the per-item side bytes stay in cache, sorted once.
void Builder::exact_subtree(std::uint32_t node, int depth, const Box& box, std::size_t b,
                            std::uint32_t n, bool no_empty) {
  gid_.resize(n);
  if (side_.size() < n) side_.resize(n);
  const BinItem* items = items_.data() + b;
  std::size_t eb[3];
  std::size_t ee[3];
  for (int k = 0; k < 3; ++k) {
    Arena& a = ev_[k];
    // Room for the subtree's list (up to 2 events per item) and the lists stacked above it
    // along the recursion path: 12 per item.
    a.top_ = 0;
    a.ensure(std::max<std::size_t>(64, std::size_t{n} * 12));
    Key* out = a.data();
    std::size_t m = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float lo = items[i].lo[k];
      const float hi = item_hi(items[i], k);
      if (lo == hi) {
        out[m++] = make_key(ordered(lo), kPlanar, i);
      } else {
        out[m++] = make_key(ordered(lo), kStart, i);
        out[m++] = make_key(ordered(hi), kEnd, i);
      }
    }
    radix_sort(out, m, sort_scratch_);
    a.top_ = m;
    eb[k] = 0;
    ee[k] = m;
  }
  for (std::uint32_t i = 0; i < n; ++i)
    gid_[i] = items[i].id;
  exact_root_ = node;
  build_node(node, depth, box, eb, ee, n, no_empty);
}

// The bins' counts, per bin the three axes side by side (and a zero lane): the sweep below
// reads one bin of all axes at once.
constexpr int kHistLanes = 4;
using BinHist = std::uint32_t[kMaxBins][kHistLanes];

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

// The three axes' bin-plane sweeps of one node: inputs nc (planes), da, al, ar per axis as
// BinScan's (nc = 0 for a flat axis), outputs each axis's first least plane.
struct BinSweep {
  int nc[3] = {0, 0, 0};
  double da[3] = {0.0, 0.0, 0.0};
  double al[3] = {0.0, 0.0, 0.0};
  double ar[3] = {0.0, 0.0, 0.0};
  double best_m[3] = {std::numeric_limits<double>::infinity(),
                      std::numeric_limits<double>::infinity(),
                      std::numeric_limits<double>::infinity()};
  int best_j[3] = {-1, -1, -1};
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

// Binned SAH (Wald 2007; for kd-trees Shevtsov et al. 2007) with exact counts on the grid.
// Per axis, a grid value x falls into bin f(x) = trunc(clamp((x - lo) * bins / extent, 0,
// bins - 1)), monotone in x. Candidate plane j is the smallest grid value s_j with f(s_j) > j,
// so for every grid value x: x < s_j <=> f(x) <= j. An item is left of s_j iff lo < s_j, i.e.
// f(lo) <= j; it is no longer right of s_j iff key < s_j (BinItem), i.e. f(key) <= j (planars at
// a candidate count right). The counts are therefore exact for the stored plane s_j, with two
// bin lookups per item and axis and no correction. A bin spans at least 4 grid steps, so s_j
// lies within a quarter bin of the even position, which is used for the areas; only the
// winner's s_j is searched. The two empty-space planes at the items' lowest and highest bounds
// are evaluated besides.
BinnedSplit Builder::find_binned_split(const Box& box, const BinItem* items, std::uint32_t n,
                                       bool no_empty) const {
  BinnedSplit best;
  const std::array<double, 3> d = extents(box);
  const double area = half_area(d);
  if (!(area > 0.0)) return best;
  const double inv_area = 1.0 / area;
  const double kt = node_kt(area);
  const double ki = p_.intersection_cost;
  // Fewer bins for smaller nodes: the per-node cost is proportional to the bins, the per-item
  // cost is not; the top of the tree, which decides the most, gets the most. On each axis a bin
  // spans at least 4 grid steps (finer candidates would collapse onto the same grid values).
  const int nb_node = std::clamp(static_cast<int>(n), std::min(32, p_.bins), p_.bins);
  int nb[3];
  float scale[3];
  float base[3];
  float top[3];
  alignas(16) BinHist hist_lo;
  alignas(16) BinHist hist_hi;
  float tlo[3];
  float tkey[3];
  for (int k = 0; k < 3; ++k) {
    const double mag = std::max(std::fabs(static_cast<double>(box.lo[k])),
                                std::fabs(static_cast<double>(box.hi[k])));
    const double grid_step = std::max(mag * step_rel_, min_normal_);
    nb[k] =
        static_cast<int>(std::clamp(d[k] / (4.0 * grid_step), 2.0, static_cast<double>(nb_node)));
    base[k] = box.lo[k];
    // Flat: all in bin 0. Any finite scale keeps f monotone (and free of 0 * inf).
    scale[k] = d[k] > 0.0 ? static_cast<float>(std::min(nb[k] / d[k], 0x1p127)) : 0.0f;
    top[k] = static_cast<float>(nb[k] - 1);
    tlo[k] = std::numeric_limits<float>::infinity();
    tkey[k] = -std::numeric_limits<float>::infinity();
  }
  const int nb_max = std::max({nb[0], nb[1], nb[2]});
  std::fill(&hist_lo[0][0], &hist_lo[0][0] + nb_max * kHistLanes, 0u);
  std::fill(&hist_hi[0][0], &hist_hi[0][0] + nb_max * kHistLanes, 0u);
#if defined(__SSE2__)
  // The same arithmetic four lanes at a time (IEEE single, as the scalar f below): lanes
  // lo0 lo1 lo2 key0 and key0 key1 key2 id (id lane: times 0, unused).
  static_assert(sizeof(BinItem) == 32 && offsetof(BinItem, key) == 12);
  {
    const __m128 base_a = _mm_setr_ps(base[0], base[1], base[2], base[0]);
    const __m128 scale_a = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
    const __m128 top_a = _mm_setr_ps(top[0], top[1], top[2], 0.0f);
    const __m128 scale_b = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
    const __m128 zero = _mm_setzero_ps();
    __m128 vlo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 vkey = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    const __m128i lane_bytes = _mm_setr_epi32(0, 4, 8, 12);
    auto* lo_bytes = reinterpret_cast<unsigned char*>(&hist_lo[0][0]);
    auto* hi_bytes = reinterpret_cast<unsigned char*>(&hist_hi[0][0]);
#if !defined(__x86_64__)
    alignas(16) std::uint32_t idx[8];
#endif
    for (std::uint32_t i = 0; i < n; ++i) {
      const float* p = items[i].lo;
      const __m128 a = _mm_loadu_ps(p);
      const __m128 c = _mm_loadu_ps(p + 3);
      vlo = _mm_min_ps(vlo, a);
      vkey = _mm_max_ps(vkey, c);
      const __m128 fa =
          _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(a, base_a), scale_a), zero), top_a);
      const __m128 fc =
          _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(c, base_a), scale_b), zero), top_a);
      // Byte offsets into the histograms (bin * 16 + lane * 4) computed in the register, so
      // that each increment needs no index arithmetic of its own.
      const __m128i oa = _mm_add_epi32(_mm_slli_epi32(_mm_cvttps_epi32(fa), 4), lane_bytes);
      const __m128i oc = _mm_add_epi32(_mm_slli_epi32(_mm_cvttps_epi32(fc), 4), lane_bytes);
#if defined(__x86_64__)
      const auto a01 = static_cast<std::uint64_t>(_mm_cvtsi128_si64(oa));
      const auto c01 = static_cast<std::uint64_t>(_mm_cvtsi128_si64(oc));
      const std::uint32_t off[6] = {
          static_cast<std::uint32_t>(a01),
          static_cast<std::uint32_t>(a01 >> 32),
          static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_unpackhi_epi64(oa, oa))),
          static_cast<std::uint32_t>(c01),
          static_cast<std::uint32_t>(c01 >> 32),
          static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_unpackhi_epi64(oc, oc)))};
#else
      _mm_store_si128(reinterpret_cast<__m128i*>(idx), oa);
      _mm_store_si128(reinterpret_cast<__m128i*>(idx + 4), oc);
      const std::uint32_t off[6] = {idx[0], idx[1], idx[2], idx[4], idx[5], idx[6]};
#endif
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
  for (std::uint32_t i = 0; i < n; ++i) {
    const BinItem& it = items[i];
    for (int k = 0; k < 3; ++k) {
      const float lo = it.lo[k];
      const float key = it.key[k];
      tlo[k] = std::min(tlo[k], lo);
      tkey[k] = std::max(tkey[k], key);
      const int j = static_cast<int>(std::min(std::max((lo - base[k]) * scale[k], 0.0f), top[k]));
      const int h = static_cast<int>(std::min(std::max((key - base[k]) * scale[k], 0.0f), top[k]));
      ++hist_lo[j][k];
      ++hist_hi[h][k];
    }
  }
#endif
  // s_j (see above): the smallest binary32 value y with f(y) > j, found by bisection on the
  // order-preserving integers (f can be flat over many values where x - lo absorbs x), then
  // rounded up onto the grid: grid values >= y reach bin j + 1, smaller ones do not. Usually
  // the even position is y already. +inf when not even the box's upper bound reaches the bin.
  auto threshold = [&](int k, int j) {
    const auto want = static_cast<float>(j + 1);
    auto reaches = [&](std::uint32_t o) {
      return std::min(std::max((unordered(o) - base[k]) * scale[k], 0.0f), top[k]) >= want;
    };
    std::uint32_t below = ordered(box.lo[k]);  // f(lo) = 0
    std::uint32_t at = ordered(box.hi[k]);
    if (!reaches(at)) return std::numeric_limits<float>::infinity();
    const std::uint32_t guess = ordered(
        std::clamp(static_cast<float>(box.lo[k] + d[k] * (j + 1) / nb[k]), box.lo[k], box.hi[k]));
    if (guess > below && guess < at) {
      if (reaches(guess)) {
        at = guess;
        if (!reaches(guess - 1)) below = guess - 1;
      } else {
        below = guess;
        if (reaches(guess + 1)) at = guess + 1;
      }
    }
    while (at - below > 1) {
      const std::uint32_t mid = below + (at - below) / 2;
      (reaches(mid) ? at : below) = mid;
    }
    return grid_.up(unordered(at));
  };
  // Per axis the first least bin plane (BinScan), all three axes swept together.
  BinSweep sw;
  for (int k = 0; k < 3; ++k) {
    if (!(d[k] > 0.0)) continue;  // flat: no planes (the lane stays at its defaults)
    const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
    const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
    sw.nc[k] = nb[k] - 1;
    sw.da[k] = d[k] / nb[k] * sum;
    sw.al[k] = prod;
    sw.ar[k] = d[k] * sum + prod;
  }
  sweep_bins(hist_lo, hist_hi, nb_max, n, sw);
  int bin_j = -1;  // the winner's candidate when it is a bin plane
  for (int k = 0; k < 3; ++k) {
    if (!(d[k] > 0.0)) continue;
    const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
    const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
    const double lo = box.lo[k];
    const double hi = box.hi[k];
    auto cost_at = [&](double x, std::uint32_t nl, std::uint32_t nr) {
      const double al = (x - lo) * sum + prod;
      const double ar = (hi - x) * sum + prod;
      return plane_cost(kt, al, ar, nl, nr, inv_area);
    };
    if (sw.best_j[k] >= 0) {
      // Both children hold items and their half areas add up to d * sum + 2 * prod on every
      // plane of this axis: the leaf steps add the same amount to each (BinScan's order holds).
      const double c = p_.leaf_step
                           ? inv_area * (ki * sw.best_m[k] + kt * (d[k] * sum + 2.0 * prod))
                           : kt + ki * inv_area * sw.best_m[k];
      if (c < best.cost) {
        best = BinnedSplit{c, k, 0.0f, false, 0, 0};  // counts summed once the winner is known
        bin_j = sw.best_j[k];                         // and s_j searched
      }
    }
    // Empty-space planes at the items' bounds (all items on one side, planars with them):
    // the lowest lower bound, and the grid value above the highest key (the highest upper
    // bound, or one grid step beyond it when that is a planar item's).
    if (!no_empty && tlo[k] > box.lo[k] && tlo[k] < box.hi[k]) {
      const double c = cost_at(tlo[k], 0, n);
      if (c < best.cost) {
        best = BinnedSplit{c, k, tlo[k], false, 0, n};
        bin_j = -1;
      }
    }
    const float thi = grid_succ(tkey[k]);
    if (!no_empty && thi < box.hi[k] && thi > box.lo[k]) {
      const double c = cost_at(thi, n, 0);
      if (c < best.cost) {
        best = BinnedSplit{c, k, thi, true, n, 0};
        bin_j = -1;
      }
    }
  }
  if (bin_j >= 0) {
    const int k = best.axis;
    std::uint32_t not_right = 0;
    for (int j = 0; j <= bin_j; ++j) {
      best.left += hist_lo[j][k];
      not_right += hist_hi[j][k];
    }
    best.right = n - not_right;
    best.pos = threshold(k, bin_j);
    // Only a box a few grid steps wide can leave no grid value strictly inside.
    if (!(best.pos > box.lo[k] && best.pos < box.hi[k])) return BinnedSplit{};
  }
  return best;
}

void Builder::bin_node(std::uint32_t node, int depth, const Box& box, std::size_t b,
                       std::uint32_t n, bool no_empty) {
  if (n == 0) {  // the empty side of an empty-space plane: a leaf under every rule
    leaf_scratch_.clear();
    emit_leaf(node, leaf_scratch_);
    return;
  }
  if (n <= static_cast<std::uint32_t>(p_.binned_above)) {
    exact_subtree(node, depth, box, b, n, no_empty);
    return;
  }
  if (n <= static_cast<std::uint32_t>(p_.leaf_size) || depth >= p_.max_depth ||
      half_area(box) < min_half_area_) {
    leaf_scratch_.clear();
    for (std::uint32_t i = 0; i < n; ++i)
      leaf_scratch_.push_back(items_.data()[b + i].id);
    emit_leaf(node, leaf_scratch_);
    return;
  }
  const BinnedSplit best = find_binned_split(box, items_.data() + b, n, no_empty);
  if (best.axis < 0 || !(best.cost < static_cast<double>(p_.intersection_cost) * n)) {
    // The bins found nothing worth it: the exact sweep decides (leaf or a plane between bins).
    exact_subtree(node, depth, box, b, n, no_empty);
    return;
  }
  const int k = best.axis;
  const float split = best.pos;
  Box lbox = box;
  Box rbox = box;
  lbox.hi[k] = split;
  rbox.lo[k] = split;

  // One pass: classify (as the exact stage does) and write the children's lists, whose sizes
  // the binning counted (clipping may only drop pieces). The left list overwrites this node's
  // in place (each item read yields at most one left item, so writing never overtakes reading);
  // the right one goes on top of the stack.
  const std::size_t entry_top = items_.top_;
  const std::size_t lb = b;
  const std::size_t rb = entry_top;
  items_.ensure(rb + best.right + 1);  // + 1: the slot the branch-free write below may fill
  BinItem* all = items_.data();
  const std::uint8_t planar_side = best.planar_left ? kLeft : kRight;
  std::uint32_t nl = 0;
  std::uint32_t nr = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    // The split axis's fields read from the list, not from the copy: indexed by k, the copy
    // would be kept on the stack and read back.
    const float lo = all[b + i].lo[k];
    const float key = all[b + i].key[k];
    const bool planar = (all[b + i].planar >> k) & 1u;
    const BinItem it = all[b + i];  // a copy: the left list may overwrite its slot
    const bool at_plane = planar & (lo == split);
    const bool left = at_plane ? planar_side == kLeft : key < split;
    const bool right = at_plane ? planar_side == kRight : lo >= split;
    if (left || right) {
      // Written to both lists, kept by the cursor of its side: which side is unpredictable,
      // so no branch on it (the right slot written for a left item is above the stack top, the
      // left one for a right item at or below the slot just read).
      all[lb + nl] = it;
      all[rb + nr] = it;
      nl += left;
      nr += right;
      continue;
    }
    // Perfect split of a straddler, with the exact stage's rules.
    float llo[3];
    float lhi[3];
    float rlo[3];
    float rhi[3];
    const int pieces = clip_split(it.id, box, k, split, llo, lhi, rlo, rhi);
    bool in_left = (pieces & 1) && llo[k] < split;
    bool in_right = (pieces & 2) && rhi[k] > split;
    if (!in_left && !in_right) {
      in_left = (pieces & 1) != 0;
      in_right = !in_left && (pieces & 2) != 0;
    }
    const std::uint32_t id = it.id;
    if (in_left) {
      for (int j = 0; j < 3; ++j) {
        llo[j] = grid_.down(llo[j]);
        lhi[j] = grid_.up(lhi[j]);
      }
      set_bin_item(all[lb + nl++], id, llo, lhi);
    }
    if (in_right) {
      for (int j = 0; j < 3; ++j) {
        rlo[j] = grid_.down(rlo[j]);
        rhi[j] = grid_.up(rhi[j]);
      }
      set_bin_item(all[rb + nr++], id, rlo, rhi);
    }
  }

  const std::uint32_t child = make_inner(node, k, split);
  const std::size_t top = rb + nr;
  items_.top_ = top;
  const bool no_empty_below = forbid_empty_below(nl, nr);
  bin_node(child, depth + 1, lbox, lb, nl, no_empty_below);
  items_.top_ = top;
  bin_node(child + 1, depth + 1, rbox, rb, nr, no_empty_below);
  items_.top_ = entry_top;
}

Split Builder::find_split(const Box& box, const std::size_t b[3], const std::size_t e[3],
                          std::uint32_t n, bool no_empty) const {
  Split best;
  const std::array<double, 3> d = extents(box);
  const double area = half_area(d);
  if (!(area > 0.0)) return best;  // a line or a point: no plane can separate anything
  const double inv_area = 1.0 / area;
  const double kt = node_kt(area);
  const double ki = p_.intersection_cost;
  const double bonus = p_.empty_bonus;
  Split face;  // the best face slab (Builder::face_slabs)
  for (int k = 0; k < 3; ++k) {
    if (!(d[k] > 0.0)) continue;
    const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
    const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
    const double lo = box.lo[k];
    const double hi = box.hi[k];
    const std::uint32_t lo_o = ordered(box.lo[k]);
    const std::uint32_t hi_o = ordered(box.hi[k]);
    // Per candidate, without the constant factors: m = aL*nL + aR*nR + nP*min(aL, aR) (the
    // planars go to the cheaper side), with aL, aR the children's half areas. The full cost
    // kt + ki * m / area is compared only when m beats the best so far; the empty-space bonus
    // (possible only where one side is empty) takes the exact path.
    const double scale = ki * inv_area;
    // With leaf steps the cost is scale * (m + step * (aL + aR)) (both sides hold items here)
    // and has no constant term.
    const double step = p_.leaf_step ? kt / ki : 0.0;
    const double kt0 = p_.leaf_step ? 0.0 : kt;
    double best_m =
        std::isinf(best.cost) ? std::numeric_limits<double>::infinity() : (best.cost - kt0) / scale;
    const Key* ev = ev_[k].data();
    std::uint32_t nl = 0;
    std::uint32_t nr = n;
    std::uint32_t np = 0;       // planars at the current position
    std::uint32_t pending = 0;  // starts and planars at the current position (left after it)
    const std::size_t end = e[k];
    for (std::size_t i = b[k]; i < end; ++i) {
      const Key key = ev[i];
      const std::uint32_t t = key_type(key);
      nr -= t != kStart;
      np += t == kPlanar;
      pending += t != kEnd;
      const std::uint32_t pos = key_pos(key);
      // Evaluate at the last event of a position: then nl holds the items entirely before it,
      // nr those entirely after it, np those in it.
      if (i + 1 < end && key_pos(ev[i + 1]) == pos) continue;
      if (pos > lo_o && pos < hi_o) {
        const double x = unordered(pos);
        const double al = (x - lo) * sum + prod;
        const double ar = (hi - x) * sum + prod;
        const double m = al * nl + ar * nr + np * std::min(al, ar);
        if (nl == 0 || nr == 0) {
          // One side may be empty: both planar placements with the bonus, exactly.
          const std::uint32_t nl1 = nl + np;
          const std::uint32_t nr2 = nr + np;
          // (The plain SAH's products in this order, as the sweep has always rounded them.)
          auto exact = [&](std::uint32_t l, std::uint32_t r) {
            if (p_.leaf_step) return leaf_step_cost(kt, al, ar, l, r, inv_area);
            return (l == 0 || r == 0 ? bonus : 1.0) *
                   (kt + ki * (al * inv_area * l + ar * inv_area * r));
          };
          // Under no_empty a placement that leaves a side empty is no candidate.
          const double inf = std::numeric_limits<double>::infinity();
          const double c1 = no_empty && (nl1 == 0 || nr == 0) ? inf : exact(nl1, nr);
          const double c2 = no_empty && (nl == 0 || nr2 == 0) ? inf : exact(nl, nr2);
          if (c1 < best.cost || c2 < best.cost) {
            best = c1 <= c2 ? Split{c1, k, pos, true} : Split{c2, k, pos, false};
            best_m = (best.cost - kt0) / scale;
          }
        } else if (const double ms = m + step * (al + ar); ms < best_m) {
          best_m = ms;
          best = Split{kt0 + scale * ms, k, pos, al <= ar};
        }
      }
      nl += pending;
      pending = 0;
      np = 0;
    }
    if (p_.face_slabs) {
      face_slabs(box, k, sum, prod, b[k], e[k], n, kt, inv_area, no_empty, face);
    }
  }
  // A face slab wins when it is cheaper, and also when no other plane beats the leaf but the slab
  // lies within the slack (build_node applies the slack to it).
  const double leaf_cost = ki * n;
  if (face.cost < best.cost || (!(best.cost < leaf_cost) && face.cost < leaf_cost * kFaceSlabSlack))
    return face;
  return best;
}

// Items lying in a face of the node's box (a room's walls, floor and ceiling) are in every leaf
// along that face, and no event plane can separate them: their events sit on the box bound.
// Every ray crossing such a leaf then tests them (no triangle mailbox, paper 3.1). A plane a
// slab's width inside the face does: the thin slab holds the face's items and is entered only by
// rays near the face. The width is a fixed share of the root extent so that the traversal's
// rounded plane distances (about 2^-15 of the distance, fp24) cannot skip the slab.
// sum, prod: the sum and product of the box's two other extents (the sweep's per-axis constants).
void Builder::face_slabs(const Box& box, int k, double sum, double prod, std::size_t b,
                         std::size_t e, std::uint32_t n, double kt, double inv_area, bool no_empty,
                         Split& best) const {
  const double width = (static_cast<double>(root_.hi[k]) - root_.lo[k]) * kFaceSlabShare;
  const float lo = box.lo[k];
  const float hi = box.hi[k];
  if (!(static_cast<double>(hi) - lo > 4.0 * width) || !(width > 0.0)) return;
  const Key* ev = ev_[k].data();
  auto evaluate = [&](float x, std::uint32_t nl, std::uint32_t nr) {
    const double al = (static_cast<double>(x) - lo) * sum + prod;
    const double ar = (static_cast<double>(hi) - x) * sum + prod;
    // The interior side is empty where every item lies in the face.
    if (no_empty && (nl == 0 || nr == 0)) {
      return;
    }
    const double cost = plane_cost(kt, al, ar, nl, nr, inv_area);
    if (cost < best.cost) best = Split{cost, k, ordered(x), true, true};
  };
  // Near the low face: left = items with lo < x, right = items with hi > x.
  const float x_lo = grid_.up(static_cast<float>(lo + width));
  // Planars at x go left (planar_left), so they count left and not right.
  // A slab thinner than a grid step rounds onto the face itself: no plane.
  if (e > b && x_lo > lo && x_lo < hi && key_pos(ev[b]) == ordered(lo) &&
      key_type(ev[b]) == kPlanar) {
    std::uint32_t nl = 0;
    std::uint32_t ended = 0;
    const std::uint32_t xo = ordered(x_lo);
    for (std::size_t i = b; i < e && key_pos(ev[i]) <= xo; ++i) {
      const std::uint32_t t = key_type(ev[i]);
      nl += t == kPlanar || (t == kStart && key_pos(ev[i]) < xo);
      ended += t != kStart;
    }
    evaluate(x_lo, nl, n - ended);
  }
  // Near the high face: left = items with lo < x, right = items with hi > x.
  const float x_hi = grid_.down(static_cast<float>(hi - width));
  if (e > b && x_hi < hi && x_hi > lo && key_pos(ev[e - 1]) == ordered(hi) &&
      key_type(ev[e - 1]) == kPlanar) {
    std::uint32_t started = 0;  // items with lo >= x
    std::uint32_t nr = 0;
    const std::uint32_t xo = ordered(x_hi);
    for (std::size_t i = e; i-- > b && key_pos(ev[i]) >= xo;) {
      const std::uint32_t t = key_type(ev[i]);
      started += t == kStart || (t == kPlanar && key_pos(ev[i]) > xo);
      nr += t != kStart && key_pos(ev[i]) > xo;
    }
    evaluate(x_hi, n - started, nr);
  }
}

void Builder::make_leaf(std::uint32_t node, std::size_t b0, std::size_t e0) {
  leaf_scratch_.clear();
  if (node == exact_root_) {
    // The exact subtree's root holds every local id, whose item ids ascend (gid_, from the
    // binned list, which keeps the root's id order): most hand-overs end here as a leaf.
    leaf_scratch_.assign(gid_.begin(), gid_.end());
    emit_leaf(node, leaf_scratch_);
    return;
  }
  // Every item has exactly one start or planar event per axis.
  const Key* ev = ev_[0].data();
  for (std::size_t i = b0; i < e0; ++i)
    if (key_type(ev[i]) != kEnd) leaf_scratch_.push_back(gid_[key_id(ev[i])]);
  emit_leaf(node, leaf_scratch_);
}

// A leaf's list in ascending item id (deterministic; the hardware's tie rule may depend on it).
void Builder::emit_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids) {
  // Lists taken from the binned stage are in id order already.
  if (!std::is_sorted(ids.begin(), ids.end())) {
    std::sort(ids.begin(), ids.end());
  }
  KdTreeNode& nd = tree_.nodes[node];
  nd.leaf = true;
  nd.first = static_cast<std::uint32_t>(tree_.items.size());
  nd.count = static_cast<std::uint32_t>(ids.size());
  tree_.items.insert(tree_.items.end(), ids.begin(), ids.end());
}

// One piece of a cut polygon (clip_split): the binary64 bounds of its vertices, exact
// coordinates as they are and the others widened by w, then rounded outward to binary32 within
// the child box and the triangle's own bounds.
struct PieceBounds {
  double l[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                 std::numeric_limits<double>::infinity()};
  double h[3] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                 -std::numeric_limits<double>::infinity()};
  int count = 0;
  void add(const double x[3], std::uint8_t exact, const double w[3]) {
    for (int k = 0; k < 3; ++k) {
      const bool e = exact & (1u << k);
      l[k] = std::min(l[k], e ? x[k] : x[k] - w[k]);
      h[k] = std::max(h[k], e ? x[k] : x[k] + w[k]);
    }
    ++count;
  }
  bool bound(const Box& b, const float tlo[3], const float thi[3], float lo[3], float hi[3]) const {
    // All three axes, then one test (the outputs are only read when a piece exists).
    bool empty = count == 0;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max({float_down(l[k]), b.lo[k], tlo[k]});
      hi[k] = std::min({float_up(h[k]), b.hi[k], thi[k]});
      empty |= lo[k] > hi[k];
    }
    return !empty;
  }
};

// Perfect splits: the straddling item clipped to the node's box and cut by the plane; fills both
// children's clipped bounds. Returns bit 0 when a left piece exists, bit 1 when a right one does.
//
// Triangles are clipped (Sutherland-Hodgman, binary64) once to the node box, then the polygon is
// cut in two. Bounds are conservative: exact coordinates (input vertices, clip-plane coordinates,
// interpolations between equal exact values) are taken as they are; interpolated ones are widened
// by 2^-32 of the triangle's magnitude before rounding outward to binary32, which covers the
// binary64 rounding. Boxes are intersected exactly.
int Builder::clip_split(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                        float lhi[3], float rlo[3], float rhi[3]) const {
  Box lbox = box;
  Box rbox = box;
  lbox.hi[axis] = split;
  rbox.lo[axis] = split;
  if (!triangles_) {
    const Aabb& a = boxes_[id];
    int result = 3;
    for (int k = 0; k < 3; ++k) {
      llo[k] = std::max(a.lo[k], lbox.lo[k]);
      lhi[k] = std::min(a.hi[k], lbox.hi[k]);
      rlo[k] = std::max(a.lo[k], rbox.lo[k]);
      rhi[k] = std::min(a.hi[k], rbox.hi[k]);
      if (llo[k] > lhi[k]) result &= ~1;
      if (rlo[k] > rhi[k]) result &= ~2;
    }
    return result;
  }
  struct V {
    double x[3];
    std::uint8_t exact;  // bit k: coordinate k is exact
  };
  // Point on edge PQ where coordinate k equals c.
  auto cut = [](const V& P, const V& Q, int k, double c, double dp, double dq) {
    const double u = dp / (dp - dq);
    V R;
    R.exact = static_cast<std::uint8_t>(1u << k);
    for (int j = 0; j < 3; ++j) {
      if (j == k) {
        R.x[j] = c;
      } else {
        R.x[j] = P.x[j] + u * (Q.x[j] - P.x[j]);
        if (P.x[j] == Q.x[j] && (P.exact & Q.exact & (1u << j)))
          R.exact |= static_cast<std::uint8_t>(1u << j);
      }
    }
    return R;
  };
  V poly[2][12];
  int n = 3;
  const glm::uvec3 t = tris_[id];
  const glm::vec3* vp[3] = {&positions_[t.x], &positions_[t.y], &positions_[t.z]};
  float tlo[3];
  float thi[3];
  for (int k = 0; k < 3; ++k) {
    tlo[k] = std::min(std::min((*vp[0])[k], (*vp[1])[k]), (*vp[2])[k]);
    thi[k] = std::max(std::max((*vp[0])[k], (*vp[1])[k]), (*vp[2])[k]);
  }
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k)
      poly[0][i].x[k] = (*vp[i])[k];
    poly[0][i].exact = 7;
  }
  int cur = 0;
  for (int k = 0; k < 3 && n > 0; ++k) {
    for (int side = 0; side < 2 && n > 0; ++side) {
      if (side == 0 ? tlo[k] >= box.lo[k] : thi[k] <= box.hi[k]) continue;  // inside already
      const double c = side == 0 ? box.lo[k] : box.hi[k];
      const double sign = side == 0 ? 1.0 : -1.0;
      const V* in = poly[cur];
      V* out = poly[cur ^ 1];
      double dist[12];  // each vertex's signed distance, computed once for both its edges
      for (int i = 0; i < n; ++i)
        dist[i] = sign * (in[i].x[k] - c);
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const int i1 = i + 1 < n ? i + 1 : 0;
        const double dp = dist[i];
        const double dq = dist[i1];
        if (dp >= 0.0) out[m++] = in[i];
        if ((dp < 0.0) != (dq < 0.0)) out[m++] = cut(in[i], in[i1], k, c, dp, dq);
      }
      n = m;
      cur ^= 1;
    }
  }
  if (n == 0) return 0;
  // Cut the polygon at the plane; vertices on it belong to both pieces. Each piece's bounds are
  // gathered as its vertices are found (in polygon order, so ties between +0 and -0 resolve as
  // they would over the piece's vertex list): exact coordinates as they are, the others widened.
  constexpr double kWiden = 0x1p-32;
  double w[3];
  for (int k = 0; k < 3; ++k)
    w[k] = kWiden * std::max(std::fabs(tlo[k]), std::fabs(thi[k]));
  PieceBounds left;
  PieceBounds right;
  const V* pg = poly[cur];
  const double c = split;
  for (int i = 0; i < n; ++i) {
    const V& P = pg[i];
    const V& Q = pg[i + 1 < n ? i + 1 : 0];
    const double dp = P.x[axis] - c;
    const double dq = Q.x[axis] - c;
    if (dp <= 0.0) left.add(P.x, P.exact, w);
    if (dp >= 0.0) right.add(P.x, P.exact, w);
    if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) {
      const V R = cut(P, Q, axis, c, dp, dq);
      left.add(R.x, R.exact, w);
      right.add(R.x, R.exact, w);
    }
  }
  return (left.bound(lbox, tlo, thi, llo, lhi) ? 1 : 0) |
         (right.bound(rbox, tlo, thi, rlo, rhi) ? 2 : 0);
}

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

// Splits one axis's sorted event list into the children's lists in one pass, merging in the
// sorted new events of the straddling items. Returns the left count; *right_count the right one.
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

void Builder::build_node(std::uint32_t node, int depth, const Box& box, const std::size_t b[3],
                         const std::size_t e[3], std::uint32_t n, bool no_empty) {
  if (n <= static_cast<std::uint32_t>(p_.leaf_size) || depth >= p_.max_depth ||
      half_area(box) < min_half_area_) {
    make_leaf(node, b[0], e[0]);
    return;
  }
  const Split best = find_split(box, b, e, n, no_empty);
  const double leaf_cost = static_cast<double>(p_.intersection_cost) * n;
  if (best.axis < 0 || !(best.cost < leaf_cost * (best.face_slab ? kFaceSlabSlack : 1.0))) {
    make_leaf(node, b[0], e[0]);
    return;
  }
  const int k = best.axis;
  const std::uint32_t s = best.pos;
  const float split = unordered(s);

  // Classify against the stored plane (the grid value itself): ends at or before it are left,
  // starts at or after it right, planars at it go to the SAH's side, the rest straddle.
  std::uint8_t* side = side_.data();
  std::uint32_t n_left = 0;
  std::uint32_t n_right = 0;
  {
    // Branch-free: a start writes right or straddling, the end then marks left if it ends at or
    // before the plane; each item is counted at its last event (end or planar).
    const Key* ev = ev_[k].data();
    const std::uint8_t planar_side = best.planar_left ? kLeft : kRight;
    const std::size_t count = e[k] - b[k];
    both_.resize(count);
    std::uint32_t* both = both_.data();
    std::size_t nb = 0;
    for (std::size_t i = b[k]; i < e[k]; ++i) {
      const Key key = ev[i];
      const std::uint32_t id = key_id(key);
      const std::uint32_t pos = key_pos(key);
      const std::uint32_t t = key_type(key);
      const std::uint8_t cur = side[id];
      const std::uint8_t v_start = pos >= s ? kRight : kBoth;
      const std::uint8_t v_end = cur | (pos <= s ? kLeft : 0);
      const std::uint8_t v_planar = pos < s ? kLeft : pos > s ? kRight : planar_side;
      const std::uint8_t v = t == kStart ? v_start : t == kEnd ? v_end : v_planar;
      side[id] = v;
      const bool last = t != kStart;
      n_left += last & (v == kLeft);
      n_right += last & (v == kRight);
      both[nb] = id;
      nb += last & (v == kBoth);
    }
    both_.resize(nb);
  }
  // Items on one side only (each has at least one event per axis on that side alone).
  const std::uint32_t left_only = n_left;
  const std::uint32_t right_only = n_right;

  Box lbox = box;
  Box rbox = box;
  lbox.hi[k] = split;
  rbox.lo[k] = split;

  // Perfect splits: straddlers get new events from their bounds clipped to each child (not at
  // the last level, whose children are leaves at once).
  const bool last_level = depth + 1 >= p_.max_depth;
  for (int j = 0; j < 3; ++j) {
    new_left_[j].clear();
    new_right_[j].clear();
  }
  both_left_.clear();
  both_right_.clear();
  for (const std::uint32_t id : both_) {
    float llo[3];
    float lhi[3];
    float rlo[3];
    float rhi[3];
    const int pieces = clip_split(gid_[id], box, k, split, llo, lhi, rlo, rhi);
    // A clipped piece that only touches the plane is left to the other side.
    bool in_left = (pieces & 1) && llo[k] < split;
    bool in_right = (pieces & 2) && rhi[k] > split;
    if (!in_left && !in_right) {
      // Only possible through rounding on a sliver: keep the item somewhere rather than lose it.
      in_left = (pieces & 1) != 0;
      in_right = !in_left && (pieces & 2) != 0;
    }
    if (in_left) {
      if (!last_level) add_clipped(id, llo, lhi, new_left_);
      both_left_.push_back(gid_[id]);
      ++n_left;
    }
    if (in_right) {
      if (!last_level) add_clipped(id, rlo, rhi, new_right_);
      both_right_.push_back(gid_[id]);
      ++n_right;
    }
  }

  const std::uint32_t child = make_inner(node, k, split);

  const auto leaf_size = static_cast<std::uint32_t>(p_.leaf_size);
  if (last_level || (n_left <= leaf_size && n_right <= leaf_size)) {
    // Both children are leaves: their lists come straight from the classification (one entry
    // per item: its start or planar event on the split axis), no event lists are split.
    leaf_scratch_.clear();
    right_scratch_.clear();
    const Key* ev = ev_[k].data();
    for (std::size_t i = b[k]; i < e[k]; ++i) {
      const Key key = ev[i];
      if (key_type(key) == kEnd) continue;
      const std::uint32_t id = key_id(key);
      if (side[id] == kLeft) leaf_scratch_.push_back(gid_[id]);
      if (side[id] == kRight) right_scratch_.push_back(gid_[id]);
    }
    leaf_scratch_.insert(leaf_scratch_.end(), both_left_.begin(), both_left_.end());
    right_scratch_.insert(right_scratch_.end(), both_right_.begin(), both_right_.end());
    emit_leaf(child, leaf_scratch_);
    emit_leaf(child + 1, right_scratch_);
    return;
  }

  std::size_t lb[3];
  std::size_t le[3];
  std::size_t rb[3];
  std::size_t re[3];
  for (int j = 0; j < 3; ++j) {
    std::sort(new_left_[j].begin(), new_left_[j].end());
    std::sort(new_right_[j].begin(), new_right_[j].end());
    const std::size_t m = e[j] - b[j];
    Arena& a = ev_[j];
    // Bounds for the children's lists: the parent's minus at least one event per item of the
    // other side, plus the new ones, plus one slot that the branch-free filter may write past
    // the last kept event.
    const std::size_t cap_left = m - right_only + new_left_[j].size() + 1;
    const std::size_t cap_right = m - left_only + new_right_[j].size() + 1;
    a.ensure(a.top_ + cap_left + cap_right);
    Key* base = a.data();
    lb[j] = a.top_;
    rb[j] = a.top_ + cap_left;
    std::size_t rn = 0;
    const std::size_t ln = split_events(base + b[j], m, side, new_left_[j], new_right_[j],
                                        base + lb[j], base + rb[j], &rn);
    le[j] = lb[j] + ln;
    re[j] = rb[j] + rn;
    a.top_ = re[j];
  }

  std::size_t saved_top[3];
  for (int j = 0; j < 3; ++j)
    saved_top[j] = ev_[j].top_;
  const bool no_empty_below = forbid_empty_below(n_left, n_right);
  build_node(child, depth + 1, lbox, lb, le, n_left, no_empty_below);
  for (int j = 0; j < 3; ++j)
    ev_[j].top_ = saved_top[j];
  build_node(child + 1, depth + 1, rbox, rb, re, n_right, no_empty_below);
  for (int j = 0; j < 3; ++j)
    ev_[j].top_ = lb[j];
}

}  // namespace

float kd_split_round_down(float v, const ff::Format& f) {
  return SplitGrid(f).down(v);
}
float kd_split_round_up(float v, const ff::Format& f) {
  return SplitGrid(f).up(v);
}

KdTreeStats compute_kdtree_stats(const KdTree& tree, const KdBuildParams& params) {
  KdTreeStats st;
  st.build_seconds = tree.stats.build_seconds;
  st.node_cost = tree.stats.node_cost;
  st.nodes = static_cast<std::uint32_t>(tree.nodes.size());
  if (tree.nodes.empty()) return st;
  Box root{};
  for (int k = 0; k < 3; ++k) {
    root.lo[k] = tree.bounds.empty() ? 0.0f : tree.bounds.lo[k];
    root.hi[k] = tree.bounds.empty() ? 0.0f : tree.bounds.hi[k];
  }
  const double root_area = half_area(root);
  struct Item {
    std::uint32_t node;
    std::uint32_t depth;
    Box box;
  };
  std::vector<Item> stack{{0, 0, root}};
  std::uint64_t listed = 0;
  double steps = 0.0;
  double leaf_visits = 0.0;
  double fetched = 0.0;
  double tests = 0.0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const KdTreeNode& nd = tree.nodes[it.node];
    // Probability that a ray through the root box also passes this node's box.
    const double pr = root_area > 0.0 ? half_area(it.box) / root_area : 1.0;
    st.depth = std::max(st.depth, it.depth);
    if (nd.leaf) {
      ++st.leaves;
      if (nd.count == 0) ++st.empty_leaves;
      listed += nd.count;
      leaf_visits += pr;
      fetched += nd.count != 0 ? pr : 0.0;
      tests += pr * nd.count;
      continue;
    }
    steps += pr;
    const int link = chain_link(tree.nodes, nd, nd.child, nd.child + 1);
    st.empty_chain_links += link != 0;
    st.mergeable_chain_links += link == 2;
    Box l = it.box;
    Box r = it.box;
    l.hi[nd.axis] = nd.split;
    r.lo[nd.axis] = nd.split;
    stack.push_back({nd.child + 1, it.depth + 1, r});
    stack.push_back({nd.child, it.depth + 1, l});
  }
  const std::uint32_t full = st.leaves - st.empty_leaves;
  st.items_per_leaf = full > 0 ? static_cast<double>(listed) / full : 0.0;
  st.expected_traversal_steps = steps;
  st.expected_leaf_visits = leaf_visits;
  st.expected_fetched_leaves = fetched;
  st.expected_item_tests = tests;
  st.sah_cost = params.traversal_cost * steps + params.intersection_cost * tests;
  return st;
}

namespace {

// The node bound's search (docs/kdtree.md "Node bound"): the least cost per node that fits,
// found by steps of kNodeCostGrowth from kFirstNodeCost times K_T (up while over the bound,
// down while within) and kNodeCostBisections geometric bisections of the bracket (within a
// factor 4^(2^-3) = 1.19 of the least). The first guess fits the 2CylinderEngine's and the
// arena's trees (5 and 4.2 nodes per triangle at no cost) in one or two steps.
constexpr double kFirstNodeCost = 0x1p-16;
constexpr double kNodeCostGrowth = 4.0;
constexpr int kMaxNodeCostSteps = 10;
constexpr int kNodeCostBisections = 3;

// build_once(node_cost) builds one tree with that cost per node.
template <class BuildOnce>
KdTree build_bounded(const KdBuildParams& params, std::size_t items, BuildOnce build_once) {
  const auto t0 = std::chrono::steady_clock::now();
  KdTree tree = build_once(0.0);
  const double budget = std::max(static_cast<double>(params.max_nodes_per_item) * items,
                                 static_cast<double>(params.node_floor));
  auto fits = [&](const KdTree& t) { return static_cast<double>(t.nodes.size()) <= budget; };
  if (params.max_nodes_per_item > 0.0f && !fits(tree)) {
    const double unit =
        params.traversal_cost > 0.0f ? params.traversal_cost : params.intersection_cost;
    double over = 0.0;    // the largest cost known to give too many nodes
    double within = 0.0;  // the least cost known to fit (tree holds its tree)
    double c = unit * kFirstNodeCost;
    for (int i = 0; i < kMaxNodeCostSteps && (over == 0.0 || within == 0.0); ++i) {
      KdTree t = build_once(c);
      if (fits(t)) {
        within = c;
        tree = std::move(t);
        c /= kNodeCostGrowth;
      } else {
        over = c;
        if (within == 0.0) tree = std::move(t);  // the smallest so far, if none fits
        c *= kNodeCostGrowth;
      }
    }
    for (int i = 0; i < kNodeCostBisections && over > 0.0 && within > 0.0; ++i) {
      const double mid = std::sqrt(over * within);
      KdTree t = build_once(mid);
      if (fits(t)) {
        tree = std::move(t);
        within = mid;
      } else {
        over = mid;
      }
    }
  }
  tree.stats = compute_kdtree_stats(tree, params);
  tree.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return tree;
}

std::size_t used_items(std::size_t n, std::span<const std::uint8_t> skip) {
  if (skip.size() != n) return n;  // the builder refuses a skip list of the wrong length
  return n - static_cast<std::size_t>(
                 std::count_if(skip.begin(), skip.end(), [](std::uint8_t v) { return v != 0; }));
}

}  // namespace

KdTree build_kdtree(std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                    std::span<const std::uint8_t> skip, const KdBuildParams& params) {
  const std::size_t items = skip.empty() ? tris.size() : used_items(tris.size(), skip);
  return build_bounded(params, items, [&](double node_cost) {
    KdTree tree;
    Builder(params, tree, node_cost).build_triangles(positions, tris, skip);
    tree.stats.node_cost = node_cost;
    return tree;
  });
}

KdTree build_kdtree(std::span<const Aabb> boxes, const KdBuildParams& params) {
  const auto items = static_cast<std::size_t>(
      std::count_if(boxes.begin(), boxes.end(), [](const Aabb& b) { return !b.empty(); }));
  return build_bounded(params, items, [&](double node_cost) {
    KdTree tree;
    Builder(params, tree, node_cost).build_boxes(boxes);
    tree.stats.node_cost = node_cost;
    return tree;
  });
}

}  // namespace saarcor::host

namespace saarcor::host {

int kd_auto_max_depth(std::size_t items) {
  int log2 = 0;
  while (items > 1) {
    items >>= 1;
    ++log2;
  }
  return static_cast<int>(std::lround(8.0 + 1.3 * log2));
}

int kd_max_depth(const KdBuildParams& params, std::size_t items) {
  return params.max_depth == KdBuildParams::kAutoDepth ? kd_auto_max_depth(items)
                                                       : params.max_depth;
}

}  // namespace saarcor::host
