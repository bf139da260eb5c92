// AFF (BART's NFF-based animation format) -> Scene. Each file is tokenised and parsed once into a
// list of statements (errors name FILE:LINE); the statements are then executed from the root
// file, following includes, which builds nodes, objects, instances, materials, textures, lights,
// the camera and the keyframe tables. Kochanek-Bartels splines follow BART's reference code
// (kbsplpos.c, kbsplrot.c, quat.c by Eberly / Assarsson) and are sampled into LINEAR channels,
// because Scene::set_time only interpolates linearly. Design and limits: docs/aff.md.
#include "host/aff_loader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <variant>

#include "host/gltf_loader.h"

namespace saarcor::host {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Quaternion operations with the semantics of BART's quat.c (MAGIC Software, converted to C by
// Ulf Assarsson): its Log/Exp/Slerp switch to the small-angle forms below a sine of 1e-3, and its
// Slerp does not take the shorter arc (the spline set-up arranges acute angles instead).

constexpr double kQuatEpsilon = 1e-3;

glm::dquat quat_log(const glm::dquat& q) {
  glm::dquat r(0.0, q.x, q.y, q.z);
  if (std::abs(q.w) < 1.0) {
    const double angle = std::acos(q.w);
    const double sn = std::sin(angle);
    if (std::abs(sn) >= kQuatEpsilon) {
      const double c = angle / sn;
      r.x *= c;
      r.y *= c;
      r.z *= c;
    }
  }
  return r;
}

glm::dquat quat_exp(const glm::dquat& q) {
  const double angle = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  const double sn = std::sin(angle);
  glm::dquat r(std::cos(angle), q.x, q.y, q.z);
  if (std::abs(sn) >= kQuatEpsilon) {
    const double c = sn / angle;
    r.x *= c;
    r.y *= c;
    r.z *= c;
  }
  return r;
}

glm::dquat quat_slerp(double t, const glm::dquat& p, const glm::dquat& q) {
  const double c = std::clamp(p.w * q.w + p.x * q.x + p.y * q.y + p.z * q.z, -1.0, 1.0);
  const double angle = std::acos(c);
  const double sn = std::sin(angle);
  if (sn < kQuatEpsilon) return p;
  const double c0 = std::sin((1.0 - t) * angle) / sn;
  const double c1 = std::sin(t * angle) / sn;
  return glm::dquat(c0 * p.w + c1 * q.w, c0 * p.x + c1 * q.x, c0 * p.y + c1 * q.y,
                    c0 * p.z + c1 * q.z);
}

glm::dquat scaled(const glm::dquat& q, double s) {
  return glm::dquat(q.w * s, q.x * s, q.y * s, q.z * s);
}
glm::dquat added(const glm::dquat& a, const glm::dquat& b) {
  return glm::dquat(a.w + b.w, a.x + b.x, a.y + b.y, a.z + b.z);
}
glm::dquat unit_inverse(const glm::dquat& q) {
  return glm::dquat(q.w, -q.x, -q.y, -q.z);
}

// Axis-angle (angle in radians) -> unit quaternion. BART assumes a unit axis; we normalise it, and
// a zero axis means no rotation.
glm::dquat from_axis_angle(const glm::dvec3& axis, double angle) {
  const double len = glm::length(axis);
  if (!(len > 0.0)) return glm::dquat(1.0, 0.0, 0.0, 0.0);
  const glm::dvec3 a = axis / len;
  const double sn = std::sin(0.5 * angle);
  return glm::dquat(std::cos(0.5 * angle), sn * a.x, sn * a.y, sn * a.z);
}

// Multipliers of the Kochanek-Bartels tangents (kbsplpos.c / kbsplrot.c): outgoing at key i1 of
// the segment (i0, i1, i2, i3), incoming at key i2.
struct KbWeights {
  double out0, out1, in0, in1;
};

KbWeights kb_weights(const AffKey& k0, const AffKey& k1, const AffKey& k2, const AffKey& k3) {
  const auto ratio = [](double num, double den) { return den != 0.0 ? 2.0 * num / den : 0.0; };
  const double adj0 = ratio(k2.time - k1.time, k2.time - k0.time);
  const double adj1 = ratio(k2.time - k1.time, k3.time - k1.time);
  KbWeights w{};
  w.out0 = 0.5 * adj0 * (1 - k1.tension) * (1 + k1.continuity) * (1 + k1.bias);
  w.out1 = 0.5 * adj0 * (1 - k1.tension) * (1 - k1.continuity) * (1 - k1.bias);
  w.in0 = 0.5 * adj1 * (1 - k2.tension) * (1 - k2.continuity) * (1 + k2.bias);
  w.in1 = 0.5 * adj1 * (1 - k2.tension) * (1 + k2.continuity) * (1 - k2.bias);
  return w;
}

// Which value at time t: BART's (ComputeIAndU / KB_RotInterpolate: the first segment that ends
// after t, clamped to [keys[1].time, keys[n-2].time]), or the limit from below or from above.
// The limits differ from each other where keys share a time: BART's spline jumps there.
enum class Side { kBart, kLeft, kRight };

// Segment i covers [keys[i+1].time, keys[i+2].time]; returns (segment, u in [0, 1]) for time t.
template <typename Seg>
std::pair<std::size_t, double> locate(const std::vector<Seg>& segs, double t, Side side) {
  const double lo = segs.front().tmin;
  const double hi = segs.back().tmax;
  if ((side == Side::kLeft && !(lo < t)) || (side == Side::kRight && !(t < hi))) side = Side::kBart;
  if (side == Side::kBart) {
    if (!(lo < t)) return {0, 0.0};
    if (!(t < hi)) return {segs.size() - 1, 1.0};
  }
  std::size_t i = 0;
  while (i + 1 < segs.size() && !(side == Side::kLeft ? t <= segs[i].tmax : t < segs[i].tmax))
    ++i;
  const double range = segs[i].tmax - segs[i].tmin;
  return {i, range > 0.0 ? std::clamp((t - segs[i].tmin) / range, 0.0, 1.0) : 0.0};
}

// Position spline (translation and scale keys): one Hermite cubic per segment.
class PositionSpline {
 public:
  explicit PositionSpline(const std::vector<AffKey>& keys) {
    for (std::size_t i0 = 0; i0 + 3 < keys.size(); ++i0) {
      const AffKey& k0 = keys[i0];
      const AffKey& k1 = keys[i0 + 1];
      const AffKey& k2 = keys[i0 + 2];
      const AffKey& k3 = keys[i0 + 3];
      const glm::dvec3 p0(k0.value), p1(k1.value), p2(k2.value), p3(k3.value);
      const glm::dvec3 dp = p2 - p1;
      const KbWeights w = kb_weights(k0, k1, k2, k3);
      const glm::dvec3 tout = w.out1 * dp + w.out0 * (p1 - p0);
      const glm::dvec3 tin = w.in1 * (p3 - p2) + w.in0 * dp;
      Seg s;
      s.c0 = p1;
      s.c1 = tout;
      s.c2 = 3.0 * dp - 2.0 * tout - tin;
      s.c3 = -2.0 * dp + tout + tin;
      s.tmin = k1.time;
      s.tmax = k2.time;
      segs_.push_back(s);
    }
  }
  glm::dvec3 operator()(double t, Side side = Side::kBart) const {
    const auto [i, u] = locate(segs_, t, side);
    const Seg& s = segs_[i];
    return s.c0 + u * (s.c1 + u * (s.c2 + u * s.c3));
  }

