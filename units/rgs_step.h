// The ray generation and shading unit's semantics (paper section 3; Figure 2 paths a and g;
// docs/shading.md; docs/shading.md; decisions D10, D15, D19, D37): the RGC hands a thread a
// primary packet of pixels, the RGS builds R' and T for the transformation unit (path a); when a
// packet returns (path g) it records primary hits, shades: the world normal through M^T, the
// material and texture, ambient, per light a packet of shadow-ray directions through the
// transformation unit and the cosines on the RGS FP helper (mul, sqrt, div), specular highlights,
// then reflection, transparency and refraction children (the refraction factor mu on the RGS FP
// helper too), traced last in, first out. Dot products and normals run on the transformation unit
// and are counted there. Timing: units/ray_source.cpp (the RGC's admission and the final hits);
// exact-cycle test: units/unit_timing_test.cpp (UnitTimingRaySource.*).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "units/packet.h"
#include "units/shading.h"

namespace saarcor::units {

template <class F, int kLanes, class D>
class RgsStep {
 public:
  using State = PacketState<F, kLanes, D>;
  using Mat64 = typename State::Mat64;
  using Operand = typename D::Operand;  // a vector as the dot products read it

  RgsStep(const memif::MemoryImage& image, const FunctionalParams& params, int packet) {
    const auto& regs = image.registers();
    max_depth_ =
        params.max_depth >= 0 ? static_cast<std::uint32_t>(params.max_depth) : regs.max_depth;
    epsilon_ = F::from_bits(regs.epsilon);
    surf_.resize(static_cast<std::size_t>(packet));
  }

  // The RGC hands the thread the primary packet of pixels `pixel[i]` (memif::kNone = empty lane).
  void start_primary(State& t, const std::vector<std::uint32_t>& pixel) {
    pending_size_ = 0;
    mem_.clear();
    pixels_.assign(pixel.begin(), pixel.end());
    t.scene.refresh(t.image);
    normal_instance_ = memif::kNone;
    const auto width = static_cast<std::uint32_t>(t.sink.width);
    GenPacket<F>& pk = t.transformation.input();  // built in place (load's copy: self-assignment)
    pk.kind = RayKind::kPrimary;
    pk.depth = 0;
    pk.shared_origin = t.params.shared_origin;
    pk.lanes.assign(t.lanes.size(), GenLane<F>{});
    for (int i = 0; i < t.p; ++i) {
      auto& g = pk.lanes[static_cast<std::size_t>(i)];
      g.t = t.transformation.camera();
      g.ro = {F::zero(), F::zero(), F::zero()};
      const std::uint32_t px = i < static_cast<int>(pixel.size()) ? pixel[i] : memif::kNone;
      if (px == memif::kNone) continue;
      g.valid = true;
      g.pixel = px;
      g.weight = 255;
      // The pixel coordinates as F (exact binary64 integers, rounded once: as F::from_int).
      g.rd = {t.u.raw.from_double(static_cast<double>(px % width)),
              t.u.raw.from_double(static_cast<double>(px / width)), F::one()};
    }
    t.transformation.load(t, pk);
  }

  // A returning primary or secondary packet (path g): its surfaces, then the lights.
  void shade_surface(State& t) {
    material_ = memif::kNone;
    account_counters(t);
    if (t.kind == RayKind::kPrimary) record_primary(t);
    if (!t.params.shade) return next_packet(t);
    const auto& regs = t.image.registers();
    const Rgb8 ambient = unpack_rgb(regs.ambient_rgb);
    const Rgb8 background = unpack_rgb(regs.background_rgb);
    static const Surface kClear{};
    for (int i = 0; i < t.p; ++i) {
      const Lane<F>& l = t.lane(i);
      Surface& s = surf_[static_cast<std::size_t>(i)];
      s = kClear;  // as Surface{}, without its string store (as in TransformationStep::load)
      if (!l.valid) continue;
      s.pixel = l.pixel;
      s.weight = l.weight;
      s.depth = t.depth;
      if (!l.hit.hit()) {
        add_colour(t, l.pixel, l.weight, background);
        continue;
      }
      surface(t, l, s, ambient);
    }
    light_ = 0;
    next_light(t);
  }

