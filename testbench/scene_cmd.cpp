// `saarcor scene`: loads a scene (glTF or built-in), evaluates it at a time, optionally exports it,
// builds the memory image (both kd-tree levels, docs/memory-image.md) and reports counts, tree
// statistics, build times and bytes per bank (README "Command line").
#include "testbench/scene_cmd.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "host/gltf_export.h"
#include "host/image_builder.h"
#include "host/kdtree.h"
#include "host/scene.h"
#include "host/tree_objective.h"
#include "host/tree_settings.h"
#include "memif/image_file.h"
#include "testbench/report.h"

namespace saarcor {

namespace {

using host::KdTreeStats;
using nlohmann::json;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The trees without a memory image (used when the image does not fit its banks): the same
// builder and parameters the image builder uses (its depth budget and top-level item cost).
SceneTrees build_trees_directly(const host::Scene& scene, const host::ImageParams& params) {
  SceneTrees t;
  std::vector<std::uint8_t> used(scene.objects.size(), 0);
  for (const host::Instance& i : scene.instances)
    used.at(i.object) = 1;
  std::vector<host::Aabb> local(scene.objects.size());
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const host::Object& obj = scene.objects[o];
    for (std::size_t k = 0; k < obj.triangles.size(); ++k) {
      if (obj.degenerate[k]) continue;
      for (int v = 0; v < 3; ++v)
        local[o].grow(obj.positions[obj.triangles[k][v]]);
    }
    if (!used[o]) continue;
    host::KdBuildParams kd = params.kd;
    std::size_t live = 0;
    for (std::size_t k = 0; k < obj.triangles.size(); ++k)
      live += obj.degenerate[k] ? 0 : 1;
    kd.max_depth = host::bottom_level_depth(params, live, scene.instances.size());
    const host::KdTree tree = host::build_kdtree_for_units(
        obj.positions, obj.triangles, obj.degenerate, kd,
        static_cast<host::KdObjective>(params.tree_objective), params.tree_objective_ratio);
    t.bottom.emplace_back(static_cast<std::uint32_t>(o), tree.stats);
  }
  std::vector<host::Aabb> boxes;
  for (const host::Instance& inst : scene.instances) {
    const host::Aabb& b = local[inst.object];
    host::Aabb w;
    if (!b.empty()) {
      for (int c = 0; c < 8; ++c) {
        const glm::dvec4 p((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y,
                           (c & 4) ? b.hi.z : b.lo.z, 1.0);
        w.grow(glm::vec3(glm::dvec3(inst.object_to_world * p)));
      }
    }
    boxes.push_back(w);
  }
  host::KdBuildParams top = params.kd;
  top.intersection_cost *= params.top_item_cost_factor;
  top.max_depth = host::top_level_depth(params, scene.instances.size());
  t.top = host::build_kdtree(boxes, top).stats;
  return t;
}

void check_scene_options(const SceneOptions& options) {
  if (!(options.bank_mb > 0.0) || options.bank_mb > 16384.0)
    throw std::runtime_error("--bank-mb must be in (0, 16384], got " +
                             std::to_string(options.bank_mb));
  if (!std::isfinite(options.time) || options.time < 0.0)
    throw std::runtime_error("--time must be a finite number >= 0, got " +
                             std::to_string(options.time));
}

SceneImage build_scene_image(const host::Scene& scene, const SceneOptions& options) {
  SceneImage img;
  const auto t1 = std::chrono::steady_clock::now();
  img.params.bank_words = static_cast<std::uint32_t>(std::llround(options.bank_mb * 262144.0));
  for (const std::string& kv : options.set)
    host::apply_tree_setting(img.params, kv);
  try {
    img.built = host::build_image(scene, img.params);
  } catch (const std::runtime_error& e) {
    img.error = e.what();
  }
  if (img.built) {
    const host::BuiltImage& built = *img.built;
    img.trees.top = built.top.stats;
    for (std::size_t o = 0; o < built.objects.size(); ++o)
      if (built.objects[o].stored)
        img.trees.bottom.emplace_back(static_cast<std::uint32_t>(o), built.objects[o].tree.stats);
  } else {
    img.trees = build_trees_directly(scene, img.params);
  }
  img.seconds = seconds_since(t1);
  return img;
}

void print_scene_counts(const SceneOptions& options, const host::Scene& scene,
                        double load_seconds) {
  std::printf("scene               %s (t = %.3f s)\n", options.scene.c_str(), scene.time);
  std::printf("triangles           %llu after instancing, %llu unique\n",
              static_cast<unsigned long long>(scene.instanced_triangles()),
              static_cast<unsigned long long>(scene.unique_triangles()));
  std::printf("dropped triangles   %llu unique (degenerate), %llu after instancing\n",
              static_cast<unsigned long long>(scene.dropped_triangles()),
              static_cast<unsigned long long>(scene.instanced_dropped_triangles()));
  std::printf("skipped primitives  %llu\n",
              static_cast<unsigned long long>(scene.skipped_primitives));
  std::printf("objects             %zu\n", scene.objects.size());
  std::printf("instances           %zu (%llu dynamic)\n", scene.instances.size(),
              static_cast<unsigned long long>(dynamic_instances(scene)));
  std::printf("materials/textures  %zu / %zu\n", scene.materials.size(), scene.textures.size());
  std::printf("lights              %zu%s\n", scene.lights.size(),
              scene.light_defaulted ? " (default light)" : "");
  // The cameras by index, the values --set image.camera takes (the first eight).
  std::string views;
  for (std::size_t c = 0; c < scene.cameras.size() && c < 8; ++c) {
    views += (c == 0 ? ": " : ", ") + std::to_string(c) + " " + scene.cameras[c].name;
  }
  if (scene.cameras.size() > 8) {
    views += ", ...";
  }
  std::printf("cameras             %zu%s\n", scene.cameras.size(),
              scene.cameras.empty() ? " (default framing)" : views.c_str());
  std::printf("animation           %.3f s\n", scene.animation_seconds);
  std::printf("load time           %.3f s\n", load_seconds);
}

void print_tree_line(const char* name, const KdTreeStats& s) {
  std::printf(
      "%-19s %u nodes, %u leaves (%u empty), %u chain links (%u mergeable), depth %u, %.2f "
      "items/leaf, SAH %.2f, per ray %.2f steps / %.2f leaves / %.2f tests, %.3f s\n",
      name, s.nodes, s.leaves, s.empty_leaves, s.empty_chain_links, s.mergeable_chain_links,
      s.depth, s.items_per_leaf, s.sah_cost, s.expected_traversal_steps, s.expected_leaf_visits,
      s.expected_item_tests, s.build_seconds);
}

// Every tree's expectations, largest first (all of them in --json).
void print_object_trees(const json& b) {
  std::vector<json> objs(b["objects"].begin(), b["objects"].end());
  std::stable_sort(objs.begin(), objs.end(), [](const json& x, const json& y) {
    return x["triangles"].get<std::uint64_t>() > y["triangles"].get<std::uint64_t>();
  });
  constexpr std::size_t kShown = 8;
  for (std::size_t i = 0; i < objs.size() && i < kShown; ++i) {
    const json& o = objs[i];
    std::printf(
        "  object %-10u %llu triangles, %.2f nodes per triangle, %llu chain links (%llu "
        "mergeable), depth %u, per ray %.2f steps / %.2f leaves / %.2f tests; K_T %.3g, cycles per "
        "packet trav/list/xfrm/int %.1f/%.1f/%.1f/%.1f\n",
        o["object"].get<unsigned>(), o["triangles"].get<unsigned long long>(),
        o["nodes_per_triangle"].get<double>(), o["empty_chain_links"].get<unsigned long long>(),
        o["mergeable_chain_links"].get<unsigned long long>(), o["depth"].get<unsigned>(),
        o["expected_traversal_steps"].get<double>(), o["expected_leaf_visits"].get<double>(),
        o["expected_item_tests"].get<double>(), o["traversal_cost"].get<double>(),
        o["expected_unit_cycles"]["traversal"].get<double>(),
        o["expected_unit_cycles"]["list"].get<double>(),
        o["expected_unit_cycles"]["transformation"].get<double>(),
        o["expected_unit_cycles"]["intersection"].get<double>());
  }
  if (objs.size() > kShown)
    std::printf("  (%zu smaller trees: --json lists every tree)\n", objs.size() - kShown);
}

void print_trees(const SceneTrees& trees, const json& j) {
  print_tree_line("kd-tree top", trees.top);
  const json b = j["kdtree"]["bottom"];
  std::printf(
      "kd-tree bottom      %zu trees, %llu nodes (%.2f per triangle), %llu leaves (%llu empty), "
      "%llu chain links (%llu mergeable), max depth %u, %.2f items/leaf, %.3f s\n",
      trees.bottom.size(), b["nodes"].get<unsigned long long>(),
      b["nodes_per_triangle"].get<double>(), b["leaves"].get<unsigned long long>(),
      b["empty_leaves"].get<unsigned long long>(), b["empty_chain_links"].get<unsigned long long>(),
      b["mergeable_chain_links"].get<unsigned long long>(), b["max_depth"].get<unsigned>(),
      b["items_per_leaf"].get<double>(), b["build_seconds"].get<double>());
  print_object_trees(b);
}

void print_image(const SceneImage& img) {
  if (img.built) {
    std::printf("bytes per bank     ");
    for (std::uint64_t v : img.built->stats.bytes_per_bank)
      std::printf(" %llu", static_cast<unsigned long long>(v));
    std::printf("  (of %llu each)\n",
                static_cast<unsigned long long>(img.params.bank_words) * 4ull);
    std::printf("image build         %.3f s\n", img.seconds);
  } else {
    std::printf("memory image        does not build: %s\n", img.error.c_str());
  }
}

}  // namespace

std::uint64_t dynamic_instances(const host::Scene& scene) {
  std::uint64_t dynamic = 0;
  for (const host::Instance& i : scene.instances)
    dynamic += i.dynamic ? 1 : 0;
  return dynamic;
}

int run_scene(const SceneOptions& options) {
  check_scene_options(options);
  const auto t0 = std::chrono::steady_clock::now();
  host::Scene scene = host::load_scene(options.scene);
  const double load_seconds = seconds_since(t0);
  if (options.time != 0.0) scene.set_time(options.time);
  if (!options.export_path.empty()) host::export_gltf(scene, options.export_path);

  const SceneImage img = build_scene_image(scene, options);
  if (!options.image_path.empty()) {
    if (!img.built)
      throw std::runtime_error("--write-image: the memory image does not build: " + img.error);
    memif::write_image_file(img.built->image, options.image_path);
  }
  const json j = scene_report_json(options, scene, load_seconds, img);
  if (options.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  print_scene_counts(options, scene, load_seconds);
  print_trees(img.trees, j);
  print_image(img);
  for (const std::string& w : scene.warnings)
    std::printf("warning             %s\n", w.c_str());
  if (!options.export_path.empty())
    std::printf("exported            %s\n", options.export_path.c_str());
  if (!options.image_path.empty())
    std::printf("image file          %s\n", options.image_path.c_str());
  return 0;
}

}  // namespace saarcor
