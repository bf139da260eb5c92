// Perfect splits (Wald & Havran 2006; Havran's thesis): a straddling item is clipped to the
// node's box and cut by the plane, and each child gets the bounds of its piece rather than the
// item's whole bounds, so the children's counts and areas are those of the pieces they hold.
#include <algorithm>

#include "host/kd_builder.h"

namespace saarcor::host::kd {
namespace {

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

// A polygon vertex in binary64 with, per coordinate, whether it is exact.
struct V {
  double x[3];
  std::uint8_t exact;  // bit k: coordinate k is exact
};
constexpr int kMaxPolygon = 12;  // a triangle clipped by six planes has at most 9 vertices
using Polygon = V[kMaxPolygon];

// Point on edge PQ where coordinate k equals c.
V cut(const V& P, const V& Q, int k, double c, double dp, double dq) {
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
}

// One Sutherland-Hodgman step: the part of `in` (n vertices) on the inside of the plane
// coordinate k = c (side 0: x >= c, side 1: x <= c) into `out`; returns its vertex count.
int clip_polygon(const V* in, int n, int k, int side, double c, V* out) {
  const double sign = side == 0 ? 1.0 : -1.0;
  double dist[kMaxPolygon];  // each vertex's signed distance, computed once for both its edges
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
  return m;
}

// The triangle (poly[0], exact vertices) clipped to the box on every face it crosses; returns the
// vertex count, the polygon in poly[cur].
int clip_to_box(Polygon poly[2], const Box& box, const float tlo[3], const float thi[3], int& cur) {
  int n = 3;
  cur = 0;
  for (int k = 0; k < 3 && n > 0; ++k) {
    for (int side = 0; side < 2 && n > 0; ++side) {
      if (side == 0 ? tlo[k] >= box.lo[k] : thi[k] <= box.hi[k]) continue;  // inside already
      const double c = side == 0 ? box.lo[k] : box.hi[k];
      n = clip_polygon(poly[cur], n, k, side, c, poly[cur ^ 1]);
      cur ^= 1;
    }
  }
  return n;
}

// Cut the polygon at the plane; vertices on it belong to both pieces. Each piece's bounds are
// gathered as its vertices are found (in polygon order, so ties between +0 and -0 resolve as
// they would over the piece's vertex list): exact coordinates as they are, the others widened
// by w.
void cut_polygon(const V* pg, int n, int axis, double c, const double w[3], PieceBounds& left,
                 PieceBounds& right) {
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
}

// Boxes (the top level's instance bounds) are intersected with each child's box exactly.
int clip_box(const Aabb& a, const Box& lbox, const Box& rbox, float llo[3], float lhi[3],
             float rlo[3], float rhi[3]) {
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

}  // namespace

// The straddling item clipped to the node's box and cut by the plane; fills both children's
// clipped bounds. Returns bit 0 when a left piece exists, bit 1 when a right one does.
int Builder::clip_split(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                        float lhi[3], float rlo[3], float rhi[3]) const {
  if (triangles_) return clip_triangle(id, box, axis, split, llo, lhi, rlo, rhi);
  Box lbox;
  Box rbox;
  split_box(box, axis, split, lbox, rbox);
  return clip_box(boxes_[id], lbox, rbox, llo, lhi, rlo, rhi);
}

// Triangles are clipped (Sutherland-Hodgman, binary64) once to the node box, then the polygon is
// cut in two. Bounds are conservative: exact coordinates (input vertices, clip-plane coordinates,
// interpolations between equal exact values) are taken as they are; interpolated ones are widened
// by 2^-32 of the triangle's magnitude before rounding outward to binary32, which covers the
// binary64 rounding.
int Builder::clip_triangle(std::uint32_t id, const Box& box, int axis, float split, float llo[3],
                           float lhi[3], float rlo[3], float rhi[3]) const {
  Polygon poly[2];
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
  const int n = clip_to_box(poly, box, tlo, thi, cur);
  if (n == 0) return 0;
  constexpr double kWiden = 0x1p-32;
  double w[3];
  for (int k = 0; k < 3; ++k)
    w[k] = kWiden * std::max(std::fabs(tlo[k]), std::fabs(thi[k]));
  PieceBounds left;
  PieceBounds right;
  cut_polygon(poly[cur], n, axis, split, w, left, right);
  Box lbox;
  Box rbox;
  split_box(box, axis, split, lbox, rbox);
  return (left.bound(lbox, tlo, thi, llo, lhi) ? 1 : 0) |
         (right.bound(rbox, tlo, thi, rlo, rhi) ? 2 : 0);
}

// The pieces a straddler leaves in the children, with the rules both stages share: a clipped
// piece that only touches the plane is left to the other side, and where rounding on a sliver
// leaves neither, the item is kept on one side rather than lost.
Pieces Builder::straddler_pieces(std::uint32_t id, const Box& box, int axis, float split) const {
  Pieces p{};
  const int pieces = clip_split(id, box, axis, split, p.llo, p.lhi, p.rlo, p.rhi);
  p.in_left = (pieces & 1) && p.llo[axis] < split;
  p.in_right = (pieces & 2) && p.rhi[axis] > split;
  if (!p.in_left && !p.in_right) {
    p.in_left = (pieces & 1) != 0;
    p.in_right = !p.in_left && (pieces & 2) != 0;
  }
  return p;
}

}  // namespace saarcor::host::kd