 private:
  struct Seg {
    glm::dvec3 c0, c1, c2, c3;
    double tmin = 0.0, tmax = 0.0;
  };
  std::vector<Seg> segs_;
};

// Rotation spline: squad between consecutive keys with KB tangents in log space (kbsplrot.c).
class RotationSpline {
 public:
  explicit RotationSpline(const std::vector<AffKey>& keys) {
    std::vector<glm::dquat> q(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i)
      q[i] = from_axis_angle(glm::dvec3(keys[i].value), keys[i].value.w);
    for (std::size_t i0 = 0; i0 + 3 < keys.size(); ++i0) {
      const std::size_t i1 = i0 + 1, i2 = i0 + 2, i3 = i0 + 3;
      // Arrange for consecutive quaternions to have an acute angle. BART writes the negated key
      // back, so later segments see it negated too (q[i2] becomes the next segment's q1).
      if (glm::dot(q[i1], q[i2]) < 0.0) q[i2] = scaled(q[i2], -1.0);
      const glm::dquat logdq = quat_log(unit_inverse(q[i1]) * q[i2]);
      const KbWeights w = kb_weights(keys[i0], keys[i1], keys[i2], keys[i3]);
      const glm::dquat tout =
          added(scaled(logdq, w.out1), scaled(quat_log(unit_inverse(q[i0]) * q[i1]), w.out0));
      const glm::dquat tin =
          added(scaled(logdq, w.in0), scaled(quat_log(unit_inverse(q[i2]) * q[i3]), w.in1));
      Seg s;
      s.p = q[i1];
      s.q = q[i2];
      s.a = q[i1] * quat_exp(scaled(added(tout, scaled(logdq, -1.0)), 0.5));
      s.b = q[i2] * quat_exp(scaled(added(logdq, scaled(tin, -1.0)), 0.5));
      s.tmin = keys[i1].time;
      s.tmax = keys[i2].time;
      segs_.push_back(s);
    }
  }
  glm::dquat operator()(double t, Side side = Side::kBart) const {
    const auto [i, u] = locate(segs_, t, side);
    const Seg& s = segs_[i];
    const glm::dquat r =
        quat_slerp(2.0 * u * (1.0 - u), quat_slerp(u, s.p, s.q), quat_slerp(u, s.a, s.b));
    // BART goes through ToAngleAxis/FromAngleAxis, which amounts to normalising.
    const double len = std::sqrt(r.w * r.w + r.x * r.x + r.y * r.y + r.z * r.z);
    return len > 0.0 ? scaled(r, 1.0 / len) : glm::dquat(1.0, 0.0, 0.0, 0.0);
  }

 private:
  struct Seg {
    glm::dquat p, a, b, q;
    double tmin = 0.0, tmax = 0.0;
  };
  std::vector<Seg> segs_;
};

// ---------------------------------------------------------------------------------------------
// Source files: tokens with line numbers.

struct Token {
  std::string_view text;
  int line = 0;
};

struct Source {
  std::string path;  // as shown in messages
  fs::path dir;      // folder of the file, includes and textures are relative to it
  std::string text;
  std::vector<Token> tokens;
  int last_line = 1;
};

// Whitespace separates tokens; '{' and '}' are tokens of their own; '#' and '%' start a comment
// that runs to the end of the line.
void tokenize(Source& src) {
  const std::string& s = src.text;
  int line = 1;
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++i;
    } else if (c == '#' || c == '%') {
      while (i < s.size() && s[i] != '\n')
        ++i;
    } else if (c == '{' || c == '}') {
      src.tokens.push_back({std::string_view(s).substr(i, 1), line});
      ++i;
    } else {
      const std::size_t b = i;
      while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\n' && s[i] != '\r' &&
             s[i] != '\f' && s[i] != '\v' && s[i] != '{' && s[i] != '}' && s[i] != '#' &&
             s[i] != '%')
        ++i;
      src.tokens.push_back({std::string_view(s).substr(b, i - b), line});
    }
  }
  src.last_line = src.tokens.empty() ? 1 : src.tokens.back().line;  // where the text ends
}

std::optional<double> to_double(std::string_view t) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  if (t.empty()) return std::nullopt;
  double v = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) {
    // from_chars reports values beyond binary64 as out of range; they are not finite numbers.
    if (r.ec == std::errc::result_out_of_range && r.ptr == t.data() + t.size())
      return std::numeric_limits<double>::infinity();
    return std::nullopt;
  }
  return v;
}

std::string quoted(std::string_view t) {
  return "'" + std::string(t) + "'";
}

// ---------------------------------------------------------------------------------------------
// Statements.

struct ViewSt {
  glm::dvec3 from{0.0}, at{0.0, 0.0, -1.0}, up{0.0, 1.0, 0.0};
  double angle = 45.0;
  int line = 0;
};
struct LightSt {
  std::string name;  // non-empty for `la` (animated light)
  glm::dvec3 position{0.0};
  glm::dvec3 color{1.0};
  int line = 0;
};
struct MaterialValues {
  glm::dvec3 diffuse{1.0};
  glm::dvec3 specular{0.0};
  double shine = 0.0;
  double transmittance = 0.0;
  double reflectivity = 0.0;
  double ior = 0.0;  // as written; 0 where the file means none
  std::array<double, 10> key() const {
    return {diffuse.x,  diffuse.y, diffuse.z,     specular.x,   specular.y,
            specular.z, shine,     transmittance, reflectivity, ior};
  }
};
struct MaterialSt {
  MaterialValues values;
  int line = 0;
};
struct IncludeSt {
  long detail = 0;
  std::string name;
  int line = 0;
};
struct DetailSt {
  long level = 0;
};
struct StaticXformSt {
  glm::dvec3 scale{1.0}, axis{0.0, 1.0, 0.0}, translation{0.0};
  double degrees = 0.0;
  int line = 0;
};
struct AnimXformSt {
  std::string name;
  int line = 0;
};
struct CloseSt {
  int line = 0;
};
struct AnimParamsSt {
  double start = 0.0, end = 0.0;
  long frames = 0;
  int line = 0;
};
struct KeysSt {
  std::string name;
  std::vector<AffKey> transl, rot, scale;  // empty = not given
  bool visibility = false;
  int decreasing_line = 0;  // first key whose time is below its predecessor's, 0 = none
  int line = 0;
};
// Triangles of `m`, `p`, `pp`, `tt`, `ttp`: positions, optional normals and texture coordinates,
// with separate index triples per attribute (AFF meshes index them separately).
struct GeometrySt {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::uvec3> pos_idx, nrm_idx, uv_idx;
  fs::path texture;  // resolved file, empty = untextured
  int line = 0;
};
struct SkippedSt {
  std::string what;
  int line = 0;
};

using Statement = std::variant<ViewSt, LightSt, MaterialSt, IncludeSt, DetailSt, StaticXformSt,
                               AnimXformSt, CloseSt, AnimParamsSt, KeysSt, GeometrySt, SkippedSt>;

struct ParsedFile {
  Source src;
  std::vector<Statement> statements;
};

// ---------------------------------------------------------------------------------------------
// Parser of one file.

class Parser {
 public:
  Parser(const Source& src, const fs::path& root_dir) : src_(src), root_dir_(root_dir) {}

  std::vector<Statement> parse() {
    std::vector<Statement> out;
    std::vector<int> open;  // lines of the transform blocks still open
    while (pos_ < src_.tokens.size()) {
      const Token kw = src_.tokens[pos_++];
      if (!scene_statement(kw, out) && !structure_statement(kw, out, open))
        fail(kw.line, "unknown keyword " + quoted(kw.text));
    }
    if (!open.empty())
      fail(src_.last_line, "unexpected end of file: the transform block opened at line " +
                               std::to_string(open.back()) + " is not closed");
    return out;
  }

