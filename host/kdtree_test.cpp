// Tests of the SAH kd-tree builder (host/kdtree.h, docs/kdtree.md; paper section 2,
// docs/memory-image.md): the tree's lists against exact triangle-box overlap, node structure and
// split rounding, point and ray queries against brute force, the top level over boxes, degenerate
// inputs and bad input.
#include "host/kdtree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace saarcor::host {
namespace {

#ifdef SAARCOR_SANITIZED
constexpr int kScale = 4;  // fewer rays and smaller meshes under ASan/UBSan
#else
constexpr int kScale = 1;
#endif

struct Mesh {
  std::vector<glm::vec3> pos;
  std::vector<glm::uvec3> tris;
  std::vector<std::uint8_t> skip;
};

Mesh random_triangles(int n, std::uint32_t seed, float spread, float size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> c(-spread, spread);
  std::uniform_real_distribution<float> o(-size, size);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Mesh m;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 center(c(rng), c(rng), c(rng));
    // A few large triangles so that many straddle planes.
    const float s = u(rng) < 0.05f ? 8.0f : 1.0f;
    const auto base = static_cast<unsigned>(m.pos.size());
    for (int v = 0; v < 3; ++v)
      m.pos.push_back(center + s * glm::vec3(o(rng), o(rng), o(rng)));
    m.tris.emplace_back(base, base + 1, base + 2);
  }
  return m;
}

// Planar grid in z = 0: every triangle in one plane, the root box flat.
Mesh planar_grid(int nx, int ny) {
  Mesh m;
  for (int y = 0; y <= ny; ++y)
    for (int x = 0; x <= nx; ++x)
      m.pos.emplace_back(0.5f * x, 0.25f * y, 0.0f);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const auto i = static_cast<unsigned>(y * (nx + 1) + x);
      m.tris.emplace_back(i, i + 1, i + nx + 2);
      m.tris.emplace_back(i, i + nx + 2, i + nx + 1);
    }
  return m;
}

Mesh terrain(int nx, int ny, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> h(-0.3f, 0.3f);
  Mesh m;
  for (int y = 0; y <= ny; ++y)
    for (int x = 0; x <= nx; ++x)
      m.pos.emplace_back(static_cast<float>(x),
                         2.0f * std::sin(0.1f * x) * std::cos(0.13f * y) + h(rng),
                         static_cast<float>(y));
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const auto i = static_cast<unsigned>(y * (nx + 1) + x);
      m.tris.emplace_back(i, i + 1, i + nx + 2);
      m.tris.emplace_back(i, i + nx + 2, i + nx + 1);
    }
  return m;
}

Mesh sphere(int stacks, int slices, glm::vec3 center, float r) {
  Mesh m;
  for (int i = 0; i <= stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double ph = 2.0 * M_PI * j / slices;
      m.pos.push_back(center + r * glm::vec3(static_cast<float>(std::sin(th) * std::cos(ph)),
                                             static_cast<float>(std::cos(th)),
                                             static_cast<float>(std::sin(th) * std::sin(ph))));
    }
  }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const auto a = static_cast<unsigned>(i * slices + j);
      const auto b = static_cast<unsigned>(i * slices + (j + 1) % slices);
      const auto c = a + static_cast<unsigned>(slices);
      const auto d = b + static_cast<unsigned>(slices);
      if (i > 0) m.tris.emplace_back(a, b, d);
      if (i < stacks - 1) m.tris.emplace_back(a, d, c);
    }
  return m;
}

void append(Mesh& m, const Mesh& o) {
  const auto base = static_cast<unsigned>(m.pos.size());
  m.pos.insert(m.pos.end(), o.pos.begin(), o.pos.end());
  for (const auto& t : o.tris)
    m.tris.push_back(t + glm::uvec3(base));
}