  // The cosines of light `light_` from the generated shadow-ray directions; the lit hits' shadow
  // rays go to the traversal unit when shadows are traced.
  void shade_light(State& t) {
    std::uint64_t trace = 0;
    for (int i = 0; i < t.p; ++i) {
      Surface& s = surf_[static_cast<std::size_t>(i)];
      s.lit = false;
      s.highlight = false;
      if (!s.hit) continue;
      const Vec3<F>& sd = t.lane(i).world.d;  // hit point - L
      const Operand ds = D::operand(sd);      // decoded once for the light's two or three dots
      const F ns = shade_dot(t, s.n, s.n_op, sd, ds);
      const F ss = shade_dot(t, sd, ds, sd, ds);
      s.lit = is_neg_nonzero(ns);
      if (!s.lit) continue;
      s.cos = cosine(t, ns, s.nn, ss);
      if (s.spec) {
        const F rl = shade_dot(t, s.r, s.r_op, sd, ds);
        s.highlight = is_neg_nonzero(rl);
        if (s.highlight) s.cos_s = cosine(t, rl, s.rr, ss);
      }
      trace |= std::uint64_t{1} << i;
    }
    t.u.shading_transformation_steps += 1;
    if (!t.params.shadows || trace == 0) {
      for (int i = 0; i < t.p; ++i)
        t.lane(i).valid = false;
      return accumulate_light(t);
    }
    for (int i = 0; i < t.p; ++i)
      t.lane(i).valid = lane_in(trace, i);
    t.traversal.issue(t);
  }

  // A returning shadow packet: the light's contribution for the unoccluded hits.
  void shade_shadow(State& t) {
    account_counters(t);
    accumulate_light(t);
  }

  // The memory accesses of the RGS request executed last, in the order the RGS makes them: the
  // shading-bank reads its shading needed and, when the primary packet is finished, its pixels'
  // frame-buffer writes (the cycle model's RGS issues them; docs/shading.md "Shading traffic").
  const std::vector<RgsAccess>& memory() const { return mem_; }
  // A new RGS request begins (the dispatcher calls this before shade_*: a phase may run the next
  // one inline, as shade_light after the shadow-ray directions when no shadow rays are traced).
  void begin_request() { mem_.clear(); }

 private:
  // The RGS's per-lane surface context while it shades a packet's hits.
  struct Surface {
    bool hit = false;
    std::uint32_t pixel = memif::kNone;
    std::uint32_t weight = 0;
    std::uint32_t depth = 0;
    Ray<F> ray;
    HitRecord<F> rec;
    Vec3<F> n{};
    F nn{}, kk{}, rr{};
    Vec3<F> r{};  // reflected view direction (specular)
    // n and r as the dot products read them, decoded once per hit for every light's dots.
    Operand n_op{}, r_op{};
    bool spec = false;
    memif::MaterialRecord mat;
    Rgb8 base{}, spec_rgb{};
    std::array<std::uint32_t, 3> acc{};
    F cos{}, cos_s{};
    bool lit = false, highlight = false;
  };