 private:
  // The view, lights, materials and geometry; false for any other keyword.
  bool scene_statement(const Token& kw, std::vector<Statement>& out) {
    const std::string_view k = kw.text;
    if (k == "v") {
      out.emplace_back(view(kw.line));
    } else if (k == "l" || k == "la") {
      out.emplace_back(light(kw.line, k == "la"));
    } else if (k == "b") {
      triple("background colour");  // no background colour in Scene: parsed and ignored
    } else if (k == "am") {
      triple("ambient light colour");  // the project's shader has its own ambient term
    } else if (k == "f") {
      out.emplace_back(nff_material(kw.line));
    } else if (k == "fm") {
      out.emplace_back(fm_material(kw.line));
    } else if (k == "c") {
      for (int i = 0; i < 8; ++i)
        number("cone base/apex and radius");
      out.emplace_back(SkippedSt{"cone/cylinder (c)", kw.line});
    } else if (k == "s") {
      for (int i = 0; i < 4; ++i)
        number("sphere centre and radius");
      out.emplace_back(SkippedSt{"sphere (s)", kw.line});
    } else if (k == "p" || k == "pp") {
      out.emplace_back(polygon(kw.line, k == "pp"));
    } else if (k == "tt" || k == "ttp") {
      out.emplace_back(textured_triangle(kw.line, k == "ttp"));
    } else if (k == "tpa") {
      animated_triangle();
      out.emplace_back(SkippedSt{"animated triangle (tpa)", kw.line});
    } else if (k == "m") {
      out.emplace_back(mesh(kw.line));
    } else {
      return false;
    }
    return true;
  }

  // Includes, detail levels, transform blocks and animation; false for any other keyword.
  bool structure_statement(const Token& kw, std::vector<Statement>& out, std::vector<int>& open) {
    const std::string_view k = kw.text;
    if (k == "i") {
      IncludeSt inc;
      inc.line = kw.line;
      inc.detail = integer("include detail level", true);
      inc.name = std::string(word("include file name").text);
      out.emplace_back(std::move(inc));
    } else if (k == "d") {
      out.emplace_back(DetailSt{integer("detail level", true)});
    } else if (k == "xs") {
      out.emplace_back(static_transform(kw.line));
      open.push_back(kw.line);
    } else if (k == "x") {
      AnimXformSt x;
      x.line = kw.line;
      x.name = std::string(word("transform name").text);
      expect("{", "'{' after the transform name");
      open.push_back(kw.line);
      out.emplace_back(std::move(x));
    } else if (k == "}") {
      if (open.empty()) fail(kw.line, "'}' without an open transform block");
      open.pop_back();
      out.emplace_back(CloseSt{kw.line});
    } else if (k == "a") {
      out.emplace_back(animation_params(kw.line));
    } else if (k == "k") {
      out.emplace_back(keyframes(kw.line));
    } else if (k == "{") {
      fail(kw.line, "'{' without a transform (xs or x) before it");
    } else {
      return false;
    }
    return true;
  }

  StaticXformSt static_transform(int line) {
    StaticXformSt x;
    x.line = line;
    x.scale = triple("static transform scale");
    x.axis = triple("static transform rotation axis");
    x.degrees = number("static transform rotation angle");
    x.translation = triple("static transform translation");
    expect("{", "'{' after the static transform");
    return x;
  }

