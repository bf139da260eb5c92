// Scene -> glTF 2.0 (README.md "Layout": host/ owns scene files). Instances become nodes that
// share one mesh per object, so an instanced scene (paper section 5, SunCOR) stays small on disk.
#include "host/gltf_export.h"

#include <tiny_gltf.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace saarcor::host {

namespace {

class ModelWriter {
 public:
  ModelWriter() { model_.buffers.emplace_back(); }

  // Appends raw bytes (4-byte aligned) as a new buffer view; returns its index.
  int view(const void* data, std::size_t size, int target) {
    auto& buf = model_.buffers[0].data;
    while (buf.size() % 4 != 0)
      buf.push_back(0);
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = buf.size();
    bv.byteLength = size;
    bv.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + size);
    model_.bufferViews.push_back(bv);
    return static_cast<int>(model_.bufferViews.size() - 1);
  }

  int accessor(const void* data, std::size_t count, int type, int component_type, int target,
               std::vector<double> min = {}, std::vector<double> max = {}) {
    const std::size_t bytes =
        count *
        static_cast<std::size_t>(
            tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(type))) *
        static_cast<std::size_t>(
            tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(component_type)));
    tinygltf::Accessor acc;
    acc.bufferView = view(data, bytes, target);
    acc.byteOffset = 0;
    acc.count = count;
    acc.type = type;
    acc.componentType = component_type;
    acc.minValues = std::move(min);
    acc.maxValues = std::move(max);
    model_.accessors.push_back(acc);
    return static_cast<int>(model_.accessors.size() - 1);
  }

  tinygltf::Model& model() { return model_; }

 private:
  tinygltf::Model model_;
};

void write_file_atomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".partial";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error(path + ": cannot write");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.close();
    if (!f) {
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write (" + ec.message() + ")");
  }
}

std::vector<double> node_matrix(const glm::dmat4& m) {
  std::vector<double> v(16);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      v[static_cast<std::size_t>(c * 4 + r)] = m[c][r];
  return v;
}

// A node placing a camera (or light) whose world frame is given by position/forward/up.
glm::dmat4 frame_matrix(const glm::vec3& position, const glm::vec3& forward, const glm::vec3& up) {
  const glm::dvec3 f = glm::normalize(glm::dvec3(forward));
  const glm::dvec3 u = glm::normalize(glm::dvec3(up));
  const glm::dvec3 r = glm::cross(f, u);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(r, 0.0);
  m[1] = glm::dvec4(u, 0.0);
  m[2] = glm::dvec4(-f, 0.0);  // glTF cameras look down their local -Z
  m[3] = glm::dvec4(glm::dvec3(position), 1.0);
  return m;
}

}  // namespace

std::vector<unsigned char> encode_png(const Texture& texture) {
  using namespace OIIO;
  std::vector<unsigned char> out;
  Filesystem::IOVecOutput vec(out);
  auto png = ImageOutput::create("texture.png", &vec);
  if (!png) throw std::runtime_error("cannot encode PNG: " + OIIO::geterror());
  ImageSpec spec(texture.width, texture.height, 4, TypeDesc::UINT8);
  std::vector<unsigned char> pix(texture.rgba.size() * 4);
  for (std::size_t i = 0; i < texture.rgba.size(); ++i)
    for (int c = 0; c < 4; ++c)
      pix[i * 4 + static_cast<std::size_t>(c)] =
          static_cast<unsigned char>(texture.rgba[i] >> (8 * c));
  if (!png->open("texture.png", spec) || !png->write_image(TypeDesc::UINT8, pix.data()) ||
      !png->close())
    throw std::runtime_error("cannot encode PNG for texture '" + texture.name +
                             "': " + png->geterror());
  return out;
}