  // ---- arithmetic: the datapath policy D's kernels (units/fast_datapath.h,
  // units/reference_datapath.h); the ops counted here per use (the same counts as UnitFp's per op).
  static void count_transform(State& t, std::uint64_t steps) {
    PipelineUnits<F>::count(t.u.transformation_ops, 9 * steps, 9 * steps, 0, 0);
  }
  // A direction step (ops counted by the caller) as three dot products: each of its rows is
  // dot_step's expression with the row as the first vector.
  static Vec3<F> direction_step(const State& t, const Mat34<F>& m, const Vec3<F>& v) {
    Vec3<F> out;
    D::direction_steps(t, m, v, m, v, out, out);
    return out;
  }
  // A dot product on the transformation unit (a zero-translation row: 3 mul, 3 add).
  static F shade_dot(State& t, const Vec3<F>& a, const Vec3<F>& b) {
    PipelineUnits<F>::count(t.u.transformation_ops, 3, 3, 0, 0);
    return D::dot(t, a, b);
  }
  // The same with both vectors as the datapath reads them already (D::operand of a and of b).
  static F shade_dot(State& t, const Vec3<F>& a, const Operand& da, const Vec3<F>& b,
                     const Operand& db) {
    PipelineUnits<F>::count(t.u.transformation_ops, 3, 3, 0, 0);
    return D::dot(t, a, da, b, db);
  }
  // -x / sqrt(a * b) on the RGS helper (1 mul, 1 sqrt, 1 div).
  static F cosine(State& t, F x, F a, F b) {
    PipelineUnits<F>::count(t.u.rgs_ops, 0, 1, 1, 0);
    ++t.u.rgs_ops.sqrt;
    return D::cosine(t, x, a, b);
  }
  // k + k for k = n / d on the RGS helper (1 div, 1 add).
  static F twice_quotient(State& t, F n, F d) {
    PipelineUnits<F>::count(t.u.rgs_ops, 1, 0, 1, 0);
    const F k = t.u.raw.div(n, d);
    return t.u.raw.add(k, k);
  }
  // T_R = [D, N, D; O] (paper 2.2.2 with the erratum: translation O).
  static Mat34<F> reflect_matrix(const Ray<F>& ray, const Vec3<F>& n) {
    Mat34<F> m{};
    for (int r = 0; r < 3; ++r)
      m[r] = {ray.d[r], n[r], ray.d[r], ray.o[r]};
    return m;
  }

  // ---- the frame ------------------------------------------------------------------------------
  void record_primary(State& t) {
    for (int i = 0; i < t.p; ++i) {
      const Lane<F>& l = t.lane(i);
      if (!l.valid) continue;
      auto& px = t.sink.pixels[l.pixel];
      px.t = l.hit.hit() ? l.hit.t.bits : F::infinity().bits;
      px.u = l.hit.u.bits;
      px.v = l.hit.v.bits;
      px.cos = l.hit.c.bits;
      px.instance = l.hit.instance;
      px.triangle = l.hit.triangle;
      for (int k = 0; k < 3; ++k) {
        px.o[static_cast<std::size_t>(k)] = l.world.o[k].bits;
        px.d[static_cast<std::size_t>(k)] = l.world.d[k].bits;
      }
      px.counters = l.counters;
    }
  }
  static void add_colour(State& t, std::uint32_t pixel, std::uint32_t weight, const Rgb8& c) {
    auto& s = t.sink.colour_sum[pixel];
    for (int k = 0; k < 3; ++k)
      s[static_cast<std::size_t>(k)] += weight * c[k];
  }
  static void account_counters(State& t) {
    for (int i = 0; i < t.p; ++i) {
      Lane<F>& l = t.lane(i);
      l.counters.traversal_steps += t.traversal_steps[static_cast<std::size_t>(i)];
      t.traversal_steps[static_cast<std::size_t>(i)] = 0;
      if (l.valid) t.sink.by_kind[static_cast<int>(t.kind)] += l.counters;
    }
  }

