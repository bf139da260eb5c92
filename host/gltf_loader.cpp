// glTF 2.0 -> Scene (README.md "Layout" and docs/memory-image.md; paper section 2: each mesh is an
// object with its own bottom-level tree, each node that carries it an instance in the top level).
// tinygltf parses the file; texture images reach us through its image-loader callback and are
// decoded with OpenImageIO. What the hardware cannot represent is reduced with a warning or refused
// with one line (docs/scenes.md, "What is refused or reduced").
#include "host/gltf_loader.h"

#include <tiny_gltf.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>

namespace saarcor::host {

namespace {

std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' '))
    s.pop_back();
  std::string out;
  for (char c : s) {
    if (c == '\n') {
      out += "; ";
    } else if (c != '\r') {
      out += c;
    }
  }
  return out;
}

// Encoded image bytes per glTF image index, filled by the tinygltf callback. Decoding waits until
// we know which images the materials use as base colour (normal, occlusion and emissive maps are
// never decoded: the fixed-function shader has no use for them).
struct ImageStash {
  std::vector<std::vector<unsigned char>> bytes;
};

bool stash_image(tinygltf::Image* /*image*/, const int image_idx, std::string* /*err*/,
                 std::string* /*warn*/, int /*req_width*/, int /*req_height*/,
                 const unsigned char* bytes, int size, void* user) {
  auto* stash = static_cast<ImageStash*>(user);
  const auto idx = static_cast<std::size_t>(image_idx);
  if (stash->bytes.size() <= idx) stash->bytes.resize(idx + 1);
  stash->bytes[idx].assign(bytes, bytes + size);
  return true;
}

const char* sniff_extension(const unsigned char* b, std::size_t n) {
  if (n >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0) return "png";
  if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return "jpg";
  if (n >= 12 && std::memcmp(b, "RIFF", 4) == 0 && std::memcmp(b + 8, "WEBP", 4) == 0)
    return "webp";
  if (n >= 2 && b[0] == 'B' && b[1] == 'M') return "bmp";
  if (n >= 4 && (std::memcmp(b, "II*\0", 4) == 0 || std::memcmp(b, "MM\0*", 4) == 0)) return "tif";
  if (n >= 6 && std::memcmp(b, "GIF8", 4) == 0) return "gif";
  return nullptr;
}

// The values a scene's accessors may hold in all, reads of one accessor counted each time
// (meshes that share accessors read them again): 2^25, about four times what a mesh of a million
// triangles needs, so a file whose counts ask for gigabytes is refused in one line instead
// (docs/scenes.md, "What is refused or reduced").
constexpr std::size_t kMaxAccessorValues = std::size_t{1} << 25;

// Reads one accessor into doubles (count * components), checking every byte it touches.
struct AccessorData {
  std::size_t count = 0;
  int components = 0;
  std::vector<double> values;
};

