// An independent ray tracer for checking the float reference (docs/compare.md: model 1 is
// checked against Intel Embree on the same triangles). Header-only on purpose: host/ library code
// must not depend on Embree, so only tests and benchmarks (which link the `embree` target)
// include this file.
//
// The scene is flattened into world space (each instance's triangles transformed object -> world
// in binary64, then rounded to binary32), one Embree geometry per instance, leaving out the
// triangles the image dropped (degenerate: no T_delta). For scenes too large to flatten, the
// instanced mode gives Embree one object geometry per object and one instance geometry per
// instance (Embree then transforms the ray itself).
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/float_reference.h"
#include "host/image_builder.h"
#include "host/scene.h"

namespace saarcor::host {

struct EmbreeHit {
  bool hit = false;
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f;  // Embree's barycentrics: point = (1-u-v)*A + u*B + v*C
  float v = 0.0f;
  std::uint32_t instance = kFloatNoHit;  // index into Scene::instances
  std::uint32_t triangle = kFloatNoHit;  // index within the object's mesh
  // Distance of the hit to the triangle's nearest edge in barycentric units.
  float edge_distance() const {
    const float w = 1.0f - u - v;
    return u < v ? (u < w ? u : w) : (v < w ? v : w);
  }
};

class EmbreeOracle {
 public:
  enum class Mode { kFlattened, kInstanced };

  // `image` decides which triangle slots exist (ObjectInfo::t_delta engaged). `threads` is the
  // build thread count (tracing is single-ray on the caller's thread). high_quality: Embree's
  // high-quality BVH build (benchmarks: the fastest tracing Embree offers).
  EmbreeOracle(const Scene& scene, const BuiltImage& image, Mode mode = Mode::kFlattened,
               int threads = 1, bool high_quality = false) {
    const std::string config = "threads=" + std::to_string(threads);
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw std::runtime_error("embree: rtcNewDevice failed");
    rtcSetDeviceErrorFunction(device_, &EmbreeOracle::on_error, this);
    scene_ = rtcNewScene(device_);
    if (high_quality) rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    if (image.objects.size() != scene.objects.size() ||
        image.instances.size() != scene.instances.size())
      throw std::runtime_error("embree oracle: image and scene differ in objects or instances");
    if (mode == Mode::kFlattened) {
      for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        add_mesh(scene_, scene.objects[inst.object], image.objects[inst.object],
                 inst.object_to_world, static_cast<std::uint32_t>(i));
      }
    } else {
      std::vector<RTCScene> object_scenes(scene.objects.size(), nullptr);
      for (std::size_t o = 0; o < scene.objects.size(); ++o) {
        object_scenes[o] = rtcNewScene(device_);
        if (high_quality) rtcSetSceneBuildQuality(object_scenes[o], RTC_BUILD_QUALITY_HIGH);
        add_mesh(object_scenes[o], scene.objects[o], image.objects[o], glm::dmat4(1.0), 0);
        rtcCommitScene(object_scenes[o]);
        owned_.push_back(object_scenes[o]);
      }
      for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        instance_object_.push_back(inst.object);
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, object_scenes[inst.object]);
        float xf[12];  // column-major 3x4
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 3; ++r)
            xf[c * 3 + r] = static_cast<float>(inst.object_to_world[c][r]);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xf);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene_, g, static_cast<unsigned>(i));
        rtcReleaseGeometry(g);
      }
      instanced_ = true;
    }
    rtcCommitScene(scene_);
    check("scene build");
  }
  ~EmbreeOracle() {
    if (scene_) rtcReleaseScene(scene_);
    for (RTCScene s : owned_)
      rtcReleaseScene(s);
    if (device_) rtcReleaseDevice(device_);
  }
  EmbreeOracle(const EmbreeOracle&) = delete;
  EmbreeOracle& operator=(const EmbreeOracle&) = delete;

  std::uint64_t triangles() const { return triangles_; }

  EmbreeHit intersect(const FloatRay& ray, float t_min = 0.0f,
                      float t_max = std::numeric_limits<float>::infinity()) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray.org_x = ray.origin.x;
    rh.ray.org_y = ray.origin.y;
    rh.ray.org_z = ray.origin.z;
    rh.ray.dir_x = ray.direction.x;
    rh.ray.dir_y = ray.direction.y;
    rh.ray.dir_z = ray.direction.z;
    rh.ray.tnear = t_min;
    rh.ray.tfar = t_max;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    EmbreeHit h;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
    h.hit = true;
    h.t = rh.ray.tfar;
    h.u = rh.hit.u;
    h.v = rh.hit.v;
    if (instanced_) {
      h.instance = rh.hit.instID[0];
      h.triangle = prim_to_triangle_[object_geometry_index(h.instance)][rh.hit.primID];
    } else {
      h.instance = rh.hit.geomID;
      h.triangle = prim_to_triangle_[rh.hit.geomID][rh.hit.primID];
    }
    return h;
  }

 private:
  static void on_error(void* self, RTCError code, const char* message) {
    // Never throw through Embree's C callback: remember and throw at the next check.
    auto* o = static_cast<EmbreeOracle*>(self);
    if (o->error_.empty())
      o->error_ = "embree error " + std::to_string(static_cast<int>(code)) + ": " +
                  (message ? message : "");
  }
  void check(const char* what) {
    if (!error_.empty())
      throw std::runtime_error(std::string("embree oracle: ") + what + ": " + error_);
  }
  std::size_t object_geometry_index(std::uint32_t instance) const {
    return instance_object_.at(instance);
  }

  void add_mesh(RTCScene target, const Object& object, const ObjectInfo& info,
                const glm::dmat4& to_world, std::uint32_t geom_id) {
    std::vector<std::uint32_t> map;
    for (std::uint32_t k = 0; k < object.triangles.size(); ++k)
      if (k < info.t_delta.size() && info.t_delta[k]) map.push_back(k);
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * map.size()));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), map.size()));
    check("buffers");
    for (std::size_t j = 0; j < map.size(); ++j) {
      const glm::uvec3 tri = object.triangles[map[j]];
      for (int c = 0; c < 3; ++c) {
        const glm::dvec4 p = to_world * glm::dvec4(glm::dvec3(object.positions[tri[c]]), 1.0);
        for (int a = 0; a < 3; ++a)
          vb[9 * j + 3 * static_cast<std::size_t>(c) + static_cast<std::size_t>(a)] =
              static_cast<float>(p[a]);
        ib[3 * j + static_cast<std::size_t>(c)] =
            static_cast<unsigned>(3 * j + static_cast<std::size_t>(c));
      }
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(target, g, geom_id);
    rtcReleaseGeometry(g);
    check("geometry");
    triangles_ += map.size();
    if (target == scene_) {
      if (prim_to_triangle_.size() <= geom_id) prim_to_triangle_.resize(geom_id + 1);
      prim_to_triangle_[geom_id] = std::move(map);
    } else {
      prim_to_triangle_.push_back(std::move(map));  // instanced: one per object, in order
    }
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<RTCScene> owned_;
  bool instanced_ = false;
  std::vector<std::vector<std::uint32_t>> prim_to_triangle_;  // per geometry (or object)
  std::vector<std::size_t> instance_object_;                  // instanced: object of instance
  std::uint64_t triangles_ = 0;
  std::string error_;
};