  // ---- shading --------------------------------------------------------------------------------
  // One hit's surface: world normal, material, base colour, reflected direction, ambient.
  void surface(State& t, const Lane<F>& l, Surface& s, const Rgb8& ambient) {
    s.hit = true;
    s.ray = l.world;
    s.rec = l.hit;
    const memif::InstanceHeader h = t.image.instance_header(s.rec.instance);
    s.n = world_normal(t, h, s.rec);
    s.n_op = D::operand(s.n);
    s.nn = shade_dot(t, s.n, s.n_op, s.n, s.n_op);
    t.u.shading_transformation_steps += 1;  // normal step; the dots count below
    const std::uint32_t record = h.shading_base + s.rec.triangle;
    const memif::ShadingRecord rec = read_shading_record(t.image, record);
    read(t.image.registers().shading_record_base + memif::kShadingRecordWords * record,
         memif::kShadingRecordWords, 0);
    if (rec.material != material_) {  // the packet's hits mostly share a material: read once
      material_ = rec.material;
      material_record_ = read_material(t.image, rec.material);  // the register's decoded record
      // w0..w3; the refraction words only for a material w3 flags as refracting.
      const std::uint32_t a =
          t.image.registers().material_base + memif::kMaterialWords * rec.material;
      read(a, memif::kMaterialBaseWords, 1);
      if (material_record_.refraction != 0)
        read(a + memif::kMaterialBaseWords, memif::kMaterialWords - memif::kMaterialBaseWords, 2);
    }
    s.mat = material_record_;
    s.base = base_colour(t.image, rec, s.mat, fix16(s.rec.u), fix16(s.rec.v),
                         [this](std::uint32_t a) { read(a, 1, 2); });
    const std::uint32_t shininess = s.mat.specular_rgb_shininess >> 24;
    s.spec_rgb = unpack_rgb(s.mat.specular_rgb_shininess);
    s.spec = shininess >= 1 && (s.mat.specular_rgb_shininess & 0xFFFFFFu) != 0;
    const bool reflect = t.params.secondary && t.depth < max_depth_ && s.mat.reflectivity > 0;
    if (s.spec || reflect)
      s.kk = twice_quotient(t, shade_dot(t, s.ray.d, D::operand(s.ray.d), s.n, s.n_op), s.nn);
    if (s.spec) {
      const Mat34<F> tr = reflect_matrix(s.ray, s.n);
      count_transform(t, 1);
      s.r = direction_step(t, tr, Vec3<F>{F::one(), s.kk.neg(), F::zero()});
      s.r_op = D::operand(s.r);
      s.rr = shade_dot(t, s.r, s.r_op, s.r, s.r_op);
      t.u.shading_transformation_steps += 1;
    }
    for (int k = 0; k < 3; ++k)
      s.acc[static_cast<std::size_t>(k)] = mul8(s.base[k], ambient[k]);
  }

  // World normal (D19): the triangle's unit normal (row 2 of T_delta) through M^T, facing the ray.
  Vec3<F> world_normal(State& t, const memif::InstanceHeader& h, const HitRecord<F>& rec) {
    const auto nrow = t.row(h.triangle_row_base + memif::kTriangleRows * rec.triangle + 2);
    if (rec.instance != normal_instance_) {  // hits of a packet mostly share the instance
      normal_instance_ = rec.instance;
      const Mat34<F> m =
          t.matrix(t.image.registers().instance_row_base + memif::kInstanceRows * rec.instance);
      for (int r = 0; r < 3; ++r)
        normal_m_[r] = {m[0][r], m[1][r], m[2][r], F::zero()};
      normal_mv_ = t.matrix_values(normal_m_);
    }
    count_transform(t, 1);
    Vec3<F> n = t.transform(normal_m_, normal_mv_, Vec3<F>{nrow[0], nrow[1], nrow[2]}, false);
    if (is_pos_nonzero(rec.c))
      for (auto& x : n)
        x = x.neg();
    return n;
  }

  std::uint64_t surface_hit_mask(const State& t) const {
    std::uint64_t m = 0;
    for (int i = 0; i < t.p; ++i)
      if (surf_[static_cast<std::size_t>(i)].hit) m |= std::uint64_t{1} << i;
    return m;
  }

