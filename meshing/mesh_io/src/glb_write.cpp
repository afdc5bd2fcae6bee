// glTF 2.0 binary, written by hand (the specification's "GLB File Format"):
// a 12-byte header, a JSON chunk padded with spaces and a BIN chunk padded
// with zeros, each to 4 bytes. Every block of the BIN chunk is a multiple
// of 4 bytes (floats, 32-bit indices, RGBA bytes), so every view and
// accessor is aligned as the specification asks.
#include "skinmesh/mesh_io/glb_write.hpp"

#include "skinmesh/core/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace skinmesh {
namespace {

using json = nlohmann::json;

constexpr int kFloat = 5126, kUnsignedInt = 5125, kUnsignedByte = 5121;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// glTF's vertex colours are linear; our palettes are sRGB.
std::uint8_t linear_byte(std::uint8_t srgb) {
  const double c = srgb / 255.0;
  const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  return static_cast<std::uint8_t>(std::lround(linear * 255.0));
}

// The BIN chunk and the JSON arrays that describe it, grown block by block.
struct Builder {
  std::vector<char> bin;
  json views = json::array(), accessors = json::array();

  int view(const void* data, size_t bytes, int target) {
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    const char* begin = static_cast<const char*>(data);
    bin.insert(bin.end(), begin, begin + bytes);
    views.push_back(v);
    return static_cast<int>(views.size() - 1);
  }
  int accessor(json a) {
    accessors.push_back(std::move(a));
    return static_cast<int>(accessors.size() - 1);
  }
  // Float vectors of `width` components; min and max when asked (POSITION
  // and animation input need them).
  int floats(const std::vector<float>& values, int width, int target, bool bounds) {
    const char* type = width == 1 ? "SCALAR" : "VEC3";
    json a = {{"bufferView", view(values.data(), values.size() * sizeof(float), target)},
              {"componentType", kFloat},
              {"count", values.size() / static_cast<size_t>(width)},
              {"type", type}};
    if (bounds) {
      std::vector<float> lo(static_cast<size_t>(width), std::numeric_limits<float>::infinity());
      std::vector<float> hi(static_cast<size_t>(width), -std::numeric_limits<float>::infinity());
      for (size_t i = 0; i < values.size(); ++i) {
        const size_t k = i % static_cast<size_t>(width);
        lo[k] = std::min(lo[k], values[i]);
        hi[k] = std::max(hi[k], values[i]);
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    return accessor(a);
  }
};

json primitive_of(Builder& b, const GlbFrame& f) {
  if (f.positions.empty() || f.indices.empty()) contract_error("glTF: a frame without vertices or triangles");
  json attributes = {{"POSITION", b.floats(f.positions, 3, kArrayBuffer, true)}};
  if (!f.normals.empty()) attributes["NORMAL"] = b.floats(f.normals, 3, kArrayBuffer, false);
  if (!f.colours.empty())
    attributes["COLOR_0"] = b.accessor({{"bufferView", b.view(f.colours.data(), f.colours.size(), kArrayBuffer)},
                                        {"componentType", kUnsignedByte},
                                        {"normalized", true},
                                        {"count", f.colours.size() / 4},
                                        {"type", "VEC4"}});
  const int indices = b.accessor({{"bufferView", b.view(f.indices.data(), f.indices.size() * 4, kElementArrayBuffer)},
                                  {"componentType", kUnsignedInt},
                                  {"count", f.indices.size()},
                                  {"type", "SCALAR"}});
  return {{"attributes", attributes}, {"indices", indices}, {"mode", 4}, {"material", 0}};
}

// Frame k's node has scale 1 from its time to the next frame's, 0 otherwise.
json visibility_animation(Builder& b, const std::vector<GlbFrame>& frames) {
  std::vector<float> times;
  for (const GlbFrame& f : frames) times.push_back(static_cast<float>(f.seconds));
  for (size_t k = 0; k < times.size(); ++k)
    if (!(times[k] >= 0) || (k > 0 && !(times[k] > times[k - 1])))
      contract_error("glTF: frame times must be non-negative and increase");
  const int input = b.floats(times, 1, 0, true);
  json channels = json::array(), samplers = json::array();
  for (size_t node = 0; node < frames.size(); ++node) {
    std::vector<float> scale(3 * frames.size(), 0.0f);
    std::fill_n(scale.begin() + static_cast<long>(3 * node), 3, 1.0f);
    samplers.push_back({{"input", input}, {"output", b.floats(scale, 3, 0, false)}, {"interpolation", "STEP"}});
    channels.push_back({{"sampler", node}, {"target", {{"node", node}, {"path", "scale"}}}});
  }
  return {{"name", "frames"}, {"channels", channels}, {"samplers", samplers}};
}

void put_u32(std::ostream& out, std::uint32_t v) {
  const unsigned char bytes[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                                  static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24)};
  out.write(reinterpret_cast<const char*>(bytes), 4);
}

}  // namespace

GlbFrame glb_frame(const SurfaceMesh& mesh, const std::vector<Rgb>& colours, const std::string& name, double seconds) {
  GlbFrame f;
  f.name = name;
  f.seconds = seconds;
  for (const auto& v : mesh.vertices)
    for (int k = 0; k < 3; ++k) f.positions.push_back(static_cast<float>(v[k]));
  if (mesh.normals.size() == mesh.vertices.size())
    for (const auto& n : mesh.normals) {
      // Unit in single precision, as the validator checks it.
      float c[3] = {static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2])};
      const float length = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      if (!(length > 0)) contract_error("glTF: a vertex normal of zero length");
      for (float x : c) f.normals.push_back(x / length);
    }
  if (colours.size() == mesh.vertices.size())
    for (const Rgb& c : colours) f.colours.insert(f.colours.end(), {linear_byte(c[0]), linear_byte(c[1]), linear_byte(c[2]), 255});
  for (const auto& t : mesh.triangles)
    for (int i : t) f.indices.push_back(static_cast<std::uint32_t>(i));
  return f;
}

