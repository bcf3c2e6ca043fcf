#include "amalgam/render/loaded_scene.h"

#include <bit>
#include <chrono>
#include <cstring>

#include "amalgam/math/random.h"

namespace amalgam {

LoadedScene load_builtin(const std::string& spec, const Params& params) {
  const auto t0 = std::chrono::steady_clock::now();
  BuiltinScene b = make_builtin(spec, params);
  LoadedScene s;
  s.name = std::move(b.name);
  s.params = params.applied();
  std::visit([&](auto& h) { s.hierarchy = std::move(h); }, b.hierarchy);
  s.env = std::move(b.env);
  s.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

namespace {

/// Accumulates a hash of values, field by field (never padding bytes).
struct Hasher {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  void add(std::uint64_t v) { h = hash_combine(h, v); }
  void add(float f) { add(static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(f))); }
  void add(Vec3 v) { add(v.x), add(v.y), add(v.z); }
  void add(const std::string& s) {
    add(static_cast<std::uint64_t>(s.size()));
    for (unsigned char c : s) add(static_cast<std::uint64_t>(c));
  }
  void add(const Surface& m) {
    add(m.colour), add(m.reflectance), add(m.shininess);
    if (m.texture >= 0) add(static_cast<std::uint64_t>(m.texture));  // untextured: as before
  }
  void add(const Texture& t) {
    add(static_cast<std::uint64_t>(t.width)), add(static_cast<std::uint64_t>(t.height));
    add(static_cast<std::uint64_t>(t.texels.size()));
    std::size_t i = 0;
    for (; i + 8 <= t.texels.size(); i += 8) {  // eight bytes at a time: textures are large
      std::uint64_t w;
      std::memcpy(&w, t.texels.data() + i, 8);
      add(w);
    }
    for (; i < t.texels.size(); ++i) add(static_cast<std::uint64_t>(t.texels[i]));
  }
  void add(const Primitive& p) {
    add(static_cast<std::uint64_t>(p.kind)), add(static_cast<std::uint64_t>(p.material));
    add(p.a), add(p.b), add(p.c), add(p.radius);
  }
  void add(const ExplicitHierarchy& e) {
    add(static_cast<std::uint64_t>(e.prims.size()));
    for (std::size_t i = 0; i < e.prims.size(); ++i) add(e.prims[i]);
    add(static_cast<std::uint64_t>(e.materials.size()));
    for (const Surface& m : e.materials) add(m);
    if (!e.uvs.empty()) {  // textured: coordinates and images (absent before textures existed)
      add(static_cast<std::uint64_t>(e.uvs.size()));
      for (const TexCoords& c : e.uvs)
        for (int k = 0; k < 3; ++k) add(c.u[k]), add(c.v[k]);
    }
    if (e.textures && !e.textures->empty()) {
      add(static_cast<std::uint64_t>(e.textures->size()));
      for (const Texture& t : *e.textures) add(t);
    }
    if (!e.vertex_normals.empty()) {  // smooth: absent for meshes without vertex normals
      add(static_cast<std::uint64_t>(e.vertex_normals.size()) | (std::uint64_t{1} << 63));
      for (const VertexNormals& v : e.vertex_normals)
        for (const Vec3& n : v.n) add(n);
    }
  }
};

}  // namespace

std::uint64_t content_hash(const LoadedScene& scene) {
  Hasher h;
  h.add(scene.name);
  h.add(scene.params);
  h.add(static_cast<std::uint64_t>(scene.env.lights.size()));
  for (const Light& l : scene.env.lights) {
    h.add(static_cast<std::uint64_t>(l.kind));
    h.add(l.position), h.add(l.direction), h.add(l.intensity);
    if (l.sized()) {  // (the hash of every unsized light, as before sizes existed)
      h.add(l.radius), h.add(l.angle);
      h.add(static_cast<std::uint64_t>(l.samples));
    }
    if (l.kind == LightKind::kSpot) h.add(l.cos_inner), h.add(l.cos_outer);
  }
  if (const SkyMap* m = scene.env.sky_map.get()) {
    h.add(static_cast<std::uint64_t>(m->width())), h.add(static_cast<std::uint64_t>(m->height()));
    h.add(m->rotate_y_deg());
    for (const Vec3& p : m->pixels()) h.add(p);
  }
  const Camera& c = scene.env.camera;
  h.add(c.position), h.add(c.look_at), h.add(c.up), h.add(c.vfov_deg);
  h.add(scene.env.background);
  h.add(static_cast<std::uint64_t>(scene.hierarchy.index()));
  if (const auto* e = std::get_if<ExplicitHierarchy>(&scene.hierarchy)) h.add(*e);
  if (const auto* in = std::get_if<InstancedHierarchy>(&scene.hierarchy)) {
    h.add(static_cast<std::uint64_t>(in->meshes.size()));
    for (const ExplicitHierarchy& m : in->meshes) h.add(m);
    h.add(static_cast<std::uint64_t>(in->instances.size()));
    for (const auto& d : in->instances) {
      h.add(static_cast<std::uint64_t>(d.mesh));
      for (const auto& row : d.to_world.m)
        for (float v : row) h.add(v);
    }
  }
  return h.h;
}

}  // namespace amalgam