  AnimParamsSt animation_params(int line) {
    AnimParamsSt a;
    a.line = line;
    a.start = number("animation start time");
    a.end = number("animation end time");
    a.frames = integer("animation frame count", true);
    if (a.end < a.start) fail(line, "animation end time is before its start time");
    return a;
  }

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw std::runtime_error(src_.path + ":" + std::to_string(line) + ": " + what);
  }

  const Token& word(const std::string& what) {
    if (pos_ >= src_.tokens.size())
      fail(src_.last_line, "unexpected end of file: expected " + what);
    return src_.tokens[pos_++];
  }

  void expect(std::string_view w, const std::string& what) {
    const Token& t = word(what);
    if (t.text != w) fail(t.line, "expected " + what + ", got " + quoted(t.text));
  }

  bool next_is_number() const {
    return pos_ < src_.tokens.size() && to_double(src_.tokens[pos_].text).has_value();
  }

  double number(const std::string& what) {
    const Token& t = word(what);
    const std::optional<double> v = to_double(t.text);
    if (!v) fail(t.line, "expected a number (" + what + "), got " + quoted(t.text));
    if (!std::isfinite(*v)) fail(t.line, quoted(t.text) + " is not a finite number (" + what + ")");
    line_ = t.line;
    return *v;
  }

  float coordinate(const std::string& what) {
    const double v = number(what);
    if (std::abs(v) > static_cast<double>(std::numeric_limits<float>::max()))
      fail(line_, "value " + std::to_string(v) + " is beyond binary32 (" + what + ")");
    return static_cast<float>(v);
  }

  long integer(const std::string& what, bool allow_negative = false) {
    const Token& t = word(what);
    long v = 0;
    std::string_view s = t.text;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size())
      fail(t.line, "expected an integer (" + what + "), got " + quoted(t.text));
    if (v < 0 && !allow_negative) fail(t.line, what + " must not be negative");
    line_ = t.line;
    return v;
  }

  // Meshes index their vertices, normals and texture coordinates with 21 bits each when the
  // loader merges them into vertices.
  static constexpr std::size_t kMaxMeshItems = (std::size_t{1} << 21) - 1;

  std::size_t mesh_count(const std::string& what, std::size_t min_tokens) {
    const std::size_t n = count(what, min_tokens);
    if (n >= kMaxMeshItems)
      fail(line_, what + " " + std::to_string(n) + " is too large (at most " +
                      std::to_string(kMaxMeshItems - 1) + ")");
    return n;
  }

  // A count of items that follow, each taking at least `min_tokens` tokens (guards against a
  // count that would make us reserve absurd amounts for a truncated file).
  std::size_t count(const std::string& what, std::size_t min_tokens) {
    const long n = integer(what);
    const int line = line_;
    const std::size_t left = src_.tokens.size() - pos_;
    if (static_cast<std::size_t>(n) > left / std::max<std::size_t>(min_tokens, 1))
      fail(src_.last_line, "unexpected end of file: " + what + " " + std::to_string(n) + " (line " +
                               std::to_string(line) + ") needs more than the " +
                               std::to_string(left) + " tokens that follow");
    return static_cast<std::size_t>(n);
  }

  glm::dvec3 triple(const std::string& what) {
    glm::dvec3 v;
    for (int i = 0; i < 3; ++i)
      v[i] = number(what);
    return v;
  }

  glm::vec3 coord3(const std::string& what) {
    glm::vec3 v;
    for (int i = 0; i < 3; ++i)
      v[i] = coordinate(what);
    return v;
  }

  ViewSt view(int line) {
    ViewSt v;
    v.line = line;
    expect("from", "'from' in the viewpoint");
    v.from = triple("viewpoint from");
    expect("at", "'at' in the viewpoint");
    v.at = triple("viewpoint at");
    expect("up", "'up' in the viewpoint");
    v.up = triple("viewpoint up");
    expect("angle", "'angle' in the viewpoint");
    v.angle = number("viewpoint angle");
    expect("hither", "'hither' in the viewpoint");
    number("viewpoint hither");
    expect("resolution", "'resolution' in the viewpoint");
    integer("viewpoint x resolution");
    integer("viewpoint y resolution");
    if (!(v.angle > 0.0 && v.angle < 180.0))
      fail(line, "viewpoint angle must be in (0, 180) degrees");
    return v;
  }

  LightSt light(int line, bool animated) {
    LightSt l;
    l.line = line;
    if (animated) l.name = std::string(word("animated light name").text);
    l.position = triple("light position");
    if (next_is_number()) l.color = triple("light colour");
    return l;
  }

  MaterialSt nff_material(int line) {
    // f R G B Kd Ks Shine T index_of_refraction
    MaterialSt m;
    m.line = line;
    const glm::dvec3 rgb = triple("fill colour");
    const double kd = number("fill Kd");
    const double ks = number("fill Ks");
    m.values.shine = number("fill Shine");
    m.values.transmittance = number("fill T");
    m.values.ior = number("fill index of refraction");
    m.values.diffuse = rgb * kd;
    m.values.specular = glm::dvec3(ks);
    m.values.reflectivity = ks;
    return m;
  }

  MaterialSt fm_material(int line) {
    // fm ambient(3) diffuse(3) specular(3) Shine T index_of_refraction
    MaterialSt m;
    m.line = line;
    triple("fill material ambient");
    m.values.diffuse = triple("fill material diffuse");
    m.values.specular = triple("fill material specular");
    m.values.shine = number("fill material Shine");
    m.values.transmittance = number("fill material T");
    m.values.ior = number("fill material index of refraction");
    m.values.reflectivity = (m.values.specular.x + m.values.specular.y + m.values.specular.z) / 3.0;
    return m;
  }

  GeometrySt polygon(int line, bool patch) {
    GeometrySt g;
    g.line = line;
    const std::size_t n = mesh_count("polygon vertex count", patch ? 6 : 3);
    if (n < 3) fail(line, "a polygon needs at least 3 vertices, got " + std::to_string(n));
    for (std::size_t i = 0; i < n; ++i) {
      g.positions.push_back(coord3("polygon vertex"));
      if (patch) g.normals.push_back(coord3("polygon patch normal"));
    }
    // A convex polygon: a fan around the first vertex.
    for (std::uint32_t i = 1; i + 1 < n; ++i) {
      g.pos_idx.emplace_back(0u, i, i + 1);
      if (patch) g.nrm_idx.emplace_back(0u, i, i + 1);
    }
    return g;
  }

  GeometrySt textured_triangle(int line, bool patch) {
    GeometrySt g;
    g.line = line;
    const Token& name = word("texture file name");
    g.texture = texture_path(name);
    for (int i = 0; i < 3; ++i) {
      g.positions.push_back(coord3("textured triangle vertex"));
      if (patch) g.normals.push_back(coord3("textured triangle normal"));
      const float u = coordinate("textured triangle u");
      const float v = coordinate("textured triangle v");
      g.uvs.emplace_back(u, v);
    }
    g.pos_idx.emplace_back(0u, 1u, 2u);
    if (patch) g.nrm_idx.emplace_back(0u, 1u, 2u);
    g.uv_idx.emplace_back(0u, 1u, 2u);
    return g;
  }

  void animated_triangle() {
    const std::size_t n = count("animated triangle time count", 19);
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 19; ++k)
        number("animated triangle data");
  }

  GeometrySt mesh(int line) {
    GeometrySt g;
    g.line = line;
    expect("vertices", "'vertices' after 'm'");
    const std::size_t nv = mesh_count("mesh vertex count", 3);
    g.positions.reserve(nv);
    for (std::size_t i = 0; i < nv; ++i)
      g.positions.push_back(coord3("mesh vertex"));
    const Token* t = &word("'normals', 'texturecoords' or 'triangles'");
    bool has_normals = false;
    bool has_uvs = false;
    if (t->text == "normals") {
      has_normals = true;
      const std::size_t nn = mesh_count("mesh normal count", 3);
      g.normals.reserve(nn);
      for (std::size_t i = 0; i < nn; ++i)
        g.normals.push_back(coord3("mesh normal"));
      t = &word("'texturecoords' or 'triangles'");
    }
    if (t->text == "texturecoords") {
      has_uvs = true;
      const std::size_t nt = mesh_count("mesh texture coordinate count", 2);
      g.texture = texture_path(word("texture file name"));
      g.uvs.reserve(nt);
      for (std::size_t i = 0; i < nt; ++i) {
        const float u = coordinate("mesh texture coordinate");
        const float v = coordinate("mesh texture coordinate");
        g.uvs.emplace_back(u, v);
      }
      t = &word("'triangles'");
    }
    if (t->text != "triangles")
      fail(t->line, "expected " +
                        std::string(has_uvs       ? "'triangles'"
                                    : has_normals ? "'texturecoords' or 'triangles'"
                                                  : "'normals', 'texturecoords' or 'triangles'") +
                        " in the mesh, got " + quoted(t->text));
    read_mesh_triangles(g, has_normals, has_uvs);
    return g;
  }

  // The mesh's triangles: per triangle three vertex indices, then three normal and three texture
  // coordinate indices where the mesh has them, each below its list's length.
  void read_mesh_triangles(GeometrySt& g, bool has_normals, bool has_uvs) {
    const std::size_t per = 3 * (1 + (has_normals ? 1 : 0) + (has_uvs ? 1 : 0));
    const std::size_t nt = count("mesh triangle count", per);
    g.pos_idx.reserve(nt);
    const auto index = [&](std::size_t limit, const char* what) {
      const long i = integer(what);
      if (static_cast<std::size_t>(i) >= limit)
        fail(line_, std::string(what) + " " + std::to_string(i) + " is not below the " +
                        std::to_string(limit) + " given");
      return static_cast<std::uint32_t>(i);
    };
    for (std::size_t i = 0; i < nt; ++i) {
      glm::uvec3 v, n, u;
      for (int k = 0; k < 3; ++k)
        v[k] = index(g.positions.size(), "vertex index");
      g.pos_idx.push_back(v);
      if (has_normals) {
        for (int k = 0; k < 3; ++k)
          n[k] = index(g.normals.size(), "normal index");
        g.nrm_idx.push_back(n);
      }
      if (has_uvs) {
        for (int k = 0; k < 3; ++k)
          u[k] = index(g.uvs.size(), "texture coordinate index");
        g.uv_idx.push_back(u);
      }
    }
  }

  KeysSt keyframes(int line) {
    KeysSt k;
    k.line = line;
    k.name = std::string(word("keyframe name").text);
    expect("{", "'{' after the keyframe name");
    while (true) {
      const Token& t = word("'transl', 'rot', 'scale', 'visibility' or '}'");
      if (t.text == "}") break;
      std::vector<AffKey>* dst = nullptr;
      if (t.text == "transl") {
        dst = &k.transl;
      } else if (t.text == "rot") {
        dst = &k.rot;
      } else if (t.text == "scale") {
        dst = &k.scale;
      } else if (t.text == "visibility") {
        const std::size_t n = count("visibility key count", 2);
        for (std::size_t i = 0; i < n; ++i) {
          number("visibility key time");
          integer("visibility flag");
        }
        k.visibility = true;
        continue;
      } else {
        fail(t.line, "unknown keyframe type " + quoted(t.text) +
                         " (expected transl, rot, scale or visibility)");
      }
      if (!dst->empty()) fail(t.line, std::string(t.text) + " keys given twice for " + k.name);
      const bool rot = t.text == "rot";
      const std::size_t n = count(std::string(t.text) + " key count", rot ? 8 : 7);
      if (n < 4)
        fail(line_, std::string(t.text) + " needs at least 4 keys (the first and the last " +
                        "only shape the end tangents), got " + std::to_string(n));
      for (std::size_t i = 0; i < n; ++i) {
        AffKey key;
        key.time = number("key time");
        // BART accepts decreasing key times (Robot1.aff's gun_rot1 restarts at 42 s after 48 s):
        // evaluation takes the first segment that ends after t, as kbsplpos.c does.
        if (!dst->empty() && key.time < dst->back().time && k.decreasing_line == 0)
          k.decreasing_line = line_;
        const glm::dvec3 v = triple(rot ? "rotation axis" : "key value");
        key.value = glm::dvec4(v, 0.0);
        if (rot) key.value.w = glm::radians(number("rotation angle"));
        key.tension = number("tension");
        key.continuity = number("continuity");
        key.bias = number("bias");
        dst->push_back(key);
      }
    }
    return k;
  }

  // Texture files: next to the including file, else in a TextureFiles folder beside or above it
  // (BART's layout: scene/aff/*.aff and scene/TextureFiles/*.ppm), else the same relative to the
  // root file.
  fs::path texture_path(const Token& name) {
    const fs::path n(std::string(name.text));
    std::vector<fs::path> tries;
    if (n.is_absolute()) {
      tries.push_back(n);
    } else {
      for (const fs::path& d : {src_.dir, root_dir_}) {
        tries.push_back(d / n);
        tries.push_back(d / "TextureFiles" / n);
        tries.push_back(d.parent_path() / "TextureFiles" / n);
      }
    }
    std::error_code ec;
    for (const fs::path& p : tries)
      if (fs::is_regular_file(p, ec)) return p.lexically_normal();
    std::string looked;
    for (const fs::path& p : tries)
      looked += (looked.empty() ? "" : ", ") + p.lexically_normal().string();
    fail(name.line,
         "texture file not found: " + std::string(name.text) + " (looked for " + looked + ")");
  }

  const Source& src_;
  const fs::path& root_dir_;
  std::size_t pos_ = 0;
  int line_ = 0;  // line of the last number read
};