// Axis-aligned cube surface: every triangle lies in a face of the root box.
Mesh cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.pos.emplace_back((i & 1) ? 1.0f : -1.0f, (i & 2) ? 2.0f : -2.0f, (i & 4) ? 0.5f : -0.5f);
  const unsigned f[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                            {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& q : f) {
    m.tris.emplace_back(q[0], q[1], q[2]);
    m.tris.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

// Stanford bunny (shared scenes, ASCII PLY): a real scanned mesh.
bool load_bunny(Mesh* m) {
  std::ifstream in(std::string(SAARCOR_SHARED_SCENES) + "/StanfordBunny/bun_zipper.ply");
  if (!in) return false;
  std::string line;
  std::size_t nv = 0;
  std::size_t nf = 0;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string w;
    std::string what;
    ls >> w >> what;
    if (w == "element" && what == "vertex") ls >> nv;
    if (w == "element" && what == "face") ls >> nf;
  }
  for (std::size_t i = 0; i < nv && std::getline(in, line); ++i) {
    std::istringstream ls(line);
    glm::vec3 p;
    ls >> p.x >> p.y >> p.z;
    m->pos.push_back(p);
  }
  for (std::size_t i = 0; i < nf && std::getline(in, line); ++i) {
    std::istringstream ls(line);
    int k = 0;
    glm::uvec3 t;
    ls >> k >> t.x >> t.y >> t.z;
    if (k == 3) m->tris.push_back(t);
  }
  return m->tris.size() == nf && nf > 0;
}

// ---- exact-ish geometry in binary64 ------------------------------------------------------------

struct DBox {
  glm::dvec3 lo;
  glm::dvec3 hi;
};

// Separating-axis test (Akenine-Moeller) of a triangle against a closed box.
bool tri_box_overlap(const DBox& b, glm::dvec3 v0, glm::dvec3 v1, glm::dvec3 v2) {
  const glm::dvec3 c = 0.5 * (b.lo + b.hi);
  const glm::dvec3 h = 0.5 * (b.hi - b.lo);
  v0 -= c;
  v1 -= c;
  v2 -= c;
  for (int k = 0; k < 3; ++k) {
    if (std::min({v0[k], v1[k], v2[k]}) > h[k] || std::max({v0[k], v1[k], v2[k]}) < -h[k])
      return false;
  }
  const glm::dvec3 e[3] = {v1 - v0, v2 - v1, v0 - v2};
  auto separated = [&](const glm::dvec3& a) {
    const double p0 = glm::dot(a, v0);
    const double p1 = glm::dot(a, v1);
    const double p2 = glm::dot(a, v2);
    const double r = h.x * std::fabs(a.x) + h.y * std::fabs(a.y) + h.z * std::fabs(a.z);
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  if (separated(glm::cross(e[0], e[1]))) return false;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      glm::dvec3 axis(0.0);
      axis[k] = 1.0;
      if (separated(glm::cross(e[i], axis))) return false;
    }
  return true;
}

// The box shrunk (margin < 0) or grown (margin > 0); zero-extent axes stay closed as they are.
DBox adjust(const DBox& b, double margin) {
  DBox r = b;
  for (int k = 0; k < 3; ++k) {
    if (b.hi[k] > b.lo[k] || margin > 0.0) {
      r.lo[k] -= margin;
      r.hi[k] += margin;
    }
  }
  return r;
}

glm::dvec3 dv(const glm::vec3& v) {
  return glm::dvec3(v);
}

struct Leaf {
  std::uint32_t node;
  DBox box;
};

// All leaves with their boxes; checks structure on the way: root 0, every other node referenced
// once as child or child + 1 of an earlier node, splits on the grid and strictly inside the box.
std::vector<Leaf> walk(const KdTree& tree, const KdBuildParams& params) {
  std::vector<Leaf> leaves;
  std::vector<int> refs(tree.nodes.size(), 0);
  std::vector<std::pair<std::uint32_t, DBox>> stack{
      {0, DBox{dv(tree.bounds.lo), dv(tree.bounds.hi)}}};
  while (!stack.empty()) {
    const auto [n, box] = stack.back();
    stack.pop_back();
    const KdTreeNode& nd = tree.nodes.at(n);
    if (nd.leaf) {
      leaves.push_back({n, box});
      EXPECT_LE(std::size_t{nd.first} + nd.count, tree.items.size());
      continue;
    }
    EXPECT_LT(nd.axis, 3);
    EXPECT_GT(nd.child, n);
    EXPECT_LT(nd.child + 1, tree.nodes.size());
    const ff::Mode rne{ff::Rounding::kNearestEven, ff::Subnormals::kFlush};
    const double stored = ff::decode(ff::from_double(nd.split, params.split_format, rne),
                                     params.split_format, ff::Subnormals::kFlush);
    EXPECT_EQ(stored, static_cast<double>(nd.split)) << "split not representable, node " << n;
    EXPECT_GT(nd.split, box.lo[nd.axis]) << "node " << n;
    EXPECT_LT(nd.split, box.hi[nd.axis]) << "node " << n;
    DBox l = box;
    DBox r = box;
    l.hi[nd.axis] = nd.split;
    r.lo[nd.axis] = nd.split;
    ++refs[nd.child];
    ++refs[nd.child + 1];
    stack.push_back({nd.child + 1, r});
    stack.push_back({nd.child, l});
  }
  EXPECT_EQ(refs[0], 0);
  for (std::size_t i = 1; i < refs.size(); ++i)
    EXPECT_EQ(refs[i], 1) << "node " << i;
  return leaves;
}

double scene_scale(const KdTree& tree) {
  double s = 1e-30;
  for (int k = 0; k < 3; ++k)
    s = std::max({s, std::fabs(double{tree.bounds.lo[k]}), std::fabs(double{tree.bounds.hi[k]})});
  return s;
}

bool in_list(const KdTree& tree, const KdTreeNode& leaf, std::uint32_t id) {
  const auto b = tree.items.begin() + leaf.first;
  return std::binary_search(b, b + leaf.count, id);
}

// The list invariants against exact triangle-box overlap:
// - each list is ascending, unique, holds no skipped triangle, and each item overlaps its leaf's
//   closed box (grown by a rounding margin);
// - each triangle overlapping a leaf's open box (shrunk by the margin; flat axes closed) is in
//   that leaf's list, and each triangle is in at least one leaf.
// `stride` > 1 checks completeness for every stride-th triangle only (large meshes).
void check_triangle_tree(const KdTree& tree, const Mesh& m, const KdBuildParams& params = {},
                         std::size_t stride = 1) {
  const std::vector<Leaf> leaves = walk(tree, params);
  const double margin = 1e-9 * scene_scale(tree);
  std::uint64_t listed = 0;
  for (const Leaf& lf : leaves) {
    const KdTreeNode& nd = tree.nodes[lf.node];
    const DBox grown = adjust(lf.box, margin);
    for (std::uint32_t i = 0; i < nd.count; ++i) {
      const std::uint32_t id = tree.items[nd.first + i];
      if (i > 0) {
        EXPECT_LT(tree.items[nd.first + i - 1], id) << "leaf " << lf.node;
      }
      ASSERT_LT(id, m.tris.size());
      EXPECT_TRUE(m.skip.empty() || m.skip[id] == 0) << "skipped triangle " << id << " listed";
      const glm::uvec3 t = m.tris[id];
      EXPECT_TRUE(tri_box_overlap(grown, dv(m.pos[t.x]), dv(m.pos[t.y]), dv(m.pos[t.z])))
          << "triangle " << id << " listed in leaf " << lf.node << " it does not overlap";
    }
    listed += nd.count;
  }
  EXPECT_EQ(tree.stats.leaves, leaves.size());
  // Completeness: descend per triangle through every node its (closed) box overlaps.
  for (std::size_t id = 0; id < m.tris.size(); id += stride) {
    if (!m.skip.empty() && m.skip[id] != 0) continue;
    const glm::uvec3 t = m.tris[id];
    const glm::dvec3 a = dv(m.pos[t.x]);
    const glm::dvec3 b = dv(m.pos[t.y]);
    const glm::dvec3 c = dv(m.pos[t.z]);
    bool found = false;
    std::vector<std::pair<std::uint32_t, DBox>> stack{
        {0, DBox{dv(tree.bounds.lo), dv(tree.bounds.hi)}}};
    while (!stack.empty()) {
      const auto [n, box] = stack.back();
      stack.pop_back();
      if (!tri_box_overlap(adjust(box, margin), a, b, c)) continue;
      const KdTreeNode& nd = tree.nodes[n];
      if (nd.leaf) {
        const bool listed_here = in_list(tree, nd, static_cast<std::uint32_t>(id));
        found = found || listed_here;
        if (tri_box_overlap(adjust(box, -margin), a, b, c)) {
          EXPECT_TRUE(listed_here)
              << "triangle " << id << " overlaps leaf " << n << " but is not in its list";
        }
        continue;
      }
      DBox l = box;
      DBox r = box;
      l.hi[nd.axis] = nd.split;
      r.lo[nd.axis] = nd.split;
      stack.push_back({nd.child + 1, r});
      stack.push_back({nd.child, l});
    }
    EXPECT_TRUE(found) << "triangle " << id << " is in no leaf";
  }
}

// ---- ray queries ----------------------------------------------------------------------------

struct Ray {
  glm::dvec3 o;
  glm::dvec3 d;
};
struct Hit {
  double t = std::numeric_limits<double>::infinity();
  std::int64_t id = -1;
};

// Moeller-Trumbore in binary64; the same function for the tree and the brute-force scan.
double intersect(const Ray& r, const Mesh& m, std::uint32_t id) {
  const glm::uvec3 t = m.tris[id];
  const glm::dvec3 a = dv(m.pos[t.x]);
  const glm::dvec3 e1 = dv(m.pos[t.y]) - a;
  const glm::dvec3 e2 = dv(m.pos[t.z]) - a;
  const glm::dvec3 p = glm::cross(r.d, e2);
  const double det = glm::dot(e1, p);
  if (det == 0.0) return std::numeric_limits<double>::infinity();
  const double inv = 1.0 / det;
  const glm::dvec3 s = r.o - a;
  const double u = glm::dot(s, p) * inv;
  if (u < 0.0 || u > 1.0) return std::numeric_limits<double>::infinity();
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(r.d, q) * inv;
  if (v < 0.0 || u + v > 1.0) return std::numeric_limits<double>::infinity();
  const double tt = glm::dot(e2, q) * inv;
  return tt >= 0.0 ? tt : std::numeric_limits<double>::infinity();
}

void consider(Hit& h, double t, std::uint32_t id) {
  if (t < h.t || (t == h.t && id < h.id)) h = Hit{t, id};
}

Hit brute_force(const Ray& r, const Mesh& m) {
  Hit h;
  for (std::uint32_t i = 0; i < m.tris.size(); ++i)
    if (m.skip.empty() || m.skip[i] == 0) consider(h, intersect(r, m, i), i);
  return h;
}

// A plain front-to-back kd-tree traversal with a stack (binary64, with a little slack so that
// rounding never loses a cell).
Hit traverse(const KdTree& tree, const Ray& r, const Mesh& m, double slack) {
  Hit h;
  double t0 = 0.0;
  double t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double lo = tree.bounds.lo[k];
    const double hi = tree.bounds.hi[k];
    if (r.d[k] == 0.0) {
      if (r.o[k] < lo || r.o[k] > hi) return h;
      continue;
    }
    double a = (lo - r.o[k]) / r.d[k];
    double b = (hi - r.o[k]) / r.d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a - slack);
    t1 = std::min(t1, b + slack);
  }
  if (t0 > t1) return h;
  struct Entry {
    std::uint32_t node;
    double t0;
    double t1;
  };
  std::vector<Entry> stack;
  std::uint32_t n = 0;
  for (;;) {
    const KdTreeNode& nd = tree.nodes[n];
    if (!nd.leaf) {
      const int k = nd.axis;
      const double o = r.o[k];
      const double s = nd.split;
      const std::uint32_t left = nd.child;
      const std::uint32_t right = nd.child + 1;
      if (r.d[k] == 0.0) {
        if (o < s) {
          n = left;
        } else if (o > s) {
          n = right;
        } else {
          stack.push_back({right, t0, t1});
          n = left;
        }
        continue;
      }
      const double t = (s - o) / r.d[k];
      const bool left_first = o < s || (o == s && r.d[k] < 0.0);
      const std::uint32_t near = left_first ? left : right;
      const std::uint32_t far = left_first ? right : left;
      if (t > t1 + slack || t < 0.0) {  // beyond the interval, or behind the origin
        n = near;
      } else if (t < t0 - slack) {
        n = far;
      } else {
        stack.push_back({far, std::max(t0, t - slack), t1});
        n = near;
        t1 = std::min(t1, t + slack);
      }
      continue;
    }
    for (std::uint32_t i = 0; i < nd.count; ++i) {
      const std::uint32_t id = tree.items[nd.first + i];
      consider(h, intersect(r, m, id), id);
    }
    if (h.t < t1 - slack || stack.empty()) return h;
    n = stack.back().node;
    t0 = stack.back().t0;
    t1 = stack.back().t1;
    stack.pop_back();
  }
}

