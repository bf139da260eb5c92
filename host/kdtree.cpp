// SAH kd-tree builder: Wald & Havran, "On building fast kd-trees for ray tracing, and on doing
// that in O(N log N)" (2006), with perfect splits. Builds the paper's (section 2) bottom-level
// trees over an object's triangles and the top-level tree over instance bounds; the node layout
// follows DESIGN.md section 4 (root at 0, children adjacent, split positions in fp24).
//
// How it works (docs/kdtree.md has the long form):
// - Every item yields, per axis, a start and an end event at its bounds (a planar event when both
//   coincide). Event positions are rounded outward onto the split grid (the values representable
//   in params.split_format): starts down, ends up. A candidate plane is therefore always a value
//   the hardware can store, and the sweep's left/right counts are exact for that stored plane.
// - Events are sorted once (radix sort on a 64-bit key: position, type, item id). Per node, one
//   linear sweep per axis finds the SAH-best plane; the items are classified against it, the
//   events split into the children's lists in order (no re-sort), and only the items that
//   straddle the plane get new events from their clipped bounds (sorted, then merged in).
// - Memory: each axis has one event arena used as a stack (a node's children are written above
//   it and popped when the subtree is done), so there is no per-node allocation.
#include "host/kdtree.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

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
        min_normal_(std::ldexp(1.0f, f.emin())),
        max_finite_(
            static_cast<float>((2.0 - std::ldexp(1.0, -f.man_bits)) * std::ldexp(1.0, f.emax()))) {}

  float max_finite() const { return max_finite_; }
  // Largest grid value <= v (v finite, |v| <= max_finite()).
  float down(float v) const { return (v < 0.0f ? -up_mag(-v) : down_mag(v)) + 0.0f; }
  // Smallest grid value >= v.
  float up(float v) const { return (v < 0.0f ? -down_mag(-v) : up_mag(v)) + 0.0f; }

 private:
  float down_mag(float a) const {
    if (!(a >= min_normal_)) return 0.0f;
    return std::bit_cast<float>(std::bit_cast<std::uint32_t>(a) & ~mask_);
  }
  float up_mag(float a) const {
    if (a == 0.0f) return 0.0f;
    if (a <= min_normal_) return min_normal_;
    const std::uint32_t u = std::bit_cast<std::uint32_t>(a);
    std::uint32_t t = u & ~mask_;
    if (t != u) t += mask_ + 1u;  // carries into the exponent; stays <= max_finite for a <= it
    return std::bit_cast<float>(t);
  }

  std::uint32_t mask_;
  float min_normal_;
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