// ---------------------------------------------------------------------------------------------
// Execution: statements -> Scene.

struct ObjectBuild {
  std::vector<std::uint8_t> has_normal;  // per vertex
  bool any_normal = false;
  bool any_uv = false;
};

// One inclusion of a file while it runs.
struct Frame {
  std::string canonical;
  int entry_material = -1;
  bool inherited = true;    // the current material is still the one in effect at entry
  bool uses_entry = false;  // geometry used that material
  const std::vector<std::uint32_t>* replay = nullptr;  // objects of an earlier, equal inclusion
  std::size_t cursor = 0;
  std::vector<std::uint32_t> record;  // objects created by this inclusion, in order
};

struct AnimatedNode {
  int node = 0;
  std::string name;
};

class Loader {
 public:
  explicit Loader(const std::string& path) : root_path_(path) { root_dir_ = folder_of(path); }

  Scene run() {
    std::error_code ec;
    if (!fs::is_regular_file(root_path_, ec))
      throw std::runtime_error(root_path_ + ": no such file");
    const int root = new_node(fs::path(root_path_).filename().string(), -1);
    scene_.roots.push_back(root);
    include(root_path_, root, "", 0);
    finalize_objects();
    build_animation();
    scene_.source = root_path_;
    scene_.set_time(0.0);
    return std::move(scene_);
  }

 private:
  [[noreturn]] static void fail(const std::string& file, int line, const std::string& what) {
    throw std::runtime_error(file + ":" + std::to_string(line) + ": " + what);
  }

  // Absolute folder of a file (includes and textures are found relative to it even when the root
  // was given as a bare relative name).
  static fs::path folder_of(const std::string& file) {
    std::error_code ec;
    const fs::path abs = fs::absolute(fs::path(file), ec);
    return (ec ? fs::path(file) : abs).lexically_normal().parent_path();
  }

  int new_node(std::string name, int parent) {
    Node n;
    n.name = std::move(name);
    n.parent = parent;
    scene_.nodes.push_back(std::move(n));
    const int idx = static_cast<int>(scene_.nodes.size()) - 1;
    if (parent >= 0) scene_.nodes[static_cast<std::size_t>(parent)].children.push_back(idx);
    return idx;
  }

  const ParsedFile& parsed(const std::string& canonical, const std::string& shown) {
    auto it = files_.find(canonical);
    if (it != files_.end()) return *it->second;
    auto pf = std::make_unique<ParsedFile>();
    pf->src.path = shown;
    pf->src.dir = folder_of(shown);
    std::ifstream in(shown, std::ios::binary);
    if (!in) throw std::runtime_error(shown + ": cannot open");
    std::ostringstream ss;
    ss << in.rdbuf();
    pf->src.text = ss.str();
    tokenize(pf->src);
    pf->statements = Parser(pf->src, root_dir_).parse();
    return *files_.emplace(canonical, std::move(pf)).first->second;
  }

  // Runs file `shown` as the content of node `node`. `from`/`line`: the including statement.
  void include(const std::string& shown, int node, const std::string& from, int line) {
    std::error_code ec;
    std::string canonical = fs::weakly_canonical(fs::path(shown), ec).string();
    if (ec) canonical = fs::absolute(fs::path(shown), ec).lexically_normal().string();
    for (std::size_t i = 0; i < stack_.size(); ++i) {
      if (stack_[i]->canonical != canonical) continue;
      std::string chain;
      for (std::size_t j = i; j < stack_.size(); ++j)
        chain += fs::path(stack_[j]->canonical).filename().string() + " -> ";
      fail(from, line, "include cycle: " + chain + fs::path(canonical).filename().string());
    }
    const ParsedFile& pf = parsed(canonical, shown);

    Frame frame;
    frame.canonical = canonical;
    frame.entry_material = material_;
    const auto independent = std::make_tuple(canonical, detail_, -2);
    const auto dependent = std::make_tuple(canonical, detail_, material_);
    if (auto it = cache_.find(independent); it != cache_.end()) {
      frame.replay = &it->second;
    } else if (auto dt = cache_.find(dependent); dt != cache_.end()) {
      frame.replay = &dt->second;
    }
    const long entry_detail = detail_;
    stack_.push_back(&frame);
    std::vector<int> scopes{node};
    for (const Statement& st : pf.statements)
      std::visit([&](const auto& s) { exec(s, pf.src, frame, scopes); }, st);
    stack_.pop_back();
    if (!frame.replay) {
      const auto key =
          std::make_tuple(canonical, entry_detail, frame.uses_entry ? frame.entry_material : -2);
      cache_.emplace(key, std::move(frame.record));
    }
  }

  void exec(const ViewSt& s, const Source&, Frame&, std::vector<int>&) { view_ = s; }

  void exec(const LightSt& s, const Source&, Frame&, std::vector<int>&) {
    Light l;
    l.position = glm::vec3(s.position);
    l.color = glm::clamp(glm::vec3(s.color), 0.0f, 1.0f);
    scene_.lights.push_back(l);
    if (!s.name.empty())
      light_names_.push_back({static_cast<int>(scene_.lights.size()) - 1, s.name});
  }

  void exec(const MaterialSt& s, const Source& src, Frame&, std::vector<int>&) {
    auto [it, added] = material_index_.emplace(s.values.key(), static_cast<int>(materials_.size()));
    if (added)
      materials_.push_back(
          {s.values, fs::path(src.path).filename().string() + ":" + std::to_string(s.line)});
    material_ = it->second;
    for (Frame* f : stack_)
      f->inherited = false;
  }

  void exec(const IncludeSt& s, const Source& src, Frame&, std::vector<int>& scopes) {
    if (s.detail > detail_) return;  // above the current detail level: skipped
    const fs::path p = (src.dir / s.name).lexically_normal();
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      fail(src.path, s.line, "include file not found: " + p.string());
    const int node = new_node(s.name, scopes.back());
    include(p.string(), node, src.path, s.line);
  }

  void exec(const DetailSt& s, const Source&, Frame&, std::vector<int>&) { detail_ = s.level; }