void check_rays(const KdTree& tree, const Mesh& m, int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<std::size_t> pick(0, m.tris.size() - 1);
  const glm::dvec3 lo = dv(tree.bounds.lo);
  const glm::dvec3 hi = dv(tree.bounds.hi);
  const glm::dvec3 ext = glm::max(hi - lo, glm::dvec3(1e-3));
  const double slack = 1e-9 * scene_scale(tree);
  int hits = 0;
  for (int i = 0; i < count; ++i) {
    Ray r;
    r.o = lo - 0.25 * ext + 1.5 * ext * glm::dvec3(u(rng), u(rng), u(rng));
    if (i % 3 == 0) {
      // Towards a random triangle's interior: most of these hit something.
      const glm::uvec3 t = m.tris[pick(rng)];
      const double a = u(rng);
      const double b = u(rng) * (1.0 - a);
      const glm::dvec3 target =
          dv(m.pos[t.x]) * (1.0 - a - b) + dv(m.pos[t.y]) * a + dv(m.pos[t.z]) * b;
      r.d = glm::normalize(target - r.o);
    } else {
      r.d = glm::normalize(glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    }
    if (i % 7 == 0) r.d[i % 3] = 0.0;  // rays parallel to split planes
    if (glm::length(r.d) == 0.0 || !std::isfinite(r.d.x)) continue;
    const Hit a = traverse(tree, r, m, slack);
    const Hit b = brute_force(r, m);
    ASSERT_EQ(std::isinf(a.t), std::isinf(b.t)) << "ray " << i;
    if (std::isinf(b.t)) continue;
    ++hits;
    if (a.id != b.id) {
      // Only a tie on a shared edge or vertex may pick another triangle.
      EXPECT_NEAR(a.t, b.t, 1e-9 * (1.0 + b.t))
          << "ray " << i << ": tree " << a.id << " brute " << b.id;
    } else {
      EXPECT_EQ(a.t, b.t);
    }
  }
  EXPECT_GT(hits, count / 4);  // the test must actually exercise hits
}

// Points on triangles: the leaves containing the point (closed boxes) must list every triangle
// through the point, as a brute-force scan finds them.
void check_points(const KdTree& tree, const Mesh& m, int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.02, 0.96);
  std::uniform_int_distribution<std::size_t> pick(0, m.tris.size() - 1);
  const double eps = 1e-7 * scene_scale(tree);
  for (int i = 0; i < count; ++i) {
    const std::size_t src = pick(rng);
    if (!m.skip.empty() && m.skip[src]) continue;
    const glm::uvec3 t = m.tris[src];
    const double a = u(rng);
    const double b = u(rng) * (1.0 - a);
    const glm::dvec3 p = dv(m.pos[t.x]) * (1.0 - a - b) + dv(m.pos[t.y]) * a + dv(m.pos[t.z]) * b;
    // Tree: all leaves whose closed box holds p.
    std::set<std::uint32_t> found;
    std::vector<std::uint32_t> stack{0};
    int leaves = 0;
    while (!stack.empty()) {
      const std::uint32_t n = stack.back();
      stack.pop_back();
      const KdTreeNode& nd = tree.nodes[n];
      if (nd.leaf) {
        ++leaves;
        found.insert(tree.items.begin() + nd.first, tree.items.begin() + nd.first + nd.count);
        continue;
      }
      if (p[nd.axis] <= nd.split) stack.push_back(nd.child);
      if (p[nd.axis] >= nd.split) stack.push_back(nd.child + 1);
    }
    ASSERT_GE(leaves, 1);
    // Brute force: every triangle whose closed box-neighbourhood of p it overlaps.
    const DBox near{p - glm::dvec3(eps), p + glm::dvec3(eps)};
    int through = 0;
    for (std::uint32_t id = 0; id < m.tris.size(); ++id) {
      if (!m.skip.empty() && m.skip[id]) continue;
      const glm::uvec3 q = m.tris[id];
      const glm::dvec3 qa = dv(m.pos[q.x]);
      const glm::dvec3 qb = dv(m.pos[q.y]);
      const glm::dvec3 qc = dv(m.pos[q.z]);
      if (glm::any(glm::lessThan(glm::max(glm::max(qa, qb), qc), near.lo)) ||
          glm::any(glm::greaterThan(glm::min(glm::min(qa, qb), qc), near.hi)))
        continue;  // quick reject on the bounds before the full test
      if (!tri_box_overlap(near, qa, qb, qc)) continue;
      ++through;
      EXPECT_TRUE(found.count(id)) << "point " << i << ": triangle " << id << " missing";
    }
    EXPECT_GE(through, 1);
  }
}

// ---- tests -----------------------------------------------------------------------------------

TEST(KdSplitGrid, DirectedRoundingMatchesTheFormatLibrary) {
  const ff::Mode rtz{ff::Rounding::kTowardZero, ff::Subnormals::kFlush};
  for (const ff::Format f : {ff::kFp24, ff::Format{5, 10}, ff::kFp32, ff::Format{8, 7}}) {
    // Reference: truncation through the format library, then one step away when inexact.
    auto next_away = [&](double r, double v) {
      std::uint32_t bits = ff::from_double(std::fabs(r), f, rtz);
      bits = bits == 0 ? (1u << f.man_bits) : bits + 1;  // smallest normal after zero
      const double mag = ff::decode(bits, f, ff::Subnormals::kFlush);
      return v < 0 ? -mag : mag;
    };
    auto ref_down = [&](float v) {
      const double r = ff::decode(ff::from_double(v, f, rtz), f, ff::Subnormals::kFlush);
      return r <= v ? r + 0.0 : next_away(r, v);
    };
    auto ref_up = [&](float v) {
      const double r = ff::decode(ff::from_double(v, f, rtz), f, ff::Subnormals::kFlush);
      return r >= v ? r + 0.0 : next_away(r, v);
    };
    std::mt19937 rng(7);
    std::vector<float> vals = {0.0f, -0.0f, 1.0f, -1.0f, 1e-30f, -1e-30f, 3.0f, 1.0f / 3.0f};
    const float min_normal = std::ldexp(1.0f, f.emin());
    vals.insert(vals.end(), {min_normal, -min_normal, std::nextafter(min_normal, 1.0f),
                             std::nextafter(min_normal, 0.0f), -std::nextafter(min_normal, 0.0f)});
    std::uniform_int_distribution<int> ex(f.emin() - 3, std::min(f.emax() - 1, 100));
    std::uniform_real_distribution<float> man(1.0f, 2.0f);
    for (int i = 0; i < 20000; ++i) {
      const float v = std::ldexp(man(rng), ex(rng)) * (i % 2 ? -1.0f : 1.0f);
      vals.push_back(v);
    }
    for (const float v : vals) {
      const float d = kd_split_round_down(v, f);
      const float up = kd_split_round_up(v, f);
      EXPECT_EQ(static_cast<double>(d), ref_down(v)) << ff::format_name(f) << " v=" << v;
      EXPECT_EQ(static_cast<double>(up), ref_up(v)) << ff::format_name(f) << " v=" << v;
      EXPECT_FALSE(std::signbit(d) && d == 0.0f);  // zero is always +0 (one key per position)
      EXPECT_FALSE(std::signbit(up) && up == 0.0f);
    }
  }
}

TEST(KdTree, RandomTrianglesInvariantsRaysAndPoints) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const Mesh m = random_triangles(1500 / kScale, seed, 10.0f, 0.7f);
    const KdTree tree = build_kdtree(m.pos, m.tris, {});
    SCOPED_TRACE("seed " + std::to_string(seed));
    EXPECT_GT(tree.stats.leaves, 50u);
    check_triangle_tree(tree, m);
    check_rays(tree, m, 3000 / kScale, seed);
    check_points(tree, m, 300 / kScale, seed);
  }
}