// ---- comparing the float reference with Embree (test and benchmark helpers) ---------------------

// How the float reference's primary rays agree with Embree's on the same rays.
struct EmbreeAgreement {
  int rays = 0;
  int both_miss = 0;
  int same = 0;          // both hit the same (instance, triangle)
  int edge_ignored = 0;  // disagree, and one of the hits lies within the tolerance of an edge
  int mismatches = 0;
  double t_rel_err_max = 0.0;  // over the rays with the same triangle
  int t_rel_err_max_pixel = -1;
  int t_rel_err_over_1e5 = 0;  // rays with the same triangle and a relative t error above 1e-5
  int first_mismatch = -1;     // pixel index
  int hits() const { return rays - both_miss; }
  // Share of the rays that count (all but the edge cases) where both agree (hit or miss).
  double same_pct() const {
    const int counted = rays - edge_ignored;
    return counted == 0 ? 100.0 : 100.0 * (same + both_miss) / counted;
  }
};

inline float float_edge_distance(const FloatHit& h) {
  return std::min({h.u, h.v, 1.0f - h.u - h.v});
}

// Edge cases: a disagreement where Embree's hit or the float reference's lies within
// `edge_tolerance` (barycentric) of its triangle's edge: a ray through a shared or silhouette
// edge falls either way within rounding.
inline EmbreeAgreement compare_with_embree(const FloatFrame& frame, const EmbreeOracle& embree,
                                           float edge_tolerance = 1e-4f) {
  EmbreeAgreement a;
  for (std::size_t i = 0; i < frame.pixels.size(); ++i) {
    const FloatPixel& px = frame.pixels[i];
    const EmbreeHit e = embree.intersect(px.ray);
    ++a.rays;
    if (!e.hit && !px.hit.hit()) {
      ++a.both_miss;
      continue;
    }
    if (e.hit && px.hit.hit() && e.instance == px.hit.instance && e.triangle == px.hit.triangle) {
      ++a.same;
      const double err = std::abs(double(px.hit.t) - double(e.t)) / double(e.t);
      if (err > 1e-5) ++a.t_rel_err_over_1e5;
      if (err > a.t_rel_err_max) {
        a.t_rel_err_max = err;
        a.t_rel_err_max_pixel = static_cast<int>(i);
      }
      continue;
    }
    const bool embree_edge = e.hit && e.edge_distance() < edge_tolerance;
    const bool float_edge = px.hit.hit() && float_edge_distance(px.hit) < edge_tolerance;
    if (embree_edge || float_edge) {
      ++a.edge_ignored;
      continue;
    }
    if (a.first_mismatch < 0) a.first_mismatch = static_cast<int>(i);
    ++a.mismatches;
  }
  return a;
}

// The image at the prototype's bank size, or at a larger one when the scene does not fit (the
// comparison checks geometry, not capacity).
inline BuiltImage build_fitting_image(const Scene& scene, int width, int height) {
  ImageParams ip;
  ip.width = width;
  ip.height = height;
  for (std::uint32_t words = ip.bank_words;; words *= 4) {
    ip.bank_words = words;
    try {
      return build_image(scene, ip);
    } catch (const std::runtime_error& e) {
      if (std::string(e.what()).find("does not fit") == std::string::npos || words >= (1u << 24))
        throw;
    }
  }
}

}  // namespace saarcor::host