class Reader {
 public:
  Reader(const tinygltf::Model& model, std::string path) : model_(model), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(path_ + ": " + what);
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size())
      fail(what + ": accessor " + std::to_string(index) + " does not exist");
    return model_.accessors[static_cast<std::size_t>(index)];
  }

  AccessorData read(int index, const std::string& what) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    AccessorData out;
    out.count = acc.count;
    out.components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
    const int csize =
        tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
    const std::string name = what + " (accessor " + std::to_string(index) + ")";
    if (out.components <= 0 || csize <= 0) fail(name + ": unknown type or component type");
    if (out.count > (std::size_t{1} << 31)) fail(name + ": count too large");
    // Everything is checked before the values are allocated: a count is only a number in the
    // JSON, and an accessor without a buffer view (zeros) is not bounded by the file's size.
    const std::size_t values = out.count * static_cast<std::size_t>(out.components);
    if (values > kMaxAccessorValues - values_read_)
      fail(name + ": the scene is too large: its accessors hold more than " +
           std::to_string(kMaxAccessorValues) + " values in all (the loader's limit)");
    const unsigned char* base = nullptr;
    std::size_t stride = 0;
    if (acc.bufferView >= 0) {
      std::size_t available = 0;
      view(acc.bufferView, acc.byteOffset, name, base, available);
      const std::size_t elem =
          static_cast<std::size_t>(csize) * static_cast<std::size_t>(out.components);
      const auto& bv = model_.bufferViews[static_cast<std::size_t>(acc.bufferView)];
      stride = bv.byteStride > 0 ? bv.byteStride : elem;
      if (out.count > 0 && (stride * (out.count - 1) + elem > available))
        fail(name + ": reads past the end of its buffer view");
    }
    values_read_ += values;
    out.values.assign(values, 0.0);
    if (base != nullptr) {
      for (std::size_t i = 0; i < out.count; ++i)
        for (int c = 0; c < out.components; ++c)
          out.values[i * static_cast<std::size_t>(out.components) + static_cast<std::size_t>(c)] =
              component(base + i * stride + static_cast<std::size_t>(c * csize), acc.componentType,
                        acc.normalized);
    }
    if (acc.sparse.isSparse) apply_sparse(acc, out, name);
    return out;
  }

  std::vector<std::uint32_t> read_indices(int index, const std::string& what) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    if (acc.type != TINYGLTF_TYPE_SCALAR ||
        (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
         acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      fail(what + " (accessor " + std::to_string(index) + "): indices must be unsigned scalars");
    const AccessorData d = read(index, what);
    std::vector<std::uint32_t> out(d.values.size());
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<std::uint32_t>(d.values[i]);
    return out;
  }

 private:
  void view(int view_index, std::size_t offset, const std::string& name, const unsigned char*& base,
            std::size_t& available) const {
    if (view_index < 0 || static_cast<std::size_t>(view_index) >= model_.bufferViews.size())
      fail(name + ": buffer view " + std::to_string(view_index) + " does not exist");
    const auto& bv = model_.bufferViews[static_cast<std::size_t>(view_index)];
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model_.buffers.size())
      fail(name + ": buffer " + std::to_string(bv.buffer) + " does not exist");
    const auto& buf = model_.buffers[static_cast<std::size_t>(bv.buffer)];
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
      fail(name + ": buffer view " + std::to_string(view_index) +
           " reaches past the end of buffer " + std::to_string(bv.buffer) +
           (buf.uri.empty() || buf.uri.rfind("data:", 0) == 0 ? std::string()
                                                              : " (" + buf.uri + ")"));
    if (offset > bv.byteLength) fail(name + ": byte offset past the end of its buffer view");
    base = buf.data.data() + bv.byteOffset + offset;
    available = bv.byteLength - offset;
  }

  static double component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
      }
      case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
        double d;
        std::memcpy(&d, p, 8);
        return d;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? p[0] / 255.0 : p[0];
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const auto v = static_cast<std::int8_t>(p[0]);
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        std::int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_INT: {
        std::int32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
      default:
        return 0.0;
    }
  }

  void apply_sparse(const tinygltf::Accessor& acc, AccessorData& out,
                    const std::string& name) const {
    const auto n = static_cast<std::size_t>(std::max(acc.sparse.count, 0));
    const int isize = tinygltf::GetComponentSizeInBytes(
        static_cast<std::uint32_t>(acc.sparse.indices.componentType));
    const int csize =
        tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
    if (isize <= 0 || csize <= 0) fail(name + ": bad sparse component type");
    // glTF 2.0 3.6.2.3: unsigned integer indices (a float one would be cast to an index).
    const int itype = acc.sparse.indices.componentType;
    if (itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(name + ": sparse indices must be unsigned integers, not component type " +
           std::to_string(itype));
    const unsigned char* ib = nullptr;
    const unsigned char* vb = nullptr;
    std::size_t ia = 0;
    std::size_t va = 0;
    view(acc.sparse.indices.bufferView, static_cast<std::size_t>(acc.sparse.indices.byteOffset),
         name + " sparse indices", ib, ia);
    view(acc.sparse.values.bufferView, static_cast<std::size_t>(acc.sparse.values.byteOffset),
         name + " sparse values", vb, va);
    const auto comps = static_cast<std::size_t>(out.components);
    if (n * static_cast<std::size_t>(isize) > ia ||
        n * comps * static_cast<std::size_t>(csize) > va)
      fail(name + ": sparse data reaches past the end of its buffer view");
    for (std::size_t i = 0; i < n; ++i) {
      const auto target = static_cast<std::size_t>(component(
          ib + i * static_cast<std::size_t>(isize), acc.sparse.indices.componentType, false));
      if (target >= out.count) fail(name + ": sparse index out of range");
      for (std::size_t c = 0; c < comps; ++c)
        out.values[target * comps + c] =
            component(vb + (i * comps + c) * static_cast<std::size_t>(csize), acc.componentType,
                      acc.normalized);
    }
  }

  const tinygltf::Model& model_;
  std::string path_;
  mutable std::size_t values_read_ = 0;  // accessor values read so far (kMaxAccessorValues)
};