TEST(KdTree, SphereTerrainAndCube) {
  Mesh m = sphere(24, 32, glm::vec3(0.0f), 3.0f);
  append(m, sphere(12, 16, glm::vec3(2.5f, 0.5f, 0.0f), 1.0f));  // intersecting spheres
  Mesh t = terrain(40 / kScale, 30 / kScale, 5);
  const Mesh c = cube();
  for (const Mesh* mesh : std::vector<const Mesh*>{&m, &t, &c}) {
    const KdTree tree = build_kdtree(mesh->pos, mesh->tris, {});
    check_triangle_tree(tree, *mesh);
    check_rays(tree, *mesh, 2000 / kScale, 11);
    check_points(tree, *mesh, 200 / kScale, 12);
  }
}

// Items in a face of the node box (a room's walls) have their only event on the box bound, where
// no plane may lie; face slabs (docs/kdtree.md) peel them off, so that a ray through the interior
// tests none of them. Without them the cube's interior leaves held the walls. With the default
// costs (a traversal step 1.5 triangle tests, no empty bonus) a leaf holding one wall and empty
// space is cheaper than its slab, and the packet's triangle mailbox skips the wall's repeats;
// with steps cheaper than tests (Wald & Havran's 15 : 20, bonus 0.8) the slabs peel every wall.
TEST(KdTree, FaceSlabsKeepWallsOutOfTheInterior) {
  Mesh m = cube();  // triangles 0..11 lie in the root box's faces
  append(m, sphere(6, 8, glm::vec3(0.0f, 1.5f, 0.0f), 0.1f));
  KdBuildParams params;
  params.traversal_cost = 15.0f;
  params.empty_bonus = 0.8f;
  const KdTree tree = build_kdtree(m.pos, m.tris, {}, params);
  check_triangle_tree(tree, m);
  check_rays(tree, m, 2000 / kScale, 21);
  int interior_leaves = 0;
  for (const Leaf& leaf : walk(tree, params)) {
    // Leaves reaching into the cube's interior (the box shrunk by a tenth of its extent on each
    // side), which a ray crosses without being near a wall: no wall may be listed there.
    bool interior = true;
    for (int k = 0; k < 3; ++k) {
      const double margin = 0.1 * (double{tree.bounds.hi[k]} - tree.bounds.lo[k]);
      interior = interior && leaf.box.hi[k] > tree.bounds.lo[k] + margin &&
                 leaf.box.lo[k] < tree.bounds.hi[k] - margin;
    }
    if (!interior) continue;
    ++interior_leaves;
    const KdTreeNode& nd = tree.nodes[leaf.node];
    for (std::uint32_t i = 0; i < nd.count; ++i)
      EXPECT_GE(tree.items[nd.first + i], 12u) << "a wall in interior leaf " << leaf.node;
  }
  EXPECT_GT(interior_leaves, 0);
}

// Triangles meeting at shared vertices: their bounds, rounded outward onto the split grid, overlap
// by a grid step, and without the area bound the cells around the vertices were split down to a
// few grid steps, 8% of all leaves at the depth limit (under 1% with it).
TEST(KdTree, CellsAroundSharedVerticesStopAtTheAreaBound) {
  Mesh m = planar_grid(12, 12);
  // A shallow pyramid: vertex heights off the grid, the root box not flat.
  for (auto& p : m.pos)
    p.z = 0.05f * (std::fabs(p.x - 3.0f) + std::fabs(p.y - 1.5f));
  const KdBuildParams params;
  const KdTree tree = build_kdtree(m.pos, m.tris, {}, params);
  check_triangle_tree(tree, m);
  check_rays(tree, m, 2000 / kScale, 22);
  std::vector<int> depth(tree.nodes.size(), 0);
  int leaves = 0;
  int at_limit = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const KdTreeNode& nd = tree.nodes[i];
    if (nd.leaf) {
      ++leaves;
      at_limit += depth[i] >= kd_max_depth(params, m.tris.size());
      continue;
    }
    depth[nd.child] = depth[nd.child + 1] = depth[i] + 1;
  }
  EXPECT_LT(at_limit * 50, leaves) << at_limit << " of " << leaves << " leaves at the depth limit";
}

TEST(KdTree, StanfordBunny) {
  Mesh m;
  ASSERT_TRUE(load_bunny(&m)) << "cannot read the shared bunny";
  const KdTree tree = build_kdtree(m.pos, m.tris, {});
  EXPECT_EQ(tree.stats.nodes, tree.nodes.size());
  EXPECT_GT(tree.stats.depth, 12u);
  EXPECT_LT(tree.stats.sah_cost, 0.01 * 20.0 * m.tris.size());
  check_triangle_tree(tree, m, {}, 5 * kScale);
  check_rays(tree, m, 160 / kScale, 21);
  check_points(tree, m, 40 / kScale, 22);
}

TEST(KdTree, SkippedTrianglesAreLeftOut) {
  Mesh m = random_triangles(600, 9, 5.0f, 1.0f);
  m.skip.assign(m.tris.size(), 0);
  for (std::size_t i = 0; i < m.skip.size(); i += 3)
    m.skip[i] = 1;
  // A skipped (degenerate) triangle's vertices are not looked at.
  m.pos[m.tris[0].y].x = std::numeric_limits<float>::quiet_NaN();
  const KdTree tree = build_kdtree(m.pos, m.tris, m.skip);
  m.pos[m.tris[0].y].x = 0.0f;
  check_triangle_tree(tree, m);
  check_rays(tree, m, 600, 3);
  // All skipped: a single empty leaf.
  std::fill(m.skip.begin(), m.skip.end(), 1);
  const KdTree none = build_kdtree(m.pos, m.tris, m.skip);
  ASSERT_EQ(none.nodes.size(), 1u);
  EXPECT_TRUE(none.nodes[0].leaf);
  EXPECT_EQ(none.nodes[0].count, 0u);
  EXPECT_TRUE(none.bounds.empty());
}

TEST(KdTree, EmptyInputIsOneEmptyLeaf) {
  const KdTree tree = build_kdtree(std::span<const glm::vec3>{}, {}, {});
  ASSERT_EQ(tree.nodes.size(), 1u);
  EXPECT_TRUE(tree.nodes[0].leaf);
  EXPECT_EQ(tree.nodes[0].count, 0u);
  EXPECT_TRUE(tree.items.empty());
  EXPECT_EQ(tree.stats.leaves, 1u);
  EXPECT_EQ(tree.stats.empty_leaves, 1u);
  EXPECT_EQ(tree.stats.sah_cost, 0.0);
  const KdTree top = build_kdtree(std::span<const Aabb>{});
  ASSERT_EQ(top.nodes.size(), 1u);
  EXPECT_TRUE(top.nodes[0].leaf);
}

TEST(KdTree, AllTrianglesInOnePlane) {
  const Mesh m = planar_grid(40, 30);
  const KdTree tree = build_kdtree(m.pos, m.tris, {});
  EXPECT_EQ(tree.bounds.lo.z, 0.0f);
  EXPECT_EQ(tree.bounds.hi.z, 0.0f);
  EXPECT_GT(tree.stats.leaves, 100u);
  for (const auto& n : tree.nodes) {
    if (!n.leaf) {
      EXPECT_NE(n.axis, 2);  // no plane can split a zero extent
    }
  }
  check_triangle_tree(tree, m);
  check_points(tree, m, 200, 4);
  // Rays through the plane (no ray lies in it, so the triangles are hit from above or below).
  check_rays(tree, m, 1500, 5);
}

TEST(KdTree, IdenticalTrianglesStop) {
  Mesh m;
  m.pos = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.5f}};
  m.tris.assign(2000, glm::uvec3(0, 1, 2));
  const KdTree tree = build_kdtree(m.pos, m.tris, {});
  // Nothing can separate them: the SAH stops at once (every plane duplicates them all).
  EXPECT_LE(tree.stats.depth, 2u);
  std::uint32_t biggest = 0;
  for (const auto& n : tree.nodes)
    if (n.leaf) biggest = std::max(biggest, n.count);
  EXPECT_EQ(biggest, 2000u);
  check_triangle_tree(tree, m);
  // Many identical plus some others: max depth bounds the tree.
  Mesh mixed = m;
  append(mixed, random_triangles(300, 4, 1.0f, 0.3f));
  KdBuildParams p;
  p.max_depth = 6;
  const KdTree bounded = build_kdtree(mixed.pos, mixed.tris, {}, p);
  EXPECT_LE(bounded.stats.depth, 6u);
  check_triangle_tree(bounded, mixed, p);
}