void export_gltf(const Scene& scene, const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  const bool binary = ext == ".glb" || ext == ".GLB";
  ModelWriter w;
  tinygltf::Model& model = w.model();
  model.asset.version = "2.0";
  model.asset.generator = "saarcor-model";

  // Textures: PNG images inside the buffer, one sampler (repeat, bilinear).
  if (!scene.textures.empty()) {
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;
    sampler.wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT;
    model.samplers.push_back(sampler);
  }
  for (std::size_t t = 0; t < scene.textures.size(); ++t) {
    const std::vector<unsigned char> png = encode_png(scene.textures[t]);
    tinygltf::Image img;
    img.name = scene.textures[t].name;
    img.mimeType = "image/png";
    img.bufferView = w.view(png.data(), png.size(), 0);
    model.images.push_back(img);
    tinygltf::Texture tex;
    tex.sampler = 0;
    tex.source = static_cast<int>(t);
    model.textures.push_back(tex);
  }
  bool transmission_used = false, ior_used = false;
  for (const Material& m : scene.materials) {
    tinygltf::Material gm;
    gm.name = m.name;
    gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.r, m.base_color.g, m.base_color.b,
                                               m.base_color.a};
    gm.pbrMetallicRoughness.metallicFactor = m.metallic;
    gm.pbrMetallicRoughness.roughnessFactor = m.roughness;
    gm.pbrMetallicRoughness.baseColorTexture.index = m.texture;
    if (m.transparency > 0.0f) gm.alphaMode = "BLEND";
    gm.doubleSided = true;  // the hardware has no backface culling (decision D13)
    // Glass (docs/scenes.md "Materials"): the inputs the loader derives the refraction weight from.
    if (m.transmission > 0.0f) {
      tinygltf::Value::Object t;
      t["transmissionFactor"] = tinygltf::Value(static_cast<double>(m.transmission));
      gm.extensions["KHR_materials_transmission"] = tinygltf::Value(t);
      transmission_used = true;
    }
    if (m.ior != 1.5f) {
      tinygltf::Value::Object i;
      i["ior"] = tinygltf::Value(static_cast<double>(m.ior));
      gm.extensions["KHR_materials_ior"] = tinygltf::Value(i);
      ior_used = true;
    }
    model.materials.push_back(gm);
  }
  if (transmission_used) model.extensionsUsed.push_back("KHR_materials_transmission");
  if (ior_used) model.extensionsUsed.push_back("KHR_materials_ior");

  for (const Object& o : scene.objects) {
    tinygltf::Mesh mesh;
    mesh.name = o.name;
    std::vector<double> lo(3, 0.0), hi(3, 0.0);
    if (!o.positions.empty()) {
      glm::vec3 a = o.positions[0], b = o.positions[0];
      for (const glm::vec3& p : o.positions) {
        a = glm::min(a, p);
        b = glm::max(b, p);
      }
      lo = {a.x, a.y, a.z};
      hi = {b.x, b.y, b.z};
    }
    const std::size_t nv = std::max<std::size_t>(o.positions.size(), 1);
    std::vector<glm::vec3> pos = o.positions;
    if (pos.empty()) pos.emplace_back(0.0f);
    const int pos_acc =
        w.accessor(pos.data(), nv, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                   TINYGLTF_TARGET_ARRAY_BUFFER, lo, hi);
    int nrm_acc = -1, uv_acc = -1;
    if (!o.normals.empty())
      nrm_acc = w.accessor(o.normals.data(), o.normals.size(), TINYGLTF_TYPE_VEC3,
                           TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!o.texcoords.empty())
      uv_acc = w.accessor(o.texcoords.data(), o.texcoords.size(), TINYGLTF_TYPE_VEC2,
                          TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    // One primitive per run of equal material; all share the vertex accessors.
    std::size_t begin = 0;
    while (begin < o.triangles.size()) {
      std::size_t end = begin + 1;
      while (end < o.triangles.size() && o.material[end] == o.material[begin])
        ++end;
      std::vector<std::uint32_t> idx;
      idx.reserve((end - begin) * 3);
      for (std::size_t t = begin; t < end; ++t)
        for (int k = 0; k < 3; ++k)
          idx.push_back(o.triangles[t][k]);
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      prim.attributes["POSITION"] = pos_acc;
      if (nrm_acc >= 0) prim.attributes["NORMAL"] = nrm_acc;
      if (uv_acc >= 0) prim.attributes["TEXCOORD_0"] = uv_acc;
      prim.material = static_cast<int>(o.material[begin]);
      prim.indices =
          w.accessor(idx.data(), idx.size(), TINYGLTF_TYPE_SCALAR,
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      mesh.primitives.push_back(prim);
      begin = end;
    }
    if (mesh.primitives.empty()) {
      // glTF requires a primitive: an object without triangles keeps its slot as points.
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_POINTS;
      prim.attributes["POSITION"] = pos_acc;
      mesh.primitives.push_back(prim);
    }
    model.meshes.push_back(mesh);
  }

  // Nodes keep their indices, so instance ids survive a round trip.
  for (const Node& n : scene.nodes) {
    tinygltf::Node gn;
    gn.name = n.name;
    gn.mesh = n.object;
    gn.children = n.children;
    if (!n.use_trs) {
      if (n.matrix != glm::dmat4(1.0)) gn.matrix = node_matrix(n.matrix);
    } else {
      if (n.translation != glm::dvec3(0.0))
        gn.translation = {n.translation.x, n.translation.y, n.translation.z};
      if (n.rotation != glm::dquat(1.0, 0.0, 0.0, 0.0))
        gn.rotation = {n.rotation.x, n.rotation.y, n.rotation.z, n.rotation.w};
      if (n.scale != glm::dvec3(1.0)) gn.scale = {n.scale.x, n.scale.y, n.scale.z};
    }
    model.nodes.push_back(gn);
  }
  tinygltf::Scene gs;
  gs.name = scene.source;
  gs.nodes = scene.roots;
  for (std::size_t c = 0; c < scene.cameras.size(); ++c) {
    const Camera& cam = scene.cameras[c];
    tinygltf::Camera gc;
    gc.type = "perspective";
    gc.name = cam.name;
    gc.perspective.yfov = cam.yfov;
    gc.perspective.znear = 0.01;
    gc.perspective.zfar = 1.0e6;
    model.cameras.push_back(gc);
    const int ci = static_cast<int>(model.cameras.size() - 1);
    if (cam.node >= 0) {
      model.nodes[static_cast<std::size_t>(cam.node)].camera = ci;
    } else {
      tinygltf::Node gn;
      gn.name = cam.name;
      gn.camera = ci;
      gn.matrix = node_matrix(frame_matrix(cam.position, cam.forward, cam.up));
      model.nodes.push_back(gn);
      gs.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
    }
  }
  if (!scene.light_defaulted) {
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      const Light& light = scene.lights[l];
      tinygltf::Light gl;
      gl.type = "point";
      gl.color = {light.color.r, light.color.g, light.color.b};
      gl.intensity = 1.0;
      model.lights.push_back(gl);
      tinygltf::Value::Object ext;
      ext["light"] = tinygltf::Value(static_cast<int>(model.lights.size() - 1));
      if (light.node >= 0) {
        model.nodes[static_cast<std::size_t>(light.node)].extensions["KHR_lights_punctual"] =
            tinygltf::Value(ext);
      } else {
        tinygltf::Node gn;
        gn.name = "light" + std::to_string(l);
        gn.translation = {light.position.x, light.position.y, light.position.z};
        gn.extensions["KHR_lights_punctual"] = tinygltf::Value(ext);
        model.nodes.push_back(gn);
        gs.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
      }
    }
    if (!model.lights.empty()) model.extensionsUsed.push_back("KHR_lights_punctual");
  }
  model.scenes.push_back(gs);
  model.defaultScene = 0;

  if (!scene.animations.empty()) {
    tinygltf::Animation anim;
    anim.name = "animation";
    for (const AnimChannel& ch : scene.animations) {
      std::vector<float> times(ch.times.begin(), ch.times.end());
      const bool rot = ch.path == AnimPath::kRotation;
      std::vector<float> values;
      for (const glm::dvec4& v : ch.values) {
        values.push_back(static_cast<float>(v.x));
        values.push_back(static_cast<float>(v.y));
        values.push_back(static_cast<float>(v.z));
        if (rot) values.push_back(static_cast<float>(v.w));
      }
      const float tmin = times.empty() ? 0.0f : times.front();
      const float tmax = times.empty() ? 0.0f : times.back();
      tinygltf::AnimationSampler smp;
      smp.input = w.accessor(times.data(), times.size(), TINYGLTF_TYPE_SCALAR,
                             TINYGLTF_COMPONENT_TYPE_FLOAT, 0, {tmin}, {tmax});
      smp.output =
          w.accessor(values.data(), ch.values.size(), rot ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                     TINYGLTF_COMPONENT_TYPE_FLOAT, 0);
      smp.interpolation = ch.interpolation == AnimInterpolation::kStep ? "STEP" : "LINEAR";
      anim.samplers.push_back(smp);
      tinygltf::AnimationChannel gc;
      gc.sampler = static_cast<int>(anim.samplers.size() - 1);
      gc.target_node = ch.node;
      gc.target_path = ch.path == AnimPath::kTranslation ? "translation"
                       : rot                             ? "rotation"
                                                         : "scale";
      anim.channels.push_back(gc);
    }
    model.animations.push_back(anim);
  }
  model.buffers[0].name = "scene";

  tinygltf::TinyGLTF gltf;
  std::ostringstream out;
  if (!gltf.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary))
    throw std::runtime_error(path + ": tinygltf could not serialise the scene");
  write_file_atomically(path, out.str());
}

}  // namespace saarcor::host