std::string mesh_label(const tinygltf::Mesh& mesh, std::size_t index) {
  return "mesh " + std::to_string(index) + (mesh.name.empty() ? "" : " '" + mesh.name + "'");
}

// Turns one primitive's index list into triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN).
std::vector<glm::uvec3> assemble(int mode, const std::vector<std::uint32_t>& idx) {
  std::vector<glm::uvec3> tris;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    tris.reserve(idx.size() / 3);
    for (std::size_t i = 0; i + 2 < idx.size(); i += 3)
      tris.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    // glTF 2.0 section 3.7.2.1: triangle i = (v_i, v_{i+1+i%2}, v_{i+2-i%2}).
    for (std::size_t i = 0; i + 2 < idx.size(); ++i) {
      const std::size_t odd = i % 2;
      tris.emplace_back(idx[i], idx[i + 1 + odd], idx[i + 2 - odd]);
    }
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    // glTF 2.0: triangle i = (v_{i+1}, v_{i+2}, v_0).
    for (std::size_t i = 0; i + 2 < idx.size(); ++i)
      tris.emplace_back(idx[i + 1], idx[i + 2], idx[0]);
  }
  return tris;
}

void compute_missing_normals(Object& obj, const std::vector<std::uint8_t>& missing) {
  std::vector<glm::dvec3> acc(obj.positions.size(), glm::dvec3(0.0));
  for (const glm::uvec3& t : obj.triangles) {
    if (!missing[t.x] && !missing[t.y] && !missing[t.z]) continue;
    const glm::dvec3 a(obj.positions[t.x]);
    const glm::dvec3 n =
        glm::cross(glm::dvec3(obj.positions[t.y]) - a, glm::dvec3(obj.positions[t.z]) - a);
    for (int k = 0; k < 3; ++k)
      acc[t[k]] += n;
  }
  for (std::size_t v = 0; v < obj.positions.size(); ++v) {
    if (!missing[v]) continue;
    const double len = glm::length(acc[v]);
    obj.normals[v] = len > 0.0 ? glm::vec3(acc[v] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

// A number property of one of a material's extensions; nullopt when the extension, the property
// or a number there is missing.
std::optional<double> extension_number(const tinygltf::Material& gm, const char* extension,
                                       const char* property) {
  const auto e = gm.extensions.find(extension);
  if (e == gm.extensions.end() || !e->second.Has(property)) return std::nullopt;
  const tinygltf::Value& v = e->second.Get(property);
  if (!v.IsNumber()) return std::nullopt;
  return v.GetNumberAsDouble();
}

// Glass (docs/shading.md section 7, docs/scenes.md "Materials"): KHR_materials_transmission's
// transmissionFactor and KHR_materials_ior's ior (glTF's 1.5 when absent). The transmission
// texture is not read: the factor alone sets the refraction weight.
void read_glass(const tinygltf::Material& gm, Material& mat, Scene& scene) {
  if (const auto t = extension_number(gm, "KHR_materials_transmission", "transmissionFactor"))
    mat.transmission = static_cast<float>(std::clamp(*t, 0.0, 1.0));
  if (const auto e = gm.extensions.find("KHR_materials_transmission");
      e != gm.extensions.end() && e->second.Has("transmissionTexture"))
    scene.warn("material '" + mat.name +
               "': transmissionTexture is not supported: transmissionFactor alone is used");
  if (const auto ior = extension_number(gm, "KHR_materials_ior", "ior")) {
    if (*ior >= 1.0 && *ior <= 64.0)
      mat.ior = static_cast<float>(*ior);
    else
      scene.warn("material '" + mat.name + "': ior " + std::to_string(*ior) +
                 " is outside 1..64: 1.5 is used");
  }
}

Object convert_mesh(const tinygltf::Model& model, const Reader& reader, std::size_t mesh_index,
                    std::uint32_t default_material, bool& default_used, Scene& scene) {
  const tinygltf::Mesh& mesh = model.meshes[mesh_index];
  const std::string label = mesh_label(mesh, mesh_index);
  Object obj;
  obj.name = mesh.name.empty() ? "mesh" + std::to_string(mesh_index) : mesh.name;
  bool any_uv = false;
  bool any_normal = false;
  std::vector<std::uint8_t> uv_present;
  std::vector<std::uint8_t> normal_present;
  // Primitives that share their vertex accessors (a common exporter pattern) share vertices.
  std::map<std::tuple<int, int, int>, std::uint32_t> vertex_base;
  bool morph = false;
  for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
    const tinygltf::Primitive& prim = mesh.primitives[p];
    const std::string plabel = label + " primitive " + std::to_string(p);
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++scene.skipped_primitives;
      scene.warn(label + ": primitive " + std::to_string(p) + " has mode " +
                 std::to_string(prim.mode) +
                 " (points or lines): skipped, only triangles are ray traced");
      continue;
    }
    if (!prim.targets.empty()) morph = true;
    const auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) reader.fail(plabel + ": no POSITION attribute");
    const auto find_attr = [&](const char* name) {
      const auto it = prim.attributes.find(name);
      return it == prim.attributes.end() ? -1 : it->second;
    };
    const int uv_acc = find_attr("TEXCOORD_0");
    const int n_acc = find_attr("NORMAL");
    const auto key = std::make_tuple(pos_it->second, uv_acc, n_acc);
    std::uint32_t base = 0;
    std::size_t vertex_count = 0;
    if (const auto it = vertex_base.find(key); it != vertex_base.end()) {
      base = it->second;
      vertex_count = reader.accessor(pos_it->second, plabel).count;
    } else {
      const AccessorData pos = reader.read(pos_it->second, plabel + " POSITION");
      if (pos.components != 3) reader.fail(plabel + " POSITION: not a VEC3 accessor");
      for (std::size_t i = 0; i < pos.values.size(); ++i) {
        if (!std::isfinite(pos.values[i]) ||
            std::abs(pos.values[i]) > static_cast<double>(std::numeric_limits<float>::max()))
          reader.fail(label + ": accessor " + std::to_string(pos_it->second) +
                      " (POSITION) has a non-finite value at vertex " + std::to_string(i / 3));
      }
      base = static_cast<std::uint32_t>(obj.positions.size());
      vertex_count = pos.count;
      vertex_base.emplace(key, base);
      for (std::size_t i = 0; i < pos.count; ++i)
        obj.positions.emplace_back(pos.values[3 * i], pos.values[3 * i + 1], pos.values[3 * i + 2]);
      if (uv_acc >= 0) {
        const AccessorData uv = reader.read(uv_acc, plabel + " TEXCOORD_0");
        if (uv.components != 2 || uv.count != pos.count)
          reader.fail(plabel + " TEXCOORD_0: not a VEC2 accessor with one entry per vertex");
        any_uv = true;
        for (std::size_t i = 0; i < uv.count; ++i)
          obj.texcoords.emplace_back(uv.values[2 * i], uv.values[2 * i + 1]);
        uv_present.insert(uv_present.end(), pos.count, 1);
      } else {
        obj.texcoords.insert(obj.texcoords.end(), pos.count, glm::vec2(0.0f));
        uv_present.insert(uv_present.end(), pos.count, 0);
      }
      if (n_acc >= 0) {
        const AccessorData nrm = reader.read(n_acc, plabel + " NORMAL");
        if (nrm.components != 3 || nrm.count != pos.count)
          reader.fail(plabel + " NORMAL: not a VEC3 accessor with one entry per vertex");
        any_normal = true;
        for (std::size_t i = 0; i < nrm.count; ++i) {
          glm::dvec3 n(nrm.values[3 * i], nrm.values[3 * i + 1], nrm.values[3 * i + 2]);
          const double len = glm::length(n);
          n = (std::isfinite(len) && len > 0.0) ? n / len : glm::dvec3(0.0, 0.0, 1.0);
          obj.normals.emplace_back(n);
        }
        normal_present.insert(normal_present.end(), pos.count, 1);
      } else {
        obj.normals.insert(obj.normals.end(), pos.count, glm::vec3(0.0f));
        normal_present.insert(normal_present.end(), pos.count, 0);
      }
    }
    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
      idx = reader.read_indices(prim.indices, plabel + " indices");
      for (std::size_t i = 0; i < idx.size(); ++i) {
        if (idx[i] >= vertex_count)
          reader.fail(label + ": accessor " + std::to_string(prim.indices) + " (indices) entry " +
                      std::to_string(i) + " = " + std::to_string(idx[i]) + " is not below the " +
                      std::to_string(vertex_count) + " vertices");
      }
    } else {
      idx.resize(vertex_count);
      for (std::size_t i = 0; i < vertex_count; ++i)
        idx[i] = static_cast<std::uint32_t>(i);
    }
    std::uint32_t material = default_material;
    if (prim.material < 0) default_used = true;
    if (prim.material >= 0) {
      if (static_cast<std::size_t>(prim.material) >= model.materials.size())
        reader.fail(plabel + ": material " + std::to_string(prim.material) + " does not exist");
      material = static_cast<std::uint32_t>(prim.material);
    }
    for (const glm::uvec3& t : assemble(prim.mode, idx)) {
      obj.triangles.push_back(t + glm::uvec3(base));
      obj.material.push_back(material);
    }
  }
  if (morph)
    scene.warn(
        label +
        " has morph targets: rendered with its base shape (morph targets are not supported)");
  if (!any_uv) obj.texcoords.clear();
  if (any_normal) {
    std::vector<std::uint8_t> missing(normal_present.size());
    for (std::size_t i = 0; i < missing.size(); ++i)
      missing[i] = normal_present[i] ? 0 : 1;
    compute_missing_normals(obj, missing);
  } else {
    obj.normals.clear();
  }
  mark_degenerate_triangles(obj);
  return obj;
}