TEST(KdTree, SingleTriangleAndAxisAlignedTriangles) {
  Mesh one;
  one.pos = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
  one.tris = {{0, 1, 2}};
  const KdTree t1 = build_kdtree(one.pos, one.tris, {});
  ASSERT_EQ(t1.nodes.size(), 1u);
  EXPECT_EQ(t1.nodes[0].count, 1u);
  EXPECT_EQ(t1.stats.sah_cost, 20.0);
  // Triangles in the planes x = i: planar events at every plane.
  Mesh slabs;
  for (int i = 0; i < 64; ++i) {
    const auto b = static_cast<unsigned>(slabs.pos.size());
    const float x = static_cast<float>(i);
    slabs.pos.insert(slabs.pos.end(), {{x, 0.0f, 0.0f}, {x, 1.0f, 0.0f}, {x, 0.0f, 1.0f}});
    slabs.tris.emplace_back(b, b + 1, b + 2);
  }
  const KdTree ts = build_kdtree(slabs.pos, slabs.tris, {});
  EXPECT_GT(ts.stats.leaves, 8u);
  check_triangle_tree(ts, slabs);
  check_rays(ts, slabs, 500, 8);
}

TEST(KdTree, SplitsAreRepresentableInOtherFormats) {
  const Mesh m = random_triangles(800, 12, 3.0f, 0.5f);
  KdBuildParams p;
  p.split_format = ff::Format{5, 6};  // a coarse grid: many candidates collapse
  const KdTree tree = build_kdtree(m.pos, m.tris, {}, p);
  EXPECT_GT(tree.stats.leaves, 20u);
  check_triangle_tree(tree, m, p);  // walk() asserts every split decodes to itself
  check_rays(tree, m, 800, 13);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(kd_split_round_down(tree.bounds.lo[k], p.split_format), tree.bounds.lo[k]);
    EXPECT_EQ(kd_split_round_up(tree.bounds.hi[k], p.split_format), tree.bounds.hi[k]);
  }
}

TEST(KdTree, ParametersBoundTheTree) {
  const Mesh m = random_triangles(1000, 3, 10.0f, 0.5f);
  KdBuildParams p;
  p.max_depth = 5;
  const KdTree shallow = build_kdtree(m.pos, m.tris, {}, p);
  EXPECT_EQ(shallow.stats.depth, 5u);
  check_triangle_tree(shallow, m, p);
  p = {};
  p.leaf_size = 2000;
  const KdTree one = build_kdtree(m.pos, m.tris, {}, p);
  EXPECT_EQ(one.nodes.size(), 1u);
  EXPECT_EQ(one.nodes[0].count, 1000u);
  // Cheap traversal makes deeper trees; expensive traversal shallower ones.
  p = {};
  p.traversal_cost = 1.0f;
  const KdTree deep = build_kdtree(m.pos, m.tris, {}, p);
  p.traversal_cost = 200.0f;
  const KdTree flat = build_kdtree(m.pos, m.tris, {}, p);
  EXPECT_GT(deep.stats.nodes, flat.stats.nodes);
  check_triangle_tree(deep, m, {});
}

TEST(KdTree, StatisticsAreConsistent) {
  const Mesh m = random_triangles(1200, 5, 10.0f, 0.5f);
  const KdBuildParams p;
  const KdTree tree = build_kdtree(m.pos, m.tris, {}, p);
  const KdTreeStats& s = tree.stats;
  EXPECT_EQ(s.nodes, tree.nodes.size());
  EXPECT_EQ(s.leaves * 2 - 1, s.nodes);
  std::uint32_t empty = 0;
  std::uint64_t listed = 0;
  for (const auto& n : tree.nodes) {
    if (n.leaf) {
      empty += n.count == 0;
      listed += n.count;
    }
  }
  EXPECT_EQ(s.empty_leaves, empty);
  EXPECT_GT(empty, 0u);
  EXPECT_DOUBLE_EQ(s.items_per_leaf, static_cast<double>(listed) / (s.leaves - empty));
  EXPECT_NEAR(
      s.sah_cost,
      p.traversal_cost * s.expected_traversal_steps + p.intersection_cost * s.expected_item_tests,
      1e-9 * s.sah_cost);
  EXPECT_GE(s.expected_traversal_steps, 1.0);  // the root is always traversed
  EXPECT_GE(s.expected_leaf_visits, 1.0);
  EXPECT_LT(s.sah_cost, p.intersection_cost * m.tris.size() / 10.0);
  EXPECT_GT(s.build_seconds, 0.0);
  const KdTreeStats again = compute_kdtree_stats(tree, p);
  EXPECT_EQ(again.sah_cost, s.sah_cost);
  EXPECT_EQ(again.depth, s.depth);

  // Monte Carlo check of the surface-area expectations: uniformly distributed random lines
  // through the root box (the isotropic line measure, under which P(line meets a convex box |
  // it meets the root box) = area ratio), counting the nodes whose boxes they pass.
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const glm::dvec3 lo = dv(tree.bounds.lo);
  const glm::dvec3 hi = dv(tree.bounds.hi);
  const glm::dvec3 center = 0.5 * (lo + hi);
  const double radius = 0.5 * glm::length(hi - lo);
  auto meets = [](const Ray& r, const DBox& b) {
    double t0 = -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      double a = (b.lo[k] - r.o[k]) / r.d[k];
      double c = (b.hi[k] - r.o[k]) / r.d[k];
      if (a > c) std::swap(a, c);
      t0 = std::max(t0, a);
      t1 = std::min(t1, c);
    }
    return t0 <= t1;
  };
  double inner = 0.0;
  double leaves = 0.0;
  double tests = 0.0;
  int lines = 0;
  while (lines < 20000 / kScale) {
    Ray r;
    r.d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    // A uniform point on the disc through the centre perpendicular to d.
    const glm::dvec3 e1 = glm::normalize(
        glm::cross(r.d, std::fabs(r.d.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 e2 = glm::cross(r.d, e1);
    double a = u(rng);
    double b = u(rng);
    if (a * a + b * b > 1.0) continue;
    r.o = center + radius * (a * e1 + b * e2);
    if (!meets(r, DBox{lo, hi})) continue;
    ++lines;
    std::vector<std::pair<std::uint32_t, DBox>> stack{{0, DBox{lo, hi}}};
    while (!stack.empty()) {
      const auto [n, box] = stack.back();
      stack.pop_back();
      if (!meets(r, box)) continue;
      const KdTreeNode& nd = tree.nodes[n];
      if (nd.leaf) {
        leaves += 1.0;
        tests += nd.count;
        continue;
      }
      inner += 1.0;
      DBox l = box;
      DBox rr = box;
      l.hi[nd.axis] = nd.split;
      rr.lo[nd.axis] = nd.split;
      stack.push_back({nd.child, l});
      stack.push_back({nd.child + 1, rr});
    }
  }
  EXPECT_NEAR(inner / lines, s.expected_traversal_steps, 0.05 * s.expected_traversal_steps);
  EXPECT_NEAR(leaves / lines, s.expected_leaf_visits, 0.05 * s.expected_leaf_visits);
  EXPECT_NEAR(tests / lines, s.expected_item_tests, 0.05 * s.expected_item_tests);
}

// Node for node: every field of every node the same.
void expect_same_nodes(const KdTree& a, const KdTree& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(a.nodes[i].leaf, b.nodes[i].leaf) << i;
    EXPECT_EQ(a.nodes[i].axis, b.nodes[i].axis) << i;
    EXPECT_EQ(a.nodes[i].split, b.nodes[i].split) << i;
    EXPECT_EQ(a.nodes[i].child, b.nodes[i].child) << i;
    EXPECT_EQ(a.nodes[i].first, b.nodes[i].first) << i;
    EXPECT_EQ(a.nodes[i].count, b.nodes[i].count) << i;
  }
}

TEST(KdTree, Deterministic) {
  const Mesh m = random_triangles(900, 77, 4.0f, 1.0f);
  const KdTree a = build_kdtree(m.pos, m.tris, {});
  const KdTree b = build_kdtree(m.pos, m.tris, {});
  expect_same_nodes(a, b);
  EXPECT_EQ(a.items, b.items);
}

// ---- the top level over boxes ------------------------------------------------------------------

void check_box_tree(const KdTree& tree, const std::vector<Aabb>& boxes) {
  const std::vector<Leaf> leaves = walk(tree, {});
  std::vector<int> seen(boxes.size(), 0);
  for (const Leaf& lf : leaves) {
    const KdTreeNode& nd = tree.nodes[lf.node];
    std::set<std::uint32_t> list;
    for (std::uint32_t i = 0; i < nd.count; ++i) {
      const std::uint32_t id = tree.items[nd.first + i];
      if (i > 0) {
        EXPECT_LT(tree.items[nd.first + i - 1], id);
      }
      list.insert(id);
      ++seen[id];
      const Aabb& b = boxes.at(id);
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(b.lo[k], lf.box.hi[k]) << "box " << id << " listed in leaf " << lf.node;
        EXPECT_GE(b.hi[k], lf.box.lo[k]) << "box " << id << " listed in leaf " << lf.node;
      }
    }
    for (std::uint32_t id = 0; id < boxes.size(); ++id) {
      const Aabb& b = boxes[id];
      if (b.empty()) continue;
      bool interior = true;  // overlaps the open box (closed on zero-extent axes)
      for (int k = 0; k < 3; ++k) {
        if (lf.box.hi[k] > lf.box.lo[k])
          interior = interior && b.lo[k] < lf.box.hi[k] && b.hi[k] > lf.box.lo[k];
        else
          interior = interior && b.lo[k] <= lf.box.lo[k] && b.hi[k] >= lf.box.hi[k];
      }
      if (interior) {
        EXPECT_TRUE(list.count(id)) << "box " << id << " missing in " << lf.node;
      }
    }
  }
  for (std::size_t id = 0; id < boxes.size(); ++id)
    EXPECT_EQ(seen[id] > 0, !boxes[id].empty()) << "box " << id;
}