  // Shadow rays of light `light_` through T_shadow = [L, O, D; 0], R' = ((1,0,0), (-1,1,t)).
  void next_light(State& t) {
    const auto& regs = t.image.registers();
    if (light_ >= regs.light_count || surface_hit_mask(t) == 0) return finish_surface(t);
    // The light's record: the RGS's on-chip light table, loaded with the frame (no shading-bank
    // read per packet; docs/shading.md section 9).
    const std::uint32_t a = regs.light_base + memif::kLightWords * light_;
    Vec3<F> pos;
    for (std::uint32_t k = 0; k < 3; ++k)
      pos[k] = F::from_bits(t.image.word(memif::kShadingBank, a + k));
    light_rgb_ = unpack_rgb(t.image.word(memif::kShadingBank, a + 3));
    GenPacket<F>& pk = t.transformation.input();  // built in place, as in start_primary
    pk.kind = RayKind::kShadow;
    pk.depth = t.depth;
    pk.shared_origin = t.params.shared_origin;
    pk.lanes.resize(t.lanes.size());
    for (int i = 0; i < t.p; ++i) {
      const Surface& s = surf_[static_cast<std::size_t>(i)];
      GenLane<F>& g = pk.lanes[static_cast<std::size_t>(i)];
      for (int r = 0; r < 3; ++r)
        g.t[r] = {pos[r], s.ray.o[r], s.ray.d[r], F::zero()};
      g.ro = {F::one(), F::zero(), F::zero()};
      g.rd = {F::one().neg(), F::one(), s.rec.t};
      g.valid = s.hit;
      g.pixel = s.pixel;
      g.weight = 0;
    }
    t.transformation.load(t, pk);
    if (t.params.shadows) return;
    // Without shadow rays only the directions are needed: n direction steps, no origin step.
    t.u.shading_transformation_steps += static_cast<std::uint64_t>(t.p);
    count_transform(t, static_cast<std::uint64_t>(t.p));
    for (int i = 0; i < t.p; i += 2) {  // two lanes at a time (P = 1: the lane with itself)
      const int j = i + 1 < t.p ? i + 1 : i;
      const GenLane<F>& ga = pk.lanes[static_cast<std::size_t>(i)];
      const GenLane<F>& gb = pk.lanes[static_cast<std::size_t>(j)];
      D::direction_steps(t, ga.t, ga.rd, gb.t, gb.rd, t.lane(i).world.d, t.lane(j).world.d);
    }
    shade_light(t);
  }

  // Diffuse and specular of light `light_` for the lit, unoccluded hits.
  void accumulate_light(State& t) {
    for (int i = 0; i < t.p; ++i) {
      Surface& s = surf_[static_cast<std::size_t>(i)];
      if (!s.hit || !s.lit) continue;
      if (t.params.shadows && t.lane(i).hit.hit()) continue;  // occluded
      const std::uint32_t wd = fix8(s.cos);
      for (int k = 0; k < 3; ++k)
        s.acc[static_cast<std::size_t>(k)] += (mul8(s.base[k], light_rgb_[k]) * wd) >> 8;
      if (s.spec && s.highlight) {
        const std::uint32_t p = specular_power(fix8(s.cos_s), s.mat.specular_rgb_shininess >> 24);
        for (int k = 0; k < 3; ++k)
          s.acc[static_cast<std::size_t>(k)] += (mul8(s.spec_rgb[k], light_rgb_[k]) * p) >> 8;
      }
    }
    ++light_;
    next_light(t);
  }

  // The child packets of one shaded packet: reflection, transparency, refraction.
  struct Children {
    std::array<GenPacket<F>*, 3> packet;
    std::array<bool, 3> any{};
  };

