// The kd-tree builder's private interface (host/kdtree.h is the public one): the split grid, the
// event keys of the exact stage, the item lists of the binned stage and the Builder whose
// member functions are spread over the kd_*.cpp files, one stage or pass per file:
//   kdtree.cpp      input checks, item bounds, the node bound's search, the public entry points
//   kd_binning.cpp  the binned-SAH stage at the top of the tree (bins, planes, children's lists)
//   kd_bin_simd.cpp the binned stage's SIMD kernels: histogram fill and the three-axis bin sweep
//   kd_events.cpp   event keys sorted (rank sort, radix sort), split and made from clipped bounds
//   kd_sweep.cpp    the exact stage (Wald & Havran): the per-axis event sweep, face slabs, the
//                   classification against the plane and the recursion
//   kd_clip.cpp     perfect splits: a straddling item clipped to the node and cut by the plane
//   kd_postpass.cpp chain links of empty cuts and their merge (KdBuildParams::empty_chains)
//   kd_stats.cpp    the SAH-expected statistics of a finished tree
// Nothing outside host/kd*.cpp includes this header.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>

#include "host/float_bounds.h"
#include "host/kdtree.h"
#include "hw/huge_pages.h"

// The bin sweep and the rank sort have 256-bit paths, chosen at run time where the processor has
// AVX (AVX2 for the sort); the files that use them include <immintrin.h>.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SAARCOR_KD_AVX 1
#else
#define SAARCOR_KD_AVX 0
#endif

namespace saarcor::host::kd {

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

// ---- events (kd_events.cpp) -------------------------------------------------------------------

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

// Stable LSD radix sort on bits [30, 64) (ties keep their order, i.e. ascending id when the input
// is in id order; the id bits are compared only through that stability).
void radix_sort(Key* data, std::size_t n, std::vector<Key>& scratch);
// Splits one axis's sorted event list into the children's lists in one pass, merging in the
// sorted new events of the straddling items. Returns the left count; *right_count the right one.
std::size_t split_events(const Key* ev, std::size_t n, const std::uint8_t* side,
                         const std::vector<Key>& add_left, const std::vector<Key>& add_right,
                         Key* left, Key* right, std::size_t* right_count);

// ---- lists ------------------------------------------------------------------------------------

// A list used as a stack (one axis's events, or the binned stage's items): a node's list is a
// range; its children go on top and are popped when the subtree is done.
// Large stacks (the root's item list of a big mesh and the lists above it) are asked for in 2 MB
// pages (hw::HugePageAllocator) from 8 MB on: every build touches them afresh, and 4 KB pages
// cost a page fault each.
template <class T>
class Stack {
  static_assert(std::is_trivially_copyable_v<T> && alignof(T) <= 16);
  using Alloc = hw::HugePageAllocator<T, 4 * hw::kHugePage>;

 public:
  Stack() = default;
  Stack(const Stack&) = delete;
  Stack& operator=(const Stack&) = delete;
  ~Stack() { release(); }

  T* data() const { return buf_; }
  void ensure(std::size_t n) {
    if (n <= cap_) return;
    const std::size_t cap = std::max(n, cap_ + cap_ / 2);
    T* buf = Alloc{}.allocate(cap);
    if (top_ > 0) std::copy(buf_, buf_ + top_, buf);
    release();
    buf_ = buf;
    cap_ = cap;
  }
  std::size_t top_ = 0;