TEST(KdTopLevel, RandomBoxesFlatBoxesAndPoints) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> c(-50.0f, 50.0f);
  std::uniform_real_distribution<float> s(0.0f, 6.0f);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 800; ++i) {
    Aabb b;
    const glm::vec3 lo(c(rng), c(rng), c(rng));
    glm::vec3 size(s(rng), s(rng), s(rng));
    if (i % 10 == 3) size.y = 0.0f;           // flat
    if (i % 10 == 7) size = glm::vec3(0.0f);  // a point
    if (i % 50 == 11) size *= 10.0f;          // a big one
    b.grow(lo);
    b.grow(lo + size);
    boxes.push_back(b);
  }
  boxes[5] = Aabb{};  // an empty instance (no triangles) is left out
  const KdTree tree = build_kdtree(boxes);
  EXPECT_GT(tree.stats.leaves, 50u);
  check_box_tree(tree, boxes);
  // All boxes in one plane (e.g. a field of flat instances on the ground).
  for (auto& b : boxes)
    b.hi.y = b.lo.y = 0.0f;
  const KdTree ground = build_kdtree(boxes);
  check_box_tree(ground, boxes);
  // Identical boxes: the SAH stops.
  std::vector<Aabb> same(500, boxes[0]);
  const KdTree st = build_kdtree(same);
  EXPECT_EQ(st.stats.leaves - st.stats.empty_leaves, 1u);
  check_box_tree(st, same);
}

// The hybrid (docs/kdtree.md): the exact event sweep alone, binning down to the leaf decisions,
// very few and the most bins, a threshold between, and a coarse split grid under binning (bins
// collapse onto few grid values) all keep every invariant; the binned tree costs little more.
TEST(KdTree, BinnedAndExactStagesKeepTheInvariants) {
  Mesh m = random_triangles(900 / kScale, 31, 10.0f, 0.7f);
  append(m, sphere(16, 24, glm::vec3(2.0f, 1.0f, 0.0f), 4.0f));
  append(m, terrain(24 / kScale, 20 / kScale, 9));
  struct Config {
    const char* name;
    int binned_above;
    int bins;
    ff::Format format;
  };
  const Config configs[] = {{"exact", 1 << 30, 128, ff::kFp24},
                            {"binned", 0, 128, ff::kFp24},
                            {"two bins", 0, 2, ff::kFp24},
                            {"256 bins, exact below 200", 200, 256, ff::kFp24},
                            {"binned e5m6", 0, 64, ff::Format{5, 6}}};
  double sah[2] = {0.0, 0.0};
  std::size_t nodes[2] = {0, 0};
  int i = 0;
  for (const Config& c : configs) {
    SCOPED_TRACE(c.name);
    KdBuildParams p;
    p.binned_above = c.binned_above;
    p.bins = c.bins;
    p.split_format = c.format;
    const KdTree tree = build_kdtree(m.pos, m.tris, {}, p);
    EXPECT_GT(tree.stats.leaves, 100u);
    check_triangle_tree(tree, m, p);
    check_rays(tree, m, 1500 / kScale, 40 + i);
    check_points(tree, m, 200 / kScale, 50 + i);
    if (i < 2) {
      sah[i] = tree.stats.sah_cost;
      nodes[i] = tree.nodes.size();
    }
    ++i;
  }
  EXPECT_NE(nodes[0], nodes[1]);  // two different builders ran
  EXPECT_LT(sah[1], 1.1 * sah[0]);
  EXPECT_GT(sah[1], 0.9 * sah[0]);
  // The top level through both stages.
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f);
  std::vector<Aabb> boxes;
  for (int b = 0; b < 600; ++b) {
    Aabb box;
    const glm::vec3 lo(u(rng), u(rng), u(rng));
    box.grow(lo);
    box.grow(lo + glm::vec3(b % 7 == 0 ? 0.0f : 1.5f, 1.0f, b % 5 == 0 ? 0.0f : 2.0f));
    boxes.push_back(box);
  }
  for (const int above : {0, 1 << 30}) {
    KdBuildParams p;
    p.binned_above = above;
    const KdTree top = build_kdtree(boxes, p);
    EXPECT_GT(top.stats.leaves, 50u);
    check_box_tree(top, boxes);
  }
}

// ---- bad input -------------------------------------------------------------------------------

void expect_error(const std::function<void()>& f, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no error, expected: " << text;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(KdTree, BadInputIsRefusedWithOneClearLine) {
  Mesh m = random_triangles(10, 1, 1.0f, 1.0f);
  m.tris[4].y = 1000;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}); },
               "kd-tree: triangle 4 indexes a vertex beyond the 30 positions");
  m = random_triangles(10, 1, 1.0f, 1.0f);
  m.pos[7].z = std::numeric_limits<float>::quiet_NaN();
  expect_error([&] { build_kdtree(m.pos, m.tris, {}); },
               "kd-tree: vertex 7 has a non-finite coordinate");
  m.pos[7].z = std::numeric_limits<float>::infinity();
  expect_error([&] { build_kdtree(m.pos, m.tris, {}); },
               "kd-tree: vertex 7 has a non-finite coordinate");
  m.pos[7].z = 1e30f;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}); }, "outside the range of split format e7m16");
  m = random_triangles(10, 1, 1.0f, 1.0f);
  const std::vector<std::uint8_t> skip(3, 0);
  expect_error([&] { build_kdtree(m.pos, m.tris, skip); },
               "kd-tree: skip list has 3 entries for 10 triangles");
  std::vector<Aabb> boxes(3);
  boxes[0].grow(glm::vec3(0.0f));
  boxes[1].grow(glm::vec3(0.0f));
  boxes[1].hi.x = std::numeric_limits<float>::quiet_NaN();
  expect_error([&] { build_kdtree(boxes); }, "kd-tree: box 1 has a non-finite coordinate");
  boxes[1].hi.x = std::numeric_limits<float>::infinity();
  expect_error([&] { build_kdtree(boxes); }, "kd-tree: box 1 has a non-finite coordinate");
  KdBuildParams p;
  p.max_depth = -2;  // -1 is the automatic limit
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, "kd-tree: max depth -2");
  p = {};
  p.intersection_cost = 0.0f;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, "kd-tree: cost parameters");
  p = {};
  p.bins = 1;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, "kd-tree: bins 1 outside 2..256");
  p.bins = 257;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, "kd-tree: bins 257 outside 2..256");
  p.bins = 128;
  p.empty_chains = 3;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); },
               "kd-tree: empty-chain rule 3 outside 0..2");
  p = {};
  p.binned_above = -1;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); },
               "kd-tree: negative binned-above threshold -1");
  p = {};
  p.split_format = ff::Format{9, 30};
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, "kd-tree: invalid split format");
  const std::string bound_error =
      "kd-tree: node bound needs 0 <= nodes per item <= 1e6 (0: no bound) and a floor >= 0";
  p = {};
  p.max_nodes_per_item = -1.0f;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, bound_error);
  p = {};
  p.node_floor = -1;
  expect_error([&] { build_kdtree(m.pos, m.tris, {}, p); }, bound_error);
}

}  // namespace
}  // namespace saarcor::host