void write_glb(std::ostream& out, const std::vector<GlbFrame>& frames, const std::string& generator) {
  if (frames.empty()) contract_error("glTF: no frame to write");
  Builder b;
  json meshes = json::array(), nodes = json::array(), scene_nodes = json::array();
  for (size_t k = 0; k < frames.size(); ++k) {
    meshes.push_back({{"name", frames[k].name}, {"primitives", json::array({primitive_of(b, frames[k])})}});
    json node = {{"name", frames[k].name}, {"mesh", k}};
    if (frames.size() > 1 && k > 0) node["scale"] = {0.0, 0.0, 0.0};  // before the animation plays: frame 0
    nodes.push_back(node);
    scene_nodes.push_back(k);
  }
  const bool coloured = !frames.front().colours.empty();
  // Without vertex colours, the light blue `render` draws a mesh file in (linear).
  const json base = coloured ? json{1.0, 1.0, 1.0, 1.0} : json{0.342, 0.509, 0.745, 1.0};
  json doc = {{"asset", {{"version", "2.0"}, {"generator", generator}}},
              {"scene", 0},
              {"scenes", json::array({json{{"nodes", scene_nodes}}})},
              {"nodes", nodes},
              {"meshes", meshes},
              {"materials", json::array({json{{"name", "skin"},
                                              {"pbrMetallicRoughness",
                                               {{"baseColorFactor", base}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.7}}}}})}};
  // Arrays of one element are spelt json::array: a braced list of one json
  // value is that value's copy under clang (an object where glTF wants an
  // array), its array under GCC.
  if (frames.size() > 1) doc["animations"] = json::array({visibility_animation(b, frames)});
  while (b.bin.size() % 4) b.bin.push_back(0);
  doc["buffers"] = json::array({json{{"byteLength", b.bin.size()}}});
  doc["bufferViews"] = b.views;
  doc["accessors"] = b.accessors;
  std::string text = doc.dump(-1, ' ', false, json::error_handler_t::replace);
  while (text.size() % 4) text.push_back(' ');
  const size_t total = 12 + 8 + text.size() + 8 + b.bin.size();
  if (total > std::numeric_limits<std::uint32_t>::max()) contract_error("glTF: more than 4 GB in one .glb");
  out.write("glTF", 4);
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(total));
  put_u32(out, static_cast<std::uint32_t>(text.size()));
  out.write("JSON", 4);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  put_u32(out, static_cast<std::uint32_t>(b.bin.size()));
  out.write("BIN\0", 4);
  out.write(b.bin.data(), static_cast<std::streamsize>(b.bin.size()));
  if (!out) output_error("", "writing the glTF file failed");
}

}  // namespace skinmesh