 private:
  void release() {
    if (buf_ != nullptr) Alloc{}.deallocate(buf_, cap_);
  }
  T* buf_ = nullptr;
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
inline std::array<double, 3> extents(const Box& b) {
  return {static_cast<double>(b.hi[0]) - b.lo[0], static_cast<double>(b.hi[1]) - b.lo[1],
          static_cast<double>(b.hi[2]) - b.lo[2]};
}
inline double half_area(const std::array<double, 3>& d) {
  return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}
inline double half_area(const Box& b) {
  return half_area(extents(b));
}
// The two children's boxes of a cut of `box` at `split` on axis k.
inline void split_box(const Box& box, int k, float split, Box& left, Box& right) {
  left = box;
  right = box;
  left.hi[k] = split;
  right.lo[k] = split;
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

// ---- chain links (kd_postpass.cpp) ------------------------------------------------------------

inline bool is_empty_leaf(const KdTreeNode& nd) {
  return nd.leaf && nd.count == 0;
}
// The chain link at an inner node whose children are `l` and `r` (KdTreeStats): 1 where one child
// is an empty leaf and the other an inner node with an empty-leaf child, 2 where that inner node
// also cuts on the same axis with its empty child on the same side (mergeable), else 0.
int chain_link(const std::vector<KdTreeNode>& nodes, const KdTreeNode& nd, std::uint32_t l,
               std::uint32_t r);

// ---- the binned stage's kernels (kd_bin_simd.cpp) ---------------------------------------------

// Per axis the bins of one node: bin f(x) = trunc(clamp((x - base) * scale, 0, top)).
struct BinGrid {
  int nb[3];
  float scale[3];
  float base[3];
  float top[3];
  int nb_max;
};
// The bins' counts, per bin the three axes side by side (and a zero lane): the sweep reads one
// bin of all axes at once.
constexpr int kHistLanes = 4;
using BinHist = std::uint32_t[kMaxBins][kHistLanes];

// Counts every item's lower bound into hist_lo and its key into hist_hi (the first nb_max bins,
// zeroed here), and gathers the items' lowest lower bound and highest key per axis.
void fill_bins(const BinGrid& g, const BinItem* items, std::uint32_t n, BinHist& hist_lo,
               BinHist& hist_hi, float tlo[3], float tkey[3]);

// The three axes' bin-plane sweeps of one node: inputs nc (planes), da, al, ar per axis (nc = 0
// for a flat axis; kd_bin_simd.cpp's BinScan says what they are), outputs each axis's first
// least plane: best_m the least aL * nL + aR * nR over planes with items on both sides, best_j
// its index (-1: none).
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
void sweep_bins(const BinHist& hist_lo, const BinHist& hist_hi, int nb_max, std::uint32_t n,
                BinSweep& sw);

// ---- the builder --------------------------------------------------------------------------------

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

// The constants of one node's plane costs in the exact sweep (Builder::find_split): per
// candidate the sweep compares m = aL*nL + aR*nR + nP*min(aL, aR) (+ step * (aL + aR) with leaf
// steps), the full cost being kt0 + scale * m.
struct SweepCosts {
  double kt;
  double ki;
  double inv_area;
  double scale;  // ki / area
  double step;   // with leaf steps K_T / K_I, else 0
  double kt0;    // with leaf steps 0, else K_T
};

// The pieces of a straddling item on each side of a plane (Builder::clip_split's output).
struct Pieces {
  float llo[3];
  float lhi[3];
  float rlo[3];
  float rhi[3];
  bool in_left;
  bool in_right;
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
  // ---- input and the shared node output (kdtree.cpp)
  static const KdBuildParams& checked(const KdBuildParams& p);
  void check_coordinate(float v, const char* what, std::size_t index) const;
  void check_triangle(std::size_t i, const glm::uvec3& t) const;
  void start(std::size_t items);
  void add_item(std::uint32_t id, const float lo[3], const float hi[3]);
  void run();
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
  void emit_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids);
  // A node is a leaf without a search: few items, the depth limit, or a negligible area.
  bool must_be_leaf(std::uint32_t n, int depth, const Box& box) const {
    return n <= static_cast<std::uint32_t>(p_.leaf_size) || depth >= p_.max_depth ||
           half_area(box) < min_half_area_;
  }

  // ---- costs
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
  // The non-empty child of a cut with `nl`, `nr` items on its sides may not be cut off empty.
  bool forbid_empty_below(std::uint32_t nl, std::uint32_t nr) const {
    return p_.empty_chains == KdBuildParams::kChainsForbidden && (nl == 0 || nr == 0);
  }

  // ---- the split grid
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
  // A clipped piece's bounds rounded outward onto the grid, as a binned-stage item.
  void set_clipped_bin_item(BinItem& it, std::uint32_t id, float lo[3], float hi[3]) const {
    for (int j = 0; j < 3; ++j) {
      lo[j] = grid_.down(lo[j]);
      hi[j] = grid_.up(hi[j]);
    }
    set_bin_item(it, id, lo, hi);
  }
  float item_hi(const BinItem& it, int k) const {
    return (it.planar >> k) & 1u ? it.key[k] : grid_succ(it.key[k]);
  }

  // ---- the binned stage (kd_binning.cpp)
  // `no_empty`: the node is the non-empty child of an empty cut and KdBuildParams::empty_chains
  // forbids chains, so no plane with an empty side is considered for it.
  void bin_node(std::uint32_t node, int depth, const Box& box, std::size_t b, std::uint32_t n,
                bool no_empty);
  bool bin_node_is_leaf(std::uint32_t node, int depth, const Box& box, std::size_t b,
                        std::uint32_t n, bool no_empty);
  void partition_binned(const Box& box, const BinnedSplit& best, std::size_t b, std::uint32_t n,
                        std::size_t rb, std::uint32_t& nl, std::uint32_t& nr);
  BinnedSplit find_binned_split(const Box& box, const BinItem* items, std::uint32_t n,
                                bool no_empty) const;
  BinGrid bin_grid(const Box& box, const std::array<double, 3>& d, std::uint32_t n) const;
  int best_binned_plane(const Box& box, const std::array<double, 3>& d, const BinSweep& sw,
                        const float tlo[3], const float tkey[3], std::uint32_t n, bool no_empty,
                        BinnedSplit& best) const;
  float bin_threshold(const Box& box, const std::array<double, 3>& d, const BinGrid& g, int k,
                      int j) const;

  // ---- the exact stage (kd_sweep.cpp)
  void exact_subtree(std::uint32_t node, int depth, const Box& box, std::size_t b, std::uint32_t n,
                     bool no_empty);
  void build_node(std::uint32_t node, int depth, const Box& box, const std::size_t b[3],
                  const std::size_t e[3], std::uint32_t n, bool no_empty);
  void make_leaf(std::uint32_t node, std::size_t b0, std::size_t e0);
  Split find_split(const Box& box, const std::size_t b[3], const std::size_t e[3], std::uint32_t n,
                   bool no_empty) const;
  void sweep_axis(const Box& box, int k, const std::array<double, 3>& d, std::size_t b,
                  std::size_t e, std::uint32_t n, const SweepCosts& c, bool no_empty,
                  Split& best) const;
  void weigh_empty_side(int k, std::uint32_t pos, double al, double ar, std::uint32_t nl,
                        std::uint32_t nr, std::uint32_t np, const SweepCosts& c, bool no_empty,
                        Split& best, double& best_m) const;
  void face_slabs(const Box& box, int k, double sum, double prod, std::size_t b, std::size_t e,
                  std::uint32_t n, double kt, double inv_area, bool no_empty, Split& best) const;
  void classify(int k, std::size_t b, std::size_t e, std::uint32_t s, bool planar_left,
                std::uint32_t& n_left, std::uint32_t& n_right);
  void clip_straddlers(const Box& box, int k, float split, bool last_level, std::uint32_t& n_left,
                       std::uint32_t& n_right);
  void emit_child_leaves(std::uint32_t child, int k, std::size_t b, std::size_t e);
  void split_event_lists(const std::size_t b[3], const std::size_t e[3], std::uint32_t left_only,
                         std::uint32_t right_only, std::size_t lb[3], std::size_t le[3],
                         std::size_t rb[3], std::size_t re[3]);

  // ---- perfect splits (kd_clip.cpp)
  int clip_split(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                 float lhi[3], float rlo[3], float rhi[3]) const;
  Pieces straddler_pieces(std::uint32_t id, const Box& box, int axis, float split) const;
  int clip_triangle(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                    float lhi[3], float rlo[3], float rhi[3]) const;
  // ---- events from clipped bounds (kd_events.cpp)
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

}  // namespace saarcor::host::kd