// Stable LSD radix sort on bits [30, 64) (ties keep their order, i.e. ascending id when the input
// is in id order; the id bits are compared only through that stability).
void radix_sort(Key* data, std::size_t n, std::vector<Key>& scratch) {
  constexpr int kDigit = 12;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  if (n < 64) {
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

// One axis's events, used as a stack: a node's list is a range; its children go on top.
class Arena {
 public:
  Key* data() const { return buf_.get(); }
  void ensure(std::size_t n) {
    if (n <= cap_) return;
    const std::size_t cap = std::max(n, cap_ + cap_ / 2);
    auto buf = std::make_unique_for_overwrite<Key[]>(cap);
    if (top_ > 0) std::copy(buf_.get(), buf_.get() + top_, buf.get());
    buf_ = std::move(buf);
    cap_ = cap;
  }
  std::size_t top_ = 0;

 private:
  std::unique_ptr<Key[]> buf_;
  std::size_t cap_ = 0;
};

struct Box {
  float lo[3];
  float hi[3];
};

// Item side after classification. kBoth items are dropped from the old lists (they get new
// events from their clipped bounds); the values make the split pass branch-free.
constexpr std::uint8_t kBoth = 0;
constexpr std::uint8_t kLeft = 1;
constexpr std::uint8_t kRight = 2;

// Neighbours of a finite binary32 value (inline: libm's nextafter is a call).
inline float float_next_down(float f) {
  const std::uint32_t u = std::bit_cast<std::uint32_t>(f);
  if (f == 0.0f) return -std::numeric_limits<float>::denorm_min();
  return std::bit_cast<float>(f > 0.0f ? u - 1u : u + 1u);
}
inline float float_next_up(float f) {
  return -float_next_down(-f);
}
// Rounding a binary64 value outward to binary32.
inline float float_down(double d) {
  const float f = static_cast<float>(d);
  return static_cast<double>(f) > d ? float_next_down(f) : f;
}
inline float float_up(double d) {
  const float f = static_cast<float>(d);
  return static_cast<double>(f) < d ? float_next_up(f) : f;
}

struct Split {
  double cost = std::numeric_limits<double>::infinity();
  int axis = -1;
  std::uint32_t pos = 0;  // ordered position
  bool planar_left = true;
};

class Builder {
 public:
  // Parameters are checked before anything is derived from them (the grid needs a valid format).
  Builder(const KdBuildParams& params, KdTree& tree)
      : p_(checked(params)), grid_(params.split_format), tree_(tree) {}

  void build_triangles(std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                       std::span<const std::uint8_t> skip);
  void build_boxes(std::span<const Aabb> boxes);

 private:
  static const KdBuildParams& checked(const KdBuildParams& p);
  void check_coordinate(float v, const char* what, std::size_t index) const;
  void start(std::size_t items);
  void add_item_events(std::uint32_t id, const float lo[3], const float hi[3]);
  void run();
  void build_node(std::uint32_t node, int depth, const Box& box, const std::size_t b[3],
                  const std::size_t e[3], std::uint32_t n);
  void make_leaf(std::uint32_t node, std::size_t b0, std::size_t e0);
  void emit_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids);
  Split find_split(const Box& box, const std::size_t b[3], const std::size_t e[3],
                   std::uint32_t n) const;
  int clip_split(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                 float lhi[3], float rlo[3], float rhi[3]) const;
  void add_clipped(std::uint32_t id, const float lo[3], const float hi[3], std::vector<Key>* out);

  const KdBuildParams& p_;
  SplitGrid grid_;
  KdTree& tree_;

  std::span<const glm::vec3> positions_;
  std::span<const glm::uvec3> tris_;
  std::span<const Aabb> boxes_;
  bool triangles_ = true;

  Arena ev_[3];
  std::vector<std::uint8_t> side_;
  std::vector<std::uint32_t> both_;
  std::vector<Key> new_left_[3];
  std::vector<Key> new_right_[3];
  std::vector<std::uint32_t> leaf_scratch_;
  std::vector<std::uint32_t> right_scratch_;
  std::vector<std::uint32_t> both_left_;  // straddlers kept on each side
  std::vector<std::uint32_t> both_right_;
  std::uint32_t item_count_ = 0;
  Box root_{};
};

const KdBuildParams& Builder::checked(const KdBuildParams& p) {
  const ff::Format& f = p.split_format;
  if (!f.valid()) throw std::runtime_error("kd-tree: invalid split format " + ff::format_name(f));
  if (!(p.traversal_cost >= 0.0f) || !(p.intersection_cost > 0.0f) ||
      !(p.empty_bonus > 0.0f && p.empty_bonus <= 1.0f))
    throw std::runtime_error(
        "kd-tree: cost parameters need traversal >= 0, intersection > 0, 0 < empty bonus <= 1");
  if (p.max_depth < 0 || p.max_depth > 1000)
    throw std::runtime_error("kd-tree: max depth " + std::to_string(p.max_depth) +
                             " outside 0..1000");
  if (p.leaf_size < 0)
    throw std::runtime_error("kd-tree: negative leaf size " + std::to_string(p.leaf_size));
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
  side_.assign(items, kBoth);
  for (auto& a : ev_) {
    a.top_ = 0;
    // Room for the initial lists (up to 2 events per item) and, stacked above them, the lists
    // along the recursion path (about 2 + 1 + 1/2 + ... times the initial ones, plus straddling
    // duplicates): 12 per item. Untouched pages cost nothing; growing copies everything.
    a.ensure(std::max<std::size_t>(64, items * 12));
  }
  for (int k = 0; k < 3; ++k) {
    root_.lo[k] = std::numeric_limits<float>::infinity();
    root_.hi[k] = -std::numeric_limits<float>::infinity();
  }
}

void Builder::add_item_events(std::uint32_t id, const float lo[3], const float hi[3]) {
  for (int k = 0; k < 3; ++k) {
    const float a = grid_.down(lo[k]);
    const float b = grid_.up(hi[k]);
    Key* out = ev_[k].data() + ev_[k].top_;
    if (a == b) {
      out[0] = make_key(ordered(a), kPlanar, id);
      ev_[k].top_ += 1;
    } else {
      out[0] = make_key(ordered(a), kStart, id);
      out[1] = make_key(ordered(b), kEnd, id);
      ev_[k].top_ += 2;
    }
    root_.lo[k] = std::min(root_.lo[k], a);
    root_.hi[k] = std::max(root_.hi[k], b);
  }
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
    // Only the vertices of used triangles matter (and must be finite and storable).
    for (const unsigned v : {t.x, t.y, t.z})
      for (int k = 0; k < 3; ++k)
        check_coordinate(positions[v][k], "vertex", v);
    const glm::vec3 lo = glm::min(glm::min(positions[t.x], positions[t.y]), positions[t.z]);
    const glm::vec3 hi = glm::max(glm::max(positions[t.x], positions[t.y]), positions[t.z]);
    const float l[3] = {lo.x, lo.y, lo.z};
    const float h[3] = {hi.x, hi.y, hi.z};
    add_item_events(static_cast<std::uint32_t>(i), l, h);
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
    add_item_events(static_cast<std::uint32_t>(i), l, h);
  }
  run();
}