  void exec(const StaticXformSt& s, const Source& src, Frame&, std::vector<int>& scopes) {
    const int n =
        new_node("xs " + fs::path(src.path).filename().string() + ":" + std::to_string(s.line),
                 scopes.back());
    Node& node = scene_.nodes[static_cast<std::size_t>(n)];
    node.translation = s.translation;
    node.rotation = from_axis_angle(s.axis, glm::radians(s.degrees));
    node.scale = s.scale;
    if (!(glm::length(s.axis) > 0.0) && s.degrees != 0.0)
      scene_.warn(src.path + ":" + std::to_string(s.line) +
                  ": static rotation about a zero axis: no rotation");
    scopes.push_back(n);
  }

  void exec(const AnimXformSt& s, const Source&, Frame&, std::vector<int>& scopes) {
    const int n = new_node(s.name, scopes.back());
    animated_.push_back({n, s.name});
    scopes.push_back(n);
  }

  void exec(const CloseSt&, const Source&, Frame&, std::vector<int>& scopes) { scopes.pop_back(); }

  void exec(const AnimParamsSt& s, const Source&, Frame&, std::vector<int>&) { anim_ = s; }

  void exec(const KeysSt& s, const Source& src, Frame&, std::vector<int>&) {
    keys_[s.name] = &s;  // a later definition replaces an earlier one (BART's FindAnimation)
    if (s.visibility)
      scene_.warn(src.path + ":" + std::to_string(s.line) + ": visibility keys of '" + s.name +
                  "' are not supported: always visible");
    if (s.decreasing_line > 0)
      scene_.warn(src.path + ":" + std::to_string(s.decreasing_line) + ": key times of '" + s.name +
                  "' decrease: each time uses the first segment that ends after it (as " +
                  "BART does)");
  }

  void exec(const SkippedSt& s, const Source& src, Frame&, std::vector<int>&) {
    ++scene_.skipped_primitives;
    if (skipped_kinds_.insert(s.what).second)  // one warning per kind
      scene_.warn(s.what + " is not supported: skipped (first at " + src.path + ":" +
                  std::to_string(s.line) + ")");
  }

  void exec(const GeometrySt& g, const Source& src, Frame& frame, std::vector<int>& scopes) {
    // Geometry that uses the material in effect at a frame's entry makes that frame (and the
    // frames it inherited the material from) depend on it.
    for (auto it = stack_.rbegin(); it != stack_.rend() && (*it)->inherited; ++it)
      (*it)->uses_entry = true;
    Node& node = scene_.nodes[static_cast<std::size_t>(scopes.back())];
    if (node.object < 0) {
      std::uint32_t obj = 0;
      if (frame.replay) {
        if (frame.cursor >= frame.replay->size())
          fail(src.path, g.line, "internal error: instanced file has more objects than before");
        obj = (*frame.replay)[frame.cursor++];
      } else {
        obj = static_cast<std::uint32_t>(scene_.objects.size());
        Object o;
        o.name = node.name;
        scene_.objects.push_back(std::move(o));
        builds_.emplace_back();
        frame.record.push_back(obj);
      }
      node.object = static_cast<int>(obj);
      Instance inst;
      inst.object = obj;
      inst.id = static_cast<std::uint32_t>(scopes.back());
      scene_.instances.push_back(inst);
    }
    if (frame.replay) return;  // the object already holds these triangles
    const int tex = g.texture.empty() ? -1 : texture(g.texture, src, g.line);
    append(scene_.objects[static_cast<std::size_t>(node.object)],
           builds_[static_cast<std::size_t>(node.object)], g, scene_material(tex));
  }