glm::dvec4 to_vec4(const AccessorData& d, std::size_t i) {
  glm::dvec4 v(0.0);
  for (int c = 0; c < std::min(d.components, 4); ++c)
    v[c] = d.values[i * static_cast<std::size_t>(d.components) + static_cast<std::size_t>(c)];
  return v;
}

}  // namespace

Texture decode_image(const unsigned char* bytes, std::size_t size, const std::string& name) {
  using namespace OIIO;
  Filesystem::IOMemReader mem(bytes, size);
  const char* ext = sniff_extension(bytes, size);
  std::string fake_name = "texture.";
  if (ext != nullptr) {
    fake_name += ext;
  } else {
    const std::string e = std::filesystem::path(name).extension().string();
    fake_name += e.empty() ? "png" : e.substr(1);
  }
  auto in = ImageInput::open(fake_name, nullptr, &mem);
  if (!in) throw std::runtime_error(name + ": cannot decode image: " + one_line(OIIO::geterror()));
  const ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.width > 65536 ||
      spec.height > 65536)
    throw std::runtime_error(name + ": cannot decode image: bad size");
  const int nch = std::min(spec.nchannels, 4);
  std::vector<unsigned char> pix(static_cast<std::size_t>(spec.width) *
                                 static_cast<std::size_t>(spec.height) *
                                 static_cast<std::size_t>(nch));
  if (!in->read_image(0, 0, 0, nch, TypeDesc::UINT8, pix.data()))
    throw std::runtime_error(name + ": cannot decode image: " + one_line(in->geterror()));
  in->close();
  Texture tex;
  tex.name = name;
  tex.width = spec.width;
  tex.height = spec.height;
  tex.rgba.resize(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height));
  for (std::size_t i = 0; i < tex.rgba.size(); ++i) {
    const unsigned char* p = &pix[i * static_cast<std::size_t>(nch)];
    std::uint32_t r = p[0], g = p[0], b = p[0], a = 255;
    if (nch == 2) a = p[1];
    if (nch >= 3) {
      g = p[1];
      b = p[2];
    }
    if (nch == 4) a = p[3];
    tex.rgba[i] = r | (g << 8) | (b << 16) | (a << 24);
  }
  return tex;
}