  // Local colour into the pixel, then reflection, transparency and refraction children (D37).
  void finish_surface(State& t) {
    if (!t.params.secondary || t.depth >= max_depth_) {
      // No children at this depth (finish_lane then only writes the local colour): no child
      // packets to clear (three lane vectors per packet on the primary-only frame).
      for (int i = 0; i < t.p; ++i) {
        const Surface& s = surf_[static_cast<std::size_t>(i)];
        if (s.hit) local_colour(t, s);
      }
      return next_packet(t);
    }
    // The children are built in the next three pending slots, whose lane vectors are kept from
    // earlier packets (no allocation per packet); the reflection packet is traced first.
    if (pending_.size() < pending_size_ + 3) pending_.resize(pending_size_ + 3);
    Children ch{
        {&pending_[pending_size_ + 2], &pending_[pending_size_ + 1], &pending_[pending_size_]}};
    const RayKind kinds[3] = {RayKind::kReflection, RayKind::kTransparency, RayKind::kRefraction};
    for (int k = 0; k < 3; ++k) {
      GenPacket<F>& pk = *ch.packet[k];
      pk.kind = kinds[k];
      pk.depth = t.depth + 1;
      pk.shared_origin = false;
      pk.lanes.assign(t.lanes.size(), GenLane<F>{});
    }
    for (int i = 0; i < t.p; ++i) {
      const Surface& s = surf_[static_cast<std::size_t>(i)];
      if (s.hit) finish_lane(t, s, static_cast<std::size_t>(i), ch);
    }
    // Keep the packets that have rays, bottom to top: refraction, transparency, reflection.
    const std::size_t first = pending_size_;
    for (int k = 2; k >= 0; --k) {
      if (!ch.any[k]) continue;
      const std::size_t slot = first + static_cast<std::size_t>(2 - k);
      if (slot != pending_size_) std::swap(pending_[slot], pending_[pending_size_]);
      ++pending_size_;
    }
    next_packet(t);
  }

  // One hit's local colour, weighted by what its children take, and its children's lanes. At the
  // depth bound the children's weights are lost (docs/shading.md section 7).
  static void local_colour(State& t, const Surface& s) {
    Rgb8 local{};
    for (int k = 0; k < 3; ++k)
      local[k] = std::min<std::uint32_t>(255u, s.acc[k]);
    const std::uint32_t kr = s.mat.reflectivity, kt = s.mat.transparency;
    const std::uint32_t kf = s.mat.refraction;
    const std::uint32_t wl =
        t.params.secondary ? mul8(s.weight, 255u - std::min(255u, kr + kt + kf)) : s.weight;
    add_colour(t, s.pixel, wl, local);
  }
  void finish_lane(State& t, const Surface& s, std::size_t i, Children& ch) {
    local_colour(t, s);
    if (!t.params.secondary || t.depth >= max_depth_) return;
    const std::uint32_t kr = s.mat.reflectivity, kt = s.mat.transparency;
    const std::uint32_t kf = s.mat.refraction;
    std::uint32_t wr = mul8(s.weight, kr);
    const std::uint32_t wt = mul8(s.weight, kt), wf = mul8(s.weight, kf);
    const Mat34<F> tr = reflect_matrix(s.ray, s.n);
    F kk = s.kk;
    if (wf > 0) {
      const Refracted r = refract(t, s);
      if (r.total) {
        // Total internal reflection: the refracted share is reflected, on the reflection ray.
        wr = std::min(255u, wr + wf);
        if (kr == 0 && !s.spec) kk = twice_quotient(t, r.nd, s.nn);  // not made by surface()
      } else {
        ch.packet[2]->lanes[i] = {
            true, s.pixel, wf, tr, {s.rec.t, F::zero(), epsilon_}, {r.eta, r.mu, F::zero()}};
        ch.any[2] = true;
      }
    }
    if (wr > 0) {
      ch.packet[0]->lanes[i] = {true,
                                s.pixel,
                                wr,
                                tr,
                                {epsilon_.neg(), F::zero(), s.rec.t},
                                {F::one(), kk.neg(), F::zero()}};
      ch.any[0] = true;
    }
    if (wt > 0) {
      ch.packet[1]->lanes[i] = {
          true, s.pixel, wt, tr, {epsilon_, F::zero(), s.rec.t}, {F::one(), F::zero(), F::zero()}};
      ch.any[1] = true;
    }
  }