  int texture(const fs::path& file, const Source& src, int line) {
    const std::string key = file.string();
    if (auto it = texture_index_.find(key); it != texture_index_.end()) return it->second;
    std::ifstream in(file, std::ios::binary);
    if (!in) fail(src.path, line, "cannot open texture file " + key);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                           std::istreambuf_iterator<char>());
    Texture t;
    try {
      t = decode_image(bytes.data(), bytes.size(), key);
    } catch (const std::exception& e) {
      fail(src.path, line, e.what());
    }
    t.name = file.filename().string();
    const int idx = static_cast<int>(scene_.textures.size());
    scene_.textures.push_back(std::move(t));
    texture_index_.emplace(key, idx);
    return idx;
  }

  std::uint32_t scene_material(int tex) {
    const auto key = std::make_pair(material_, tex);
    if (auto it = scene_material_.find(key); it != scene_material_.end()) return it->second;
    Material m;
    MaterialValues v;  // no f/fm yet: white, diffuse only
    if (material_ >= 0) {
      v = materials_[static_cast<std::size_t>(material_)].values;
      m.name = materials_[static_cast<std::size_t>(material_)].where;
    } else {
      m.name = "default";
    }
    // The shader multiplies texture and base colour; BART's textured materials often carry a
    // black or dark diffuse colour (garden.aff), so a texture replaces the diffuse colour.
    m.base_color =
        tex >= 0 ? glm::vec4(1.0f) : glm::vec4(glm::clamp(glm::vec3(v.diffuse), 0.0f, 1.0f), 1.0f);
    m.texture = tex;
    if (tex >= 0) m.name += " " + scene_.textures[static_cast<std::size_t>(tex)].name;
    m.specular = glm::clamp(glm::vec3(v.specular), 0.0f, 1.0f);
    m.shininess = static_cast<float>(std::clamp(v.shine, 0.0, 255.0));
    m.reflectivity = static_cast<float>(std::clamp(v.reflectivity, 0.0, 1.0));
    // NFF's T is the weight of the transmitted ray, bent by the index of refraction of the
    // material's inside: a refraction ray (docs/shading.md section 7). BART writes an index of 0
    // where none is meant (opaque materials, and the kitchen's 4 % transmittance); that, and an
    // index outside 1/64..64, refracts with index 1: a straight ray.
    m.transmission = static_cast<float>(std::clamp(v.transmittance, 0.0, 1.0));
    m.refraction = m.transmission;
    if (m.refraction > 0.0f)
      m.ior = v.ior >= 1.0 / 64.0 && v.ior <= 64.0 ? static_cast<float>(v.ior) : 1.0f;
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    const auto idx = static_cast<std::uint32_t>(scene_.materials.size());
    scene_.materials.push_back(std::move(m));
    scene_material_.emplace(key, idx);
    return idx;
  }

  // Appends the triangles, with one vertex per distinct (position, normal, uv) index triple.
  static void append(Object& o, ObjectBuild& b, const GeometrySt& g, std::uint32_t material) {
    const bool has_n = !g.nrm_idx.empty();
    const bool has_t = !g.uv_idx.empty();
    b.any_normal = b.any_normal || has_n;
    b.any_uv = b.any_uv || has_t;
    constexpr std::uint64_t kNone = (1u << 21) - 1;  // the parser keeps counts below it
    std::unordered_map<std::uint64_t, std::uint32_t> remap;
    remap.reserve(g.positions.size());
    for (std::size_t i = 0; i < g.pos_idx.size(); ++i) {
      glm::uvec3 tri;
      for (int k = 0; k < 3; ++k) {
        const std::uint64_t v = g.pos_idx[i][k];
        const std::uint64_t n = has_n ? g.nrm_idx[i][k] : kNone;
        const std::uint64_t t = has_t ? g.uv_idx[i][k] : kNone;
        const std::uint64_t key = (v << 42) | (n << 21) | t;
        auto [it, added] = remap.emplace(key, static_cast<std::uint32_t>(o.positions.size()));
        if (added) {
          o.positions.push_back(g.positions[v]);
          glm::vec3 nrm(0.0f);
          bool ok = false;
          if (n != kNone) {
            const glm::dvec3 d(g.normals[n]);
            const double len = glm::length(d);
            ok = std::isfinite(len) && len > 0.0;
            if (ok) nrm = glm::vec3(d / len);
          }
          o.normals.push_back(nrm);
          b.has_normal.push_back(ok ? 1 : 0);
          o.texcoords.push_back(t != kNone ? g.uvs[t] : glm::vec2(0.0f));
        }
        tri[k] = it->second;
      }
      o.triangles.push_back(tri);
      o.material.push_back(material);
    }
  }

  // Vertices without a normal in an object that has normals get their triangle's face normal
  // (flat shading, as BART shows meshes without normals); a vertex shared by triangles of
  // different faces is duplicated.
  void finalize_objects() {
    for (std::size_t oi = 0; oi < scene_.objects.size(); ++oi) {
      Object& o = scene_.objects[oi];
      ObjectBuild& b = builds_[oi];
      if (!b.any_normal) {
        o.normals.clear();
      } else {
        std::vector<std::int64_t> owner(o.positions.size(), -1);
        for (std::size_t t = 0; t < o.triangles.size(); ++t) {
          glm::uvec3& tri = o.triangles[t];
          if (b.has_normal[tri.x] && b.has_normal[tri.y] && b.has_normal[tri.z]) continue;
          const glm::dvec3 a(o.positions[tri.x]);
          const glm::dvec3 c =
              glm::cross(glm::dvec3(o.positions[tri.y]) - a, glm::dvec3(o.positions[tri.z]) - a);
          const double len = glm::length(c);
          const glm::vec3 fn = len > 0.0 ? glm::vec3(c / len) : glm::vec3(0.0f, 0.0f, 1.0f);
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = tri[k];
            if (b.has_normal[v]) continue;
            if (owner[v] < 0) {
              owner[v] = static_cast<std::int64_t>(t);
              o.normals[v] = fn;
            } else if (owner[v] != static_cast<std::int64_t>(t)) {
              tri[k] = static_cast<std::uint32_t>(o.positions.size());
              o.positions.push_back(o.positions[v]);
              o.texcoords.push_back(o.texcoords[v]);
              o.normals.push_back(fn);
            }
          }
        }
        for (std::size_t v = 0; v < owner.size(); ++v)
          if (!b.has_normal[v] && owner[v] < 0) o.normals[v] = glm::vec3(0.0f, 0.0f, 1.0f);
      }
      if (!b.any_uv) o.texcoords.clear();
      mark_degenerate_triangles(o);
    }
    builds_.clear();
  }

  // Samples a spline over its valid range [keys[1], keys[n-2]] clipped to [0, end]: at every key
  // time (both one-sided limits where the spline jumps, as two samples with the same time) and at
  // max(kAffMinStepsPerKey, kAffSamplesPerSecond x length) steps between consecutive key times.
  template <typename Spline, typename ToVec4, typename Same>
  void sample(const Spline& spline, const std::vector<AffKey>& keys, double end, AnimChannel& ch,
              ToVec4 to_vec4, Same same) {
    const double lo = std::clamp(keys[1].time, 0.0, end);
    const double hi = std::clamp(keys[keys.size() - 2].time, 0.0, end);
    // Key times in order (BART allows decreasing ones; only new maxima start segments).
    std::vector<double> cuts{lo};
    for (std::size_t i = 1; i + 1 < keys.size(); ++i)
      if (keys[i].time > cuts.back() && keys[i].time < hi) cuts.push_back(keys[i].time);
    if (hi > cuts.back()) cuts.push_back(hi);
    // The samples this channel takes (at most 2 per key time plus the steps between), counted
    // before any is taken: key times days apart would ask for gigabytes.
    double samples = 0.0;
    for (std::size_t c = 0; c < cuts.size(); ++c)
      samples += 2.0 + (c + 1 < cuts.size()
                            ? std::max(static_cast<double>(kAffMinStepsPerKey),
                                       std::ceil((cuts[c + 1] - cuts[c]) * kAffSamplesPerSecond))
                            : 0.0);
    if (samples > static_cast<double>(kMaxSamples - samples_))
      throw std::runtime_error(
          root_path_ + ": the keyframes of '" +
          scene_.nodes[static_cast<std::size_t>(ch.node)].name + "' span " +
          std::to_string(hi - lo) + " s: sampled " +
          std::to_string(static_cast<int>(kAffSamplesPerSecond)) +
          " times a second, the scene's channels would exceed the loader's limit of " +
          std::to_string(kMaxSamples) + " samples");
    samples_ += static_cast<std::size_t>(samples);
    const auto put = [&](double t, const auto& v) {
      ch.times.push_back(t);
      ch.values.push_back(to_vec4(v));
    };
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      const double t = cuts[c];
      const auto left = spline(t, Side::kLeft);
      const auto right = spline(t, Side::kRight);
      put(t, left);
      if (!same(left, right)) put(t, right);
      if (c + 1 == cuts.size()) break;
      const double len = cuts[c + 1] - t;
      const auto steps = static_cast<std::size_t>(std::max(
          static_cast<double>(kAffMinStepsPerKey), std::ceil(len * kAffSamplesPerSecond - 1e-9)));
      for (std::size_t k = 1; k < steps; ++k) {
        const double tk = t + len * static_cast<double>(k) / static_cast<double>(steps);
        put(tk, spline(tk, Side::kBart));
      }
    }
  }

  AnimChannel position_channel(int node, AnimPath path, const std::vector<AffKey>& keys,
                               double end) {
    AnimChannel ch;
    ch.node = node;
    ch.path = path;
    ch.interpolation = AnimInterpolation::kLinear;
    const auto same = [](const glm::dvec3& a, const glm::dvec3& b) {
      return glm::length(a - b) <= 1e-9 * std::max(1.0, glm::length(a));
    };
    const auto to_vec4 = [](const glm::dvec3& v) { return glm::dvec4(v, 0.0); };
    sample(PositionSpline(keys), keys, end, ch, to_vec4, same);
    return ch;
  }

  AnimChannel rotation_channel(int node, const std::vector<AffKey>& keys, double end) {
    AnimChannel ch;
    ch.node = node;
    ch.path = AnimPath::kRotation;
    ch.interpolation = AnimInterpolation::kLinear;
    const auto same = [](const glm::dquat& a, const glm::dquat& b) {
      return std::abs(glm::dot(a, b)) >= 1.0 - 1e-12;
    };
    const auto to_vec4 = [](const glm::dquat& q) { return glm::dvec4(q.x, q.y, q.z, q.w); };
    sample(RotationSpline(keys), keys, end, ch, to_vec4, same);
    // Consecutive samples in the same hemisphere (slerp takes the shorter way anyway).
    for (std::size_t i = 1; i < ch.values.size(); ++i)
      if (glm::dot(ch.values[i - 1], ch.values[i]) < 0.0) ch.values[i] = -ch.values[i];
    return ch;
  }

  static double spline_end(const KeysSt& k) {
    double e = 0.0;
    for (const auto* keys : {&k.transl, &k.rot, &k.scale})
      if (!keys->empty()) e = std::max(e, (*keys)[keys->size() - 2].time);
    return e;
  }

  // The animation's end: the `a` line's, else the last key of any spline that drives something.
  double animation_end(const KeysSt* cam_keys) const {
    if (anim_) return std::max(anim_->end, 0.0);
    double end = 0.0;
    for (const AnimatedNode& a : animated_)
      if (auto it = keys_.find(a.name); it != keys_.end())
        end = std::max(end, spline_end(*it->second));
    for (const auto& [light, name] : light_names_)
      if (auto it = keys_.find(name); it != keys_.end())
        end = std::max(end, spline_end(*it->second));
    if (cam_keys) end = std::max(end, spline_end(*cam_keys));
    return end;
  }

  // The view's orthonormal frame: forward f and up u (a degenerate view is repaired with a
  // warning).
  void view_frame(const ViewSt& v, glm::dvec3& f, glm::dvec3& u) {
    f = v.at - v.from;
    if (!(glm::length(f) > 0.0)) {
      scene_.warn("viewpoint: 'from' equals 'at': looking along -Z");
      f = {0.0, 0.0, -1.0};
    }
    f = glm::normalize(f);
    u = v.up - f * glm::dot(v.up, f);
    if (!(glm::length(u) > 1e-12 * glm::length(v.up)) || !(glm::length(u) > 0.0)) {
      scene_.warn("viewpoint: 'up' is parallel to the view direction: another up is used");
      u = std::abs(f.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
      u = u - f * glm::dot(u, f);
    }
    u = glm::normalize(u);
  }

  // Camera: `v` gives the static view; `k camera` animates position (transl) and orientation
  // (rot) of a node that looks along its local -Z with +Y up (BART's GetCamera).
  void build_camera(const KeysSt* cam_keys, double end) {
    Camera cam;
    cam.name = "camera";
    const ViewSt v = view_ ? *view_ : ViewSt{};
    glm::dvec3 f;
    glm::dvec3 u;
    view_frame(v, f, u);
    cam.position = glm::vec3(v.from);
    cam.forward = glm::vec3(f);
    cam.up = glm::vec3(u);
    cam.yfov = static_cast<float>(glm::radians(v.angle));  // AFF: vertical field of view
    if (cam_keys && (!cam_keys->transl.empty() || !cam_keys->rot.empty())) {
      const int n = new_node("camera", -1);
      scene_.roots.push_back(n);
      Node& node = scene_.nodes[static_cast<std::size_t>(n)];
      node.translation = v.from;
      // Columns: right, up, -forward (the camera looks down its local -Z).
      node.rotation = glm::normalize(glm::quat_cast(glm::dmat3(glm::cross(f, u), u, -f)));
      node.camera = static_cast<int>(scene_.cameras.size());
      cam.node = n;
      if (!cam_keys->transl.empty())
        add_channel(position_channel(n, AnimPath::kTranslation, cam_keys->transl, end));
      if (!cam_keys->rot.empty()) add_channel(rotation_channel(n, cam_keys->rot, end));
      if (!cam_keys->scale.empty())
        scene_.warn("keyframes 'camera': scale keys are ignored for the camera");
    }
    scene_.cameras.push_back(cam);
  }

  // Each `x NAME` transform driven by `k NAME`.
  void animate_transforms(double end, std::map<std::string, bool>& used) {
    for (const AnimatedNode& a : animated_) {
      const auto it = keys_.find(a.name);
      if (it == keys_.end()) {
        scene_.warn("transform '" + a.name + "' has no keyframes (k " + a.name +
                    "): it stays at the identity");
        continue;
      }
      used[a.name] = true;
      const KeysSt& k = *it->second;
      if (!k.transl.empty())
        add_channel(position_channel(a.node, AnimPath::kTranslation, k.transl, end));
      if (!k.rot.empty()) add_channel(rotation_channel(a.node, k.rot, end));
      if (!k.scale.empty()) add_channel(position_channel(a.node, AnimPath::kScale, k.scale, end));
    }
  }

  // Animated lights (`la NAME`): their position follows the translation keys of NAME.
  void animate_lights(double end, std::map<std::string, bool>& used) {
    for (const auto& [light, name] : light_names_) {
      const auto it = keys_.find(name);
      if (it == keys_.end() || it->second->transl.empty()) {
        scene_.warn("light '" + name + "' has no translation keyframes: it stays in place");
        continue;
      }
      used[name] = true;
      const int n = new_node("light " + name, -1);
      scene_.roots.push_back(n);
      Node& node = scene_.nodes[static_cast<std::size_t>(n)];
      node.translation = glm::dvec3(scene_.lights[static_cast<std::size_t>(light)].position);
      node.light = light;
      scene_.lights[static_cast<std::size_t>(light)].node = n;
      add_channel(position_channel(n, AnimPath::kTranslation, it->second->transl, end));
    }
  }

  // Animated flags: targeted nodes and everything below them.
  void mark_animated_nodes() {
    std::vector<std::uint8_t> targeted(scene_.nodes.size(), 0);
    for (const AnimChannel& ch : scene_.animations)
      targeted[static_cast<std::size_t>(ch.node)] = 1;
    std::vector<std::pair<int, bool>> stack;
    for (int r : scene_.roots)
      stack.emplace_back(r, false);
    while (!stack.empty()) {
      const auto [n, anc] = stack.back();
      stack.pop_back();
      Node& node = scene_.nodes[static_cast<std::size_t>(n)];
      node.animated = anc || targeted[static_cast<std::size_t>(n)];
      for (int c : node.children)
        stack.emplace_back(c, node.animated);
    }
  }

  void build_animation() {
    std::map<std::string, bool> used;
    for (const auto& [name, k] : keys_)
      used[name] = false;
    const KeysSt* cam_keys = nullptr;
    if (auto it = keys_.find("camera"); it != keys_.end()) {
      cam_keys = it->second;
      used["camera"] = true;
    }
    const double end = animation_end(cam_keys);
    if (view_ || cam_keys) build_camera(cam_keys, end);
    animate_transforms(end, used);
    animate_lights(end, used);
    for (const auto& [name, u] : used)
      if (!u) scene_.warn("keyframes '" + name + "' animate nothing: ignored");
    scene_.animation_seconds = scene_.animations.empty() ? 0.0 : end;
    mark_animated_nodes();
  }

  void add_channel(AnimChannel ch) { scene_.animations.push_back(std::move(ch)); }

  struct NamedMaterial {
    MaterialValues values;
    std::string where;
  };

  std::string root_path_;
  fs::path root_dir_;
  Scene scene_;
  std::map<std::string, std::unique_ptr<ParsedFile>> files_;
  std::vector<Frame*> stack_;
  std::map<std::tuple<std::string, long, int>, std::vector<std::uint32_t>> cache_;
  long detail_ = 0;
  int material_ = -1;  // index into materials_, -1 = none given yet
  std::vector<NamedMaterial> materials_;
  std::map<std::array<double, 10>, int> material_index_;
  std::map<std::pair<int, int>, std::uint32_t> scene_material_;
  std::map<std::string, int> texture_index_;
  std::vector<ObjectBuild> builds_;
  std::optional<ViewSt> view_;
  std::optional<AnimParamsSt> anim_;
  std::map<std::string, const KeysSt*> keys_;
  std::vector<AnimatedNode> animated_;
  std::vector<std::pair<int, std::string>> light_names_;
  std::set<std::string> skipped_kinds_;
  // Animation samples of every channel in all (sample()): 2^24, 38 times what BART's robots take
  // (442,327), at most 670 MB of keys.
  static constexpr std::size_t kMaxSamples = std::size_t{1} << 24;
  std::size_t samples_ = 0;
};

}  // namespace

glm::dvec3 aff_position_spline(const std::vector<AffKey>& keys, double t) {
  if (keys.size() < 4) throw std::invalid_argument("a BART spline needs at least 4 keys");
  return PositionSpline(keys)(t);
}

glm::dquat aff_rotation_spline(const std::vector<AffKey>& keys, double t) {
  if (keys.size() < 4) throw std::invalid_argument("a BART spline needs at least 4 keys");
  return RotationSpline(keys)(t);
}

Scene load_aff(const std::string& path) {
  return Loader(path).run();
}

}  // namespace saarcor::host