Scene load_gltf(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error(path + ": no such file");
  char magic[4] = {0, 0, 0, 0};
  {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error(path + ": cannot open");
    f.read(magic, 4);
  }
  const bool binary = std::memcmp(magic, "glTF", 4) == 0;

  tinygltf::Model model;
  tinygltf::TinyGLTF gltf;
  ImageStash stash;
  gltf.SetImageLoader(&stash_image, &stash);
  std::string err;
  std::string warn;
  const bool ok = binary ? gltf.LoadBinaryFromFile(&model, &err, &warn, path)
                         : gltf.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!ok) {
    if (err.empty()) err = "unknown tinygltf error";
    throw std::runtime_error(path + ": cannot load glTF: " + one_line(err));
  }
  const Reader reader(model, path);
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();

  Scene scene;
  // Extensions: geometry we cannot decode (Draco, meshopt, ...) must not load as garbage, so an
  // unsupported *required* extension is refused; material and texture extensions only change
  // appearance, so they are ignored with a warning.
  const auto supported = [](const std::string& ext) {
    return ext == "KHR_lights_punctual" || ext == "KHR_mesh_quantization" ||
           ext == "KHR_materials_transmission" || ext == "KHR_materials_ior";
  };
  const auto cosmetic = [](const std::string& ext) {
    return ext.rfind("KHR_materials_", 0) == 0 || ext == "KHR_texture_transform";
  };
  for (const std::string& ext : model.extensionsRequired) {
    if (!supported(ext) && !cosmetic(ext))
      reader.fail("requires extension " + ext + ", which is not supported");
  }
  for (const std::string& ext : model.extensionsUsed) {
    if (!supported(ext)) scene.warn("extension " + ext + " is not supported: ignored");
  }

  // Every external image must exist, even one the shader will not use: a missing file is a
  // broken asset.
  stash.bytes.resize(model.images.size());
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    const tinygltf::Image& img = model.images[i];
    if (stash.bytes[i].empty()) {
      const std::string file =
          img.uri.empty() ? "image " + std::to_string(i) : (dir / img.uri).string();
      throw std::runtime_error(path + ": image file missing or unreadable: " + file);
    }
  }

  // Materials; textures are decoded only for the base colour.
  std::vector<int> image_texture(model.images.size(), -1);
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const tinygltf::Material& gm = model.materials[m];
    Material mat;
    mat.name = gm.name.empty() ? "material" + std::to_string(m) : gm.name;
    const auto& pbr = gm.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      mat.base_color = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                 pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    mat.metallic = static_cast<float>(pbr.metallicFactor);
    mat.roughness = static_cast<float>(pbr.roughnessFactor);
    if (pbr.baseColorTexture.index >= 0) {
      const auto ti = static_cast<std::size_t>(pbr.baseColorTexture.index);
      if (ti >= model.textures.size())
        reader.fail(mat.name + ": texture " + std::to_string(ti) + " does not exist");
      const int src = model.textures[ti].source;
      if (src < 0 || static_cast<std::size_t>(src) >= model.images.size()) {
        scene.warn("texture " + std::to_string(ti) + " has no image it can use: material '" +
                   mat.name + "' is untextured");
      } else {
        const auto si = static_cast<std::size_t>(src);
        if (image_texture[si] < 0) {
          const tinygltf::Image& img = model.images[si];
          const std::string name = img.uri.empty() || img.uri.rfind("data:", 0) == 0
                                       ? "embedded:" + std::to_string(si)
                                       : img.uri;
          const std::string file = img.uri.empty() || img.uri.rfind("data:", 0) == 0
                                       ? path + " image " + std::to_string(si)
                                       : (dir / img.uri).string();
          Texture tex = decode_image(stash.bytes[si].data(), stash.bytes[si].size(), file);
          tex.name = name;
          image_texture[si] = static_cast<int>(scene.textures.size());
          scene.textures.push_back(std::move(tex));
        }
        mat.texture = image_texture[si];
        if (pbr.baseColorTexture.texCoord != 0)
          scene.warn("material '" + mat.name + "' uses TEXCOORD_" +
                     std::to_string(pbr.baseColorTexture.texCoord) +
                     ": TEXCOORD_0 is used instead");
      }
    }
    read_glass(gm, mat, scene);
    derive_fixed_function_terms(mat, gm.alphaMode == "BLEND");
    scene.materials.push_back(std::move(mat));
  }
  // glTF's default material, for primitives without one: white, fully metallic and rough (the
  // glTF default factors). Added only when a primitive uses it.
  const auto default_material = static_cast<std::uint32_t>(scene.materials.size());
  bool default_used = false;
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    scene.objects.push_back(convert_mesh(model, reader, m, default_material, default_used, scene));
  if (default_used) {
    Material mat;
    mat.name = "default";
    mat.metallic = 1.0f;
    mat.roughness = 1.0f;
    derive_fixed_function_terms(mat, false);
    scene.materials.push_back(mat);
  }

  // Nodes.
  const std::size_t node_count = model.nodes.size();
  scene.nodes.resize(node_count);
  for (std::size_t n = 0; n < node_count; ++n) {
    const tinygltf::Node& gn = model.nodes[n];
    Node& node = scene.nodes[n];
    node.name = gn.name;
    if (gn.mesh >= 0) {
      if (static_cast<std::size_t>(gn.mesh) >= model.meshes.size())
        reader.fail("node " + std::to_string(n) + ": mesh " + std::to_string(gn.mesh) +
                    " does not exist");
      node.object = gn.mesh;
      if (gn.skin >= 0)
        scene.warn(mesh_label(model.meshes[static_cast<std::size_t>(gn.mesh)],
                              static_cast<std::size_t>(gn.mesh)) +
                   " is skinned: rendered in its bind pose (skinning is not supported)");
    }
    for (int c : gn.children) {
      if (c < 0 || static_cast<std::size_t>(c) >= node_count)
        reader.fail("node " + std::to_string(n) + ": child " + std::to_string(c) +
                    " does not exist");
      node.children.push_back(c);
      scene.nodes[static_cast<std::size_t>(c)].parent = static_cast<int>(n);
    }
    if (gn.matrix.size() == 16) {
      node.use_trs = false;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          node.matrix[c][r] = gn.matrix[static_cast<std::size_t>(c * 4 + r)];
    } else {
      if (gn.translation.size() == 3)
        node.translation = {gn.translation[0], gn.translation[1], gn.translation[2]};
      if (gn.rotation.size() == 4)
        node.rotation = glm::normalize(
            glm::dquat(gn.rotation[3], gn.rotation[0], gn.rotation[1], gn.rotation[2]));
      if (gn.scale.size() == 3) node.scale = {gn.scale[0], gn.scale[1], gn.scale[2]};
    }
  }

  // Default scene; a file without scenes renders every root node.
  if (!model.scenes.empty()) {
    int s = model.defaultScene;
    if (s < 0 || static_cast<std::size_t>(s) >= model.scenes.size()) s = 0;
    for (int r : model.scenes[static_cast<std::size_t>(s)].nodes) {
      if (r < 0 || static_cast<std::size_t>(r) >= node_count)
        reader.fail("scene " + std::to_string(s) + ": node " + std::to_string(r) +
                    " does not exist");
      scene.roots.push_back(r);
    }
  } else {
    for (std::size_t n = 0; n < node_count; ++n)
      if (scene.nodes[n].parent < 0) scene.roots.push_back(static_cast<int>(n));
  }

  // Animations (all clips play together; docs/scenes.md).
  std::vector<std::uint8_t> targeted(node_count, 0);
  for (std::size_t a = 0; a < model.animations.size(); ++a) {
    const tinygltf::Animation& anim = model.animations[a];
    for (std::size_t c = 0; c < anim.channels.size(); ++c) {
      const tinygltf::AnimationChannel& gc = anim.channels[c];
      const std::string label = "animation " + std::to_string(a) + " channel " + std::to_string(c);
      if (gc.target_node < 0) continue;
      if (static_cast<std::size_t>(gc.target_node) >= node_count)
        reader.fail(label + ": node " + std::to_string(gc.target_node) + " does not exist");
      AnimChannel ch;
      ch.node = gc.target_node;
      if (gc.target_path == "translation") {
        ch.path = AnimPath::kTranslation;
      } else if (gc.target_path == "rotation") {
        ch.path = AnimPath::kRotation;
      } else if (gc.target_path == "scale") {
        ch.path = AnimPath::kScale;
      } else {
        scene.warn("animation of '" + gc.target_path +
                   "' (morph weights) is not supported: ignored");
        continue;
      }
      if (gc.sampler < 0 || static_cast<std::size_t>(gc.sampler) >= anim.samplers.size())
        reader.fail(label + ": sampler " + std::to_string(gc.sampler) + " does not exist");
      const tinygltf::AnimationSampler& gs = anim.samplers[static_cast<std::size_t>(gc.sampler)];
      if (gs.interpolation == "STEP") {
        ch.interpolation = AnimInterpolation::kStep;
      } else if (gs.interpolation == "CUBICSPLINE") {
        ch.interpolation = AnimInterpolation::kCubicSpline;
        scene.warn(
            "CUBICSPLINE animation interpolation is not supported: interpolated linearly "
            "between its key values (tangents ignored)");
      } else {
        ch.interpolation = AnimInterpolation::kLinear;
      }
      const AccessorData in = reader.read(gs.input, label + " input");
      const AccessorData out = reader.read(gs.output, label + " output");
      if (in.components != 1) reader.fail(label + " input: not a SCALAR accessor");
      const int want = ch.path == AnimPath::kRotation ? 4 : 3;
      if (out.components != want)
        reader.fail(label + " output: wrong accessor type for " + gc.target_path);
      const std::size_t keys = in.count;
      const std::size_t per_key = ch.interpolation == AnimInterpolation::kCubicSpline ? 3 : 1;
      if (keys == 0 || out.count != keys * per_key)
        reader.fail(label + ": " + std::to_string(out.count) + " output values for " +
                    std::to_string(keys) + " keys");
      for (std::size_t k = 0; k < keys; ++k) {
        const double t = in.values[k];
        if (!std::isfinite(t) || (k > 0 && t < ch.times.back()))
          reader.fail(label + ": key times are not finite and ascending");
        ch.times.push_back(t);
        ch.values.push_back(to_vec4(out, k * per_key + (per_key == 3 ? 1 : 0)));
      }
      scene.animation_seconds = std::max(scene.animation_seconds, ch.times.back());
      if (ch.interpolation == AnimInterpolation::kCubicSpline)
        ch.interpolation = AnimInterpolation::kLinear;
      targeted[static_cast<std::size_t>(ch.node)] = 1;
      // An animated node's matrix is replaced by TRS (glTF forbids animating matrix nodes; be
      // lenient).
      scene.nodes[static_cast<std::size_t>(ch.node)].use_trs = true;
      scene.animations.push_back(std::move(ch));
    }
  }

  // Instances, cameras and lights of the default scene, depth-first in node order.
  std::vector<std::uint8_t> visited(node_count, 0);
  std::vector<std::pair<int, bool>> stack;  // node, an ancestor is animated
  for (auto r = scene.roots.rbegin(); r != scene.roots.rend(); ++r)
    stack.emplace_back(*r, false);
  while (!stack.empty()) {
    const auto [n, anc_animated] = stack.back();
    stack.pop_back();
    const auto un = static_cast<std::size_t>(n);
    if (visited[un])
      reader.fail("node " + std::to_string(n) + " is reached twice: the node graph is not a tree");
    visited[un] = 1;
    Node& node = scene.nodes[un];
    node.animated = anc_animated || targeted[un];
    const tinygltf::Node& gn = model.nodes[un];
    if (node.object >= 0) {
      Instance inst;
      inst.object = static_cast<std::uint32_t>(node.object);
      inst.id = static_cast<std::uint32_t>(n);
      inst.dynamic = node.animated;
      scene.instances.push_back(inst);
    }
    if (gn.camera >= 0) {
      if (static_cast<std::size_t>(gn.camera) >= model.cameras.size())
        reader.fail("node " + std::to_string(n) + ": camera " + std::to_string(gn.camera) +
                    " does not exist");
      const tinygltf::Camera& gc = model.cameras[static_cast<std::size_t>(gn.camera)];
      if (gc.type == "perspective") {
        Camera cam;
        cam.name = gc.name.empty() ? "camera" + std::to_string(gn.camera) : gc.name;
        cam.yfov = static_cast<float>(gc.perspective.yfov);
        cam.node = n;
        node.camera = static_cast<int>(scene.cameras.size());
        scene.cameras.push_back(cam);
      } else {
        scene.warn("camera " + std::to_string(gn.camera) + " is " + gc.type +
                   ": skipped (only perspective cameras are supported)");
      }
    }
    if (const auto ext = gn.extensions.find("KHR_lights_punctual"); ext != gn.extensions.end()) {
      const tinygltf::Value& v = ext->second.Get("light");
      const int li = v.IsInt() ? v.Get<int>() : -1;
      if (li < 0 || static_cast<std::size_t>(li) >= model.lights.size())
        reader.fail("node " + std::to_string(n) + ": light " + std::to_string(li) +
                    " does not exist");
      const tinygltf::Light& gl = model.lights[static_cast<std::size_t>(li)];
      if (gl.type == "directional") {
        scene.warn("light " + std::to_string(li) +
                   " is directional: skipped (only point lights are supported)");
      } else {
        if (gl.type == "spot")
          scene.warn("light " + std::to_string(li) +
                     " is a spot light: used as a point light (no cone)");
        Light light;
        glm::vec3 color(1.0f);
        if (gl.color.size() == 3) color = glm::vec3(gl.color[0], gl.color[1], gl.color[2]);
        light.color =
            glm::clamp(color * static_cast<float>(std::min(gl.intensity, 1.0)), 0.0f, 1.0f);
        light.node = n;
        node.light = static_cast<int>(scene.lights.size());
        scene.lights.push_back(light);
      }
    }
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
      stack.emplace_back(*c, node.animated);
  }

  scene.source = path;
  scene.set_time(0.0);
  return scene;
}

}  // namespace saarcor::host