  // The refraction factor of one hit (docs/shading.md, the sign of D12): N.D and D.D on the
  // transformation unit (one step: rows N and D on D), mu on the RGS FP helper. eta is the
  // material's ratio for the side the ray comes from: the back of a triangle (D'z > 0, the
  // normal was turned to face the ray) is inside the material.
  struct Refracted {
    F eta{}, nd{}, mu{};
    bool total = false;
  };
  static Refracted refract(State& t, const Surface& s) {
    Refracted r;
    r.eta = F::from_bits(is_pos_nonzero(s.rec.c) ? s.mat.eta_leave : s.mat.eta_enter);
    r.nd = shade_dot(t, s.n, s.ray.d);
    const F dd = shade_dot(t, s.ray.d, s.ray.d);
    t.u.shading_transformation_steps += 1;
    PipelineUnits<F>::count(t.u.rgs_ops, 3, 5, 1, 0);
    ++t.u.rgs_ops.sqrt;
    const RefractionFactor<F> f = refraction_factor(t.u.raw, r.eta, r.nd, dd, s.nn);
    r.mu = f.mu;
    r.total = f.total;
    return r;
  }

  // The next child packet (last in, first out), or the thread is done.
  void next_packet(State& t) {
    if (pending_size_ == 0) {
      write_pixels(t);
      t.phase = Phase::kDone;
      return;
    }
    --pending_size_;
    t.transformation.load(t, pending_[pending_size_]);  // copied: the slot may be rebuilt
  }

  // ---- the RGS's memory accesses ---------------------------------------------------------------
  // A read of `words` shading-bank words from `offset`, in requests of at most kMaxRequestWords.
  void read(std::uint32_t offset, std::uint32_t words, std::uint8_t wave) {
    constexpr auto kMax = static_cast<std::uint32_t>(memif::kMaxRequestWords);
    for (std::uint32_t w = 0; w < words; w += kMax) {
      RgsAccess a;
      a.offset = offset + w;
      a.words = static_cast<std::uint8_t>(std::min(kMax, words - w));
      a.wave = wave;
      mem_.push_back(a);
    }
  }
  // The finished primary packet's pixels, one word each, into the back frame-buffer bank
  // (FrameRegisters::frame_bank): every ray of the packet, children included, has returned.
  void write_pixels(const State& t) {
    const auto bank = static_cast<std::uint8_t>(t.image.registers().frame_bank);
    for (std::uint32_t px : pixels_) {
      if (px == memif::kNone) continue;
      RgsAccess a;
      a.bank = bank;
      a.offset = px;
      a.data = pixel_word(t.sink.colour_sum[px]);
      a.write = true;
      mem_.push_back(a);
    }
  }

  std::uint32_t max_depth_ = 3;
  F epsilon_{};
  std::vector<RgsAccess> mem_;             // the accesses of the request executing
  std::vector<std::uint32_t> pixels_;      // the primary packet's pixels (kNone: empty lane)
  std::uint32_t material_ = memif::kNone;  // the material read last in this shading pass
  memif::MaterialRecord material_record_;  // its record, decoded once per read
  std::vector<Surface> surf_;
  std::uint32_t light_ = 0;
  Rgb8 light_rgb_{};
  // Child packets still to trace (a LIFO of pending_size_ entries); slots beyond it keep their
  // lane vectors for reuse.
  std::vector<GenPacket<F>> pending_;
  std::size_t pending_size_ = 0;
  // M^T (zero translation) of the instance whose normals the RGS transformed last, and its values;
  // kNone: none yet in this primary packet's tree (the image may change between frames).
  std::uint32_t normal_instance_ = memif::kNone;
  Mat34<F> normal_m_{};
  Mat64 normal_mv_{};
};

}  // namespace saarcor::units