namespace saarcor::host {
namespace {

// pbrt's and Mitsuba's depth rule, 8 + 1.3 log2 N, rounded; an explicit limit wins.
TEST(KdTree, AutomaticDepthLimitFollowsTheItemCount) {
  EXPECT_EQ(kd_auto_max_depth(0), 8);
  EXPECT_EQ(kd_auto_max_depth(1), 8);
  EXPECT_EQ(kd_auto_max_depth(2), 9);
  EXPECT_EQ(kd_auto_max_depth(806), 20);       // the room: log2 = 9
  EXPECT_EQ(kd_auto_max_depth(1u << 20), 34);  // a 1M-triangle mesh: 8 + 26
  KdBuildParams p;
  EXPECT_EQ(kd_max_depth(p, 806), 20);
  p.max_depth = 5;
  EXPECT_EQ(kd_max_depth(p, 806), 5);
}

}  // namespace
}  // namespace saarcor::host

namespace saarcor::host {
namespace {
// ---- the trees themselves ----------------------------------------------------------------------

// FNV-1a over everything a tree stores: node kinds, axes, split bits, children, leaf ranges and
// the item lists.
std::uint64_t tree_hash(const KdTree& t) {
  std::uint64_t h = 14695981039346656037ull;
  auto mix = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) {
      h ^= (v >> (8 * i)) & 0xFFu;
      h *= 1099511628211ull;
    }
  };
  for (const KdTreeNode& nd : t.nodes) {
    mix(nd.leaf);
    if (nd.leaf) {
      mix(nd.first);
      mix(nd.count);
    } else {
      mix(nd.axis);
      mix(std::bit_cast<std::uint32_t>(nd.split));
      mix(nd.child);
    }
  }
  for (const std::uint32_t id : t.items)
    mix(id);
  return h;
}

// The trees are tuned against the modelled hardware (the room's costs, docs/kdtree.md "Costs for
// this hardware"), so a change meant to make the builder faster must leave them bit for bit as
// they are. These hashes pin the default build of fixed meshes and boxes (both stages, face slabs,
// empty-space planes, flat axes); a change that means to alter the trees updates them and says
// so in docs/kdtree.md.
TEST(KdTree, TreesOfFixedInputsAreUnchanged) {
  Mesh spheres = sphere(24, 32, glm::vec3(0.0f), 3.0f);
  append(spheres, sphere(12, 16, glm::vec3(2.5f, 0.5f, 0.0f), 1.0f));
  const Mesh land = terrain(40, 30, 5);
  const Mesh soup = random_triangles(900, 77, 4.0f, 1.0f);
  const Mesh box = cube();
  const Mesh flat = planar_grid(30, 20);
  struct Case {
    const char* name;
    const Mesh* mesh;
    std::uint64_t hash;
  };
  const Case cases[] = {
      {"spheres", &spheres, 0x677fbac1c1ce91b2ull},  {"terrain", &land, 0xbadaacdcd74cc440ull},
      {"soup", &soup, 0x9120e280d5fd30c7ull},        {"cube", &box, 0x51f6dc2663dba91ull},
      {"planar grid", &flat, 0x68ff23bd66cc45abull},
  };
  for (const Case& c : cases) {
    const KdTree tree = build_kdtree(c.mesh->pos, c.mesh->tris, {});
    EXPECT_EQ(tree_hash(tree), c.hash)
        << c.name << ": " << tree.nodes.size() << " nodes, hash 0x" << std::hex << tree_hash(tree);
  }
  std::mt19937 rng(4242);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  std::uniform_real_distribution<float> s(0.0f, 6.0f);
  std::vector<Aabb> boxes(700);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const glm::vec3 lo(u(rng), u(rng), u(rng));
    // Every 7th box flat in y, every 11th a point.
    const glm::vec3 ext(s(rng), i % 7 == 0 ? 0.0f : s(rng), s(rng));
    boxes[i].lo = lo;
    boxes[i].hi = i % 11 == 0 ? lo : lo + ext;
  }
  const KdTree top = build_kdtree(boxes, {});
  EXPECT_EQ(tree_hash(top), 0x211123f28b8665beull)
      << "boxes: " << top.nodes.size() << " nodes, hash 0x" << std::hex << tree_hash(top);
}

// The node bound (docs/kdtree.md "Node bound"): a tree over the bound is built again with a cost
// per node, the least that fits; a tree within it is the tree the plain SAH builds.
TEST(KdTree, NodeBoundKeepsTreesWithinNodesPerItem) {
  Mesh m = sphere(24, 32, glm::vec3(0.0f), 3.0f);
  append(m, sphere(12, 16, glm::vec3(2.5f, 0.5f, 0.0f), 1.0f));
  KdBuildParams free;
  free.max_nodes_per_item = 0.0f;
  const KdTree unbound = build_kdtree(m.pos, m.tris, {}, free);
  EXPECT_EQ(tree_hash(build_kdtree(m.pos, m.tris, {})), tree_hash(unbound));  // under the floor
  EXPECT_EQ(unbound.stats.node_cost, 0.0);
  const double items = static_cast<double>(m.tris.size());
  const double per_item = static_cast<double>(unbound.nodes.size()) / items;
  KdBuildParams bound;
  bound.node_floor = 0;
  bound.max_nodes_per_item = static_cast<float>(0.75 * per_item);
  const KdTree cut = build_kdtree(m.pos, m.tris, {}, bound);
  EXPECT_LE(static_cast<double>(cut.nodes.size()), bound.max_nodes_per_item * items);
  // The least cost that fits (within the search's factor 1.19): not far below the bound.
  EXPECT_GT(static_cast<double>(cut.nodes.size()), 0.6 * per_item * items);
  EXPECT_GT(cut.stats.node_cost, 0.0);
  // The nodes the cost removes are the ones that save least: the expected cost moves by little.
  EXPECT_LT(cut.stats.sah_cost, unbound.stats.sah_cost * 1.05);
  check_triangle_tree(cut, m, bound);
  check_rays(cut, m, 2000 / kScale, 21);
  check_points(cut, m, 200 / kScale, 22);
  // A bound that no tree can meet keeps the smallest tree the search built.
  bound.max_nodes_per_item = 0.01f;
  const KdTree least = build_kdtree(m.pos, m.tris, {}, bound);
  EXPECT_LT(least.nodes.size(), cut.nodes.size());
  check_triangle_tree(least, m, bound);
}

// Leaf steps (docs/kdtree.md "Costs for this hardware"): K_T for each non-empty child by its
// area share makes cuts through cubes dearer and cuts of empty space cheaper; the trees are
// smaller at the same costs and stay correct.
TEST(KdTree, LeafStepsChargeEveryNonEmptyChild) {
  const Mesh t = terrain(40 / kScale, 30 / kScale, 5);
  KdBuildParams p;
  p.leaf_step = true;
  const KdTree stepped = build_kdtree(t.pos, t.tris, {}, p);
  const KdTree plain = build_kdtree(t.pos, t.tris, {});
  EXPECT_LT(stepped.nodes.size(), plain.nodes.size());
  EXPECT_GT(stepped.stats.items_per_leaf, plain.stats.items_per_leaf);
  check_triangle_tree(stepped, t, p);
  check_rays(stepped, t, 2000 / kScale, 31);
  check_points(stepped, t, 200 / kScale, 32);
}

// ---- chains of empty cuts (docs/kdtree.md "Chains of empty cuts") ----------------------