void Builder::run() {
  tree_.nodes.clear();
  tree_.items.clear();
  tree_.nodes.reserve(std::size_t{item_count_} * 2 + 1);
  tree_.items.reserve(std::size_t{item_count_} * 3);
  tree_.nodes.emplace_back();
  if (item_count_ == 0) {
    tree_.nodes[0].leaf = true;
    tree_.bounds = Aabb{};
    return;
  }
  std::vector<Key> scratch;
  std::size_t b[3];
  std::size_t e[3];
  for (int k = 0; k < 3; ++k) {
    radix_sort(ev_[k].data(), ev_[k].top_, scratch);
    b[k] = 0;
    e[k] = ev_[k].top_;
  }
  tree_.bounds.lo = glm::vec3(root_.lo[0], root_.lo[1], root_.lo[2]);
  tree_.bounds.hi = glm::vec3(root_.hi[0], root_.hi[1], root_.hi[2]);
  build_node(0, 0, root_, b, e, item_count_);
}

Split Builder::find_split(const Box& box, const std::size_t b[3], const std::size_t e[3],
                          std::uint32_t n) const {
  Split best;
  const double d[3] = {static_cast<double>(box.hi[0]) - box.lo[0],
                       static_cast<double>(box.hi[1]) - box.lo[1],
                       static_cast<double>(box.hi[2]) - box.lo[2]};
  const double half_area = d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
  if (!(half_area > 0.0)) return best;  // a line or a point: no plane can separate anything
  const double inv_area = 1.0 / half_area;
  const double kt = p_.traversal_cost;
  const double ki = p_.intersection_cost;
  const double bonus = p_.empty_bonus;
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
    double best_m =
        std::isinf(best.cost) ? std::numeric_limits<double>::infinity() : (best.cost - kt) / scale;
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
          const double c1 = (nl1 == 0 || nr == 0 ? bonus : 1.0) *
                            (kt + ki * (al * inv_area * nl1 + ar * inv_area * nr));
          const double c2 = (nl == 0 || nr2 == 0 ? bonus : 1.0) *
                            (kt + ki * (al * inv_area * nl + ar * inv_area * nr2));
          if (c1 < best.cost || c2 < best.cost) {
            best = c1 <= c2 ? Split{c1, k, pos, true} : Split{c2, k, pos, false};
            best_m = (best.cost - kt) / scale;
          }
        } else if (m < best_m) {
          best_m = m;
          best = Split{kt + scale * m, k, pos, al <= ar};
        }
      }
      nl += pending;
      pending = 0;
      np = 0;
    }
  }
  return best;
}

void Builder::make_leaf(std::uint32_t node, std::size_t b0, std::size_t e0) {
  // Every item has exactly one start or planar event per axis.
  leaf_scratch_.clear();
  const Key* ev = ev_[0].data();
  for (std::size_t i = b0; i < e0; ++i)
    if (key_type(ev[i]) != kEnd) leaf_scratch_.push_back(key_id(ev[i]));
  emit_leaf(node, leaf_scratch_);
}

// A leaf's list in ascending item id (deterministic; the hardware's tie rule may depend on it).
void Builder::emit_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids) {
  std::sort(ids.begin(), ids.end());
  KdTreeNode& nd = tree_.nodes[node];
  nd.leaf = true;
  nd.first = static_cast<std::uint32_t>(tree_.items.size());
  nd.count = static_cast<std::uint32_t>(ids.size());
  tree_.items.insert(tree_.items.end(), ids.begin(), ids.end());
}

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
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const V& P = in[i];
        const V& Q = in[i + 1 < n ? i + 1 : 0];
        const double dp = sign * (P.x[k] - c);
        const double dq = sign * (Q.x[k] - c);
        if (dp >= 0.0) out[m++] = P;
        if ((dp < 0.0) != (dq < 0.0)) out[m++] = cut(P, Q, k, c, dp, dq);
      }
      n = m;
      cur ^= 1;
    }
  }
  if (n == 0) return 0;
  // Cut the polygon at the plane; vertices on it belong to both pieces.
  V left[12];
  V right[12];
  int nl = 0;
  int nr = 0;
  const V* pg = poly[cur];
  const double c = split;
  for (int i = 0; i < n; ++i) {
    const V& P = pg[i];
    const V& Q = pg[i + 1 < n ? i + 1 : 0];
    const double dp = P.x[axis] - c;
    const double dq = Q.x[axis] - c;
    if (dp <= 0.0) left[nl++] = P;
    if (dp >= 0.0) right[nr++] = P;
    if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) {
      const V R = cut(P, Q, axis, c, dp, dq);
      left[nl++] = R;
      right[nr++] = R;
    }
  }
  constexpr double kWiden = 0x1p-32;
  auto bound = [&](const V* pv, int count, const Box& b, float lo[3], float hi[3]) {
    if (count == 0) return false;
    for (int k = 0; k < 3; ++k) {
      const double w = kWiden * std::max(std::fabs(tlo[k]), std::fabs(thi[k]));
      double l = std::numeric_limits<double>::infinity();
      double h = -std::numeric_limits<double>::infinity();
      for (int i = 0; i < count; ++i) {
        const bool exact = pv[i].exact & (1u << k);
        l = std::min(l, exact ? pv[i].x[k] : pv[i].x[k] - w);
        h = std::max(h, exact ? pv[i].x[k] : pv[i].x[k] + w);
      }
      lo[k] = std::max({float_down(l), b.lo[k], tlo[k]});
      hi[k] = std::min({float_up(h), b.hi[k], thi[k]});
      if (lo[k] > hi[k]) return false;
    }
    return true;
  };
  return (bound(left, nl, lbox, llo, lhi) ? 1 : 0) | (bound(right, nr, rbox, rlo, rhi) ? 2 : 0);
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
                         const std::size_t e[3], std::uint32_t n) {
  if (n <= static_cast<std::uint32_t>(p_.leaf_size) || depth >= p_.max_depth) {
    make_leaf(node, b[0], e[0]);
    return;
  }
  const Split best = find_split(box, b, e, n);
  if (best.axis < 0 || !(best.cost < static_cast<double>(p_.intersection_cost) * n)) {
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
    const int pieces = clip_split(id, box, k, split, llo, lhi, rlo, rhi);
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
      both_left_.push_back(id);
      ++n_left;
    }
    if (in_right) {
      if (!last_level) add_clipped(id, rlo, rhi, new_right_);
      both_right_.push_back(id);
      ++n_right;
    }
  }

  const auto child = static_cast<std::uint32_t>(tree_.nodes.size());
  {
    KdTreeNode& nd = tree_.nodes[node];
    nd.leaf = false;
    nd.axis = static_cast<std::uint8_t>(k);
    nd.split = split;
    nd.child = child;
  }
  tree_.nodes.emplace_back();
  tree_.nodes.emplace_back();

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
      if (side[id] == kLeft) leaf_scratch_.push_back(id);
      if (side[id] == kRight) right_scratch_.push_back(id);
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
  build_node(child, depth + 1, lbox, lb, le, n_left);
  for (int j = 0; j < 3; ++j)
    ev_[j].top_ = saved_top[j];
  build_node(child + 1, depth + 1, rbox, rb, re, n_right);
  for (int j = 0; j < 3; ++j)
    ev_[j].top_ = lb[j];
}

double half_area(const Box& b) {
  const double d0 = static_cast<double>(b.hi[0]) - b.lo[0];
  const double d1 = static_cast<double>(b.hi[1]) - b.lo[1];
  const double d2 = static_cast<double>(b.hi[2]) - b.lo[2];
  return d0 * d1 + d1 * d2 + d2 * d0;
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
      tests += pr * nd.count;
      continue;
    }
    steps += pr;
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
  st.expected_item_tests = tests;
  st.sah_cost = params.traversal_cost * steps + params.intersection_cost * tests;
  return st;
}

KdTree build_kdtree(std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                    std::span<const std::uint8_t> skip, const KdBuildParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  KdTree tree;
  Builder(params, tree).build_triangles(positions, tris, skip);
  tree.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  tree.stats = compute_kdtree_stats(tree, params);
  return tree;
}

KdTree build_kdtree(std::span<const Aabb> boxes, const KdBuildParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  KdTree tree;
  Builder(params, tree).build_boxes(boxes);
  tree.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  tree.stats = compute_kdtree_stats(tree, params);
  return tree;
}

}  // namespace saarcor::host