// The non-empty leaves of a tree with their boxes and lists (empty leaves left out), in order.
std::vector<std::pair<std::vector<double>, std::vector<std::uint32_t>>> full_leaves(
    const KdTree& tree, const KdBuildParams& params) {
  std::vector<std::pair<std::vector<double>, std::vector<std::uint32_t>>> out;
  for (const Leaf& lf : walk(tree, params)) {
    const KdTreeNode& nd = tree.nodes[lf.node];
    if (nd.count == 0) continue;
    std::vector<double> box;
    for (int k = 0; k < 3; ++k) {
      box.push_back(lf.box.lo[k]);
      box.push_back(lf.box.hi[k]);
    }
    out.emplace_back(box, std::vector<std::uint32_t>(tree.items.begin() + nd.first,
                                                     tree.items.begin() + nd.first + nd.count));
  }
  std::sort(out.begin(), out.end());
  return out;
}

KdTreeNode inner(int axis, float split, std::uint32_t child) {
  KdTreeNode n;
  n.axis = static_cast<std::uint8_t>(axis);
  n.split = split;
  n.child = child;
  return n;
}
KdTreeNode leaf(std::uint32_t first, std::uint32_t count) {
  KdTreeNode n;
  n.leaf = true;
  n.first = first;
  n.count = count;
  return n;
}

// A hand-built tree over [0, 16]^3 (children adjacent, in the builder's order):
//   0: x = 2,  left empty  | 2        link, mergeable (2 cuts x, empty side below)
//   2: x = 5,  left empty  | 4        link, mergeable
//   4: x = 7,  left empty  | 6        link across axes
//   6: y = 4,  left empty  | 8        link across axes and sides
//   8: z = 12, 9           | empty    link, mergeable (9 cuts z, empty side above)
//   9: z = 9,  11          | empty    no link (11 has no empty child)
//  11: x = 10, leaf {0}    | leaf {1, 2}
// Merged: x = 7 (empty below) -> y = 4 (empty below) -> z = 9 (empty above) -> x = 10.
TEST(KdTree, ChainLinksAreCountedAndSameAxisLinksMerge) {
  KdTree t;
  t.bounds.lo = glm::vec3(0.0f);
  t.bounds.hi = glm::vec3(16.0f);
  t.items = {0, 1, 2};
  t.nodes.resize(15);
  t.nodes[0] = inner(0, 2.0f, 1);
  t.nodes[1] = leaf(0, 0);
  t.nodes[2] = inner(0, 5.0f, 3);
  t.nodes[3] = leaf(0, 0);
  t.nodes[4] = inner(0, 7.0f, 5);
  t.nodes[5] = leaf(0, 0);
  t.nodes[6] = inner(1, 4.0f, 7);
  t.nodes[7] = leaf(0, 0);
  t.nodes[8] = inner(2, 12.0f, 9);
  t.nodes[9] = inner(2, 9.0f, 11);
  t.nodes[10] = leaf(0, 0);
  t.nodes[11] = inner(0, 10.0f, 13);
  t.nodes[12] = leaf(0, 0);
  t.nodes[13] = leaf(0, 1);
  t.nodes[14] = leaf(1, 2);
  const KdTreeStats before = compute_kdtree_stats(t);
  EXPECT_EQ(before.nodes, 15u);
  EXPECT_EQ(before.empty_leaves, 6u);
  EXPECT_EQ(before.empty_chain_links, 5u);      // nodes 0, 2, 4, 6 and 8
  EXPECT_EQ(before.mergeable_chain_links, 3u);  // nodes 0, 2 and 8
  const auto leaves_before = full_leaves(t, {});

  KdTree m = t;
  kd_merge_empty_chains(m);
  const KdTreeStats after = compute_kdtree_stats(m);
  // One inner node and one empty leaf fewer per mergeable link.
  EXPECT_EQ(after.nodes, before.nodes - 2 * before.mergeable_chain_links);
  EXPECT_EQ(after.empty_leaves, before.empty_leaves - before.mergeable_chain_links);
  EXPECT_EQ(after.mergeable_chain_links, 0u);
  EXPECT_EQ(after.empty_chain_links, 2u);  // x = 7 -> y = 4 -> z = 9, across axes
  EXPECT_EQ(full_leaves(m, {}), leaves_before);
  EXPECT_LT(after.expected_traversal_steps, before.expected_traversal_steps);
  EXPECT_DOUBLE_EQ(after.expected_item_tests, before.expected_item_tests);
  // The merged cuts are the inner planes.
  EXPECT_EQ(m.nodes[0].axis, 0);
  EXPECT_EQ(m.nodes[0].split, 7.0f);
  ASSERT_FALSE(m.nodes[m.nodes[0].child + 1].leaf);
  const KdTreeNode& y = m.nodes[m.nodes[0].child + 1];
  EXPECT_EQ(y.axis, 1);
  const KdTreeNode& z = m.nodes[y.child + 1];
  EXPECT_EQ(z.axis, 2);
  EXPECT_EQ(z.split, 9.0f);
  // Merging again changes nothing: the array is written in the builder's order.
  KdTree again = m;
  kd_merge_empty_chains(again);
  expect_same_nodes(again, m);
}

// The rules on built trees: merging leaves the non-empty leaves as they are and no mergeable link;
// forbidding chains leaves no link at all; both keep every invariant and answer rays right.
TEST(KdTree, EmptyChainRulesKeepTheInvariants) {
  Mesh m = random_triangles(400 / kScale, 5, 20.0f, 1.0f);
  append(m, sphere(12, 16, glm::vec3(30.0f, 0.0f, 0.0f), 2.0f));
  append(m, terrain(20, 15, 3));
  KdBuildParams allowed;
  allowed.max_nodes_per_item = 0.0f;  // the rules alone, without the bound's rebuilds
  allowed.empty_chains = KdBuildParams::kChainsAllowed;
  KdBuildParams merged = allowed;
  merged.empty_chains = KdBuildParams::kChainsMerged;
  KdBuildParams forbidden = allowed;
  forbidden.empty_chains = KdBuildParams::kChainsForbidden;
  const KdTree a = build_kdtree(m.pos, m.tris, {}, allowed);
  const KdTree b = build_kdtree(m.pos, m.tris, {}, merged);
  const KdTree c = build_kdtree(m.pos, m.tris, {}, forbidden);
  EXPECT_GT(a.stats.empty_chain_links, 0u);
  EXPECT_EQ(b.stats.mergeable_chain_links, 0u);
  EXPECT_EQ(b.nodes.size(), a.nodes.size() - 2 * a.stats.mergeable_chain_links);
  EXPECT_EQ(b.stats.empty_chain_links, a.stats.empty_chain_links - a.stats.mergeable_chain_links);
  EXPECT_EQ(full_leaves(b, merged), full_leaves(a, allowed));
  EXPECT_EQ(c.stats.empty_chain_links, 0u);
  // The rule itself: below an empty cut, no plane with an empty side.
  for (const KdTreeNode& nd : c.nodes) {
    if (nd.leaf) continue;
    for (int s = 0; s < 2; ++s) {
      const KdTreeNode& e = c.nodes[nd.child + s];
      const KdTreeNode& o = c.nodes[nd.child + 1 - s];
      if (!(e.leaf && e.count == 0) || o.leaf) continue;
      EXPECT_FALSE(c.nodes[o.child].leaf && c.nodes[o.child].count == 0);
      EXPECT_FALSE(c.nodes[o.child + 1].leaf && c.nodes[o.child + 1].count == 0);
    }
  }
  for (const auto& [tree, params] : {std::pair{&b, merged}, std::pair{&c, forbidden}}) {
    check_triangle_tree(*tree, m, params);
    check_rays(*tree, m, 2000 / kScale, 41);
    check_points(*tree, m, 200 / kScale, 42);
  }
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  std::uniform_real_distribution<float> s(0.0f, 3.0f);
  std::vector<Aabb> boxes(300);
  for (Aabb& bx : boxes) {
    bx.lo = glm::vec3(u(rng), u(rng) * 0.1f, u(rng));
    bx.hi = bx.lo + glm::vec3(s(rng), s(rng), s(rng));
  }
  for (const KdBuildParams& p : {merged, forbidden}) {
    const KdTree top = build_kdtree(boxes, p);
    check_box_tree(top, boxes);
    EXPECT_EQ(top.stats.mergeable_chain_links, 0u);
  }
}

}  // namespace
}  // namespace saarcor::host
