#include "amalgam/io/assimp_scene.h"

#include <assimp/GltfMaterial.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "amalgam/io/image_decode.h"
#include "amalgam/io/import_protocol.h"
#include "amalgam/util/error.h"

namespace amalgam::assimp_scene {
namespace {

namespace fs = std::filesystem;

std::string quoted(const aiString& s) {
  std::string q = "'";  // appended, not "'" + ...: GCC 12 warns falsely (-Wrestrict) on that
  q += one_line(s.C_Str(), 60);
  q += '\'';
  return q;
}

std::string numbered(unsigned i) {
  std::string s = "#";
  s += std::to_string(i);
  return s;
}

std::string material_name(const aiMaterial& m, unsigned index) {
  aiString name;
  if (m.Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS && name.length) return quoted(name);
  return numbered(index);
}

/// Collects the things of one kind that are not rendered; one line each kind.
class Notes {
 public:
  explicit Notes(const std::string& path) : path_(path) {}
  void add(const std::string& what, const std::string& item) {
    auto& items = kinds_[what];
    if (std::find(items.begin(), items.end(), item) == items.end()) items.push_back(item);
  }
  void flush(std::vector<std::string>& out) {
    for (const auto& [what, items] : kinds_) {
      std::string line = path_ + ": " + what + ": ";
      const std::size_t shown = std::min<std::size_t>(items.size(), 6);
      for (std::size_t i = 0; i < shown; ++i) line += (i ? ", " : "") + items[i];
      if (items.size() > shown) line += " and " + std::to_string(items.size() - shown) + " more";
      out.push_back(line);
    }
    kinds_.clear();
  }

 private:
  std::string path_;
  std::map<std::string, std::vector<std::string>> kinds_;
};

aiMatrix4x4 global_transform(const aiNode* n) {
  aiMatrix4x4 m;
  for (; n != nullptr; n = n->mParent) m = n->mTransformation * m;
  return m;
}

Vec3 point(const aiMatrix4x4& m, const aiVector3D& p) {
  const aiVector3D q = m * p;
  return {q.x, q.y, q.z};
}

Vec3 vector(const aiMatrix4x4& m, const aiVector3D& v) {
  const aiVector3D q = aiMatrix3x3(m) * v;
  return {q.x, q.y, q.z};
}

float clamp01(float v) {
  return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.8f;
}

bool is_spec_gloss(const aiMaterial& m) {
  float g;
  return m.Get(AI_MATKEY_GLOSSINESS_FACTOR, g) == aiReturn_SUCCESS;
}

/// Reads the whole file, up to `limit` bytes; false with `why` set otherwise.
bool read_bytes(const fs::path& p, std::uintmax_t limit, std::vector<std::uint8_t>& out,
                std::string& why) {
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) {
    why = "no such file";
    return false;
  }
  const std::uintmax_t size = fs::file_size(p, ec);
  if (ec || size > limit) {
    why = ec ? ec.message() : "larger than " + std::to_string(limit) + " bytes";
    return false;
  }
  std::ifstream in(p, std::ios::binary);
  out.resize(static_cast<std::size_t>(size));
  if (!in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(size))) {
    why = "cannot read the file";
    return false;
  }
  return true;
}

/// Loads the texture `ref` of the mesh at `path` (embedded, or a file beside the mesh).
/// A texture file found is recorded in `files`, read or not; `by_name` is set when it was found
/// by its file name alone, beside the mesh, and not where `ref` says.
bool load_texture(const aiScene& scene, const std::string& path, const std::string& ref,
                  std::uint64_t budget, Texture& t, std::string& why,
                  std::vector<std::string>& files, bool& by_name) {
  const std::uint64_t max_texels = budget / 3;
  const auto side = import_protocol::kMaxTextureSide;
  if (const aiTexture* e = scene.GetEmbeddedTexture(ref.c_str())) {
    if (e->mHeight == 0)  // compressed: mWidth bytes of a PNG, JPEG, ... file
      return decode_image(reinterpret_cast<const std::uint8_t*>(e->pcData), e->mWidth, max_texels,
                          side, t, why);
    const std::uint64_t w = e->mWidth, h = e->mHeight;
    if (w > side || h > side || w * h > max_texels) {
      why = "the embedded image is too large";
      return false;
    }
    t.width = e->mWidth, t.height = e->mHeight;
    t.texels.resize(3 * w * h);
    for (std::size_t i = 0; i < w * h; ++i) {
      t.texels[3 * i] = e->pcData[i].r;
      t.texels[3 * i + 1] = e->pcData[i].g;
      t.texels[3 * i + 2] = e->pcData[i].b;
    }
    return true;
  }
  if (!ref.empty() && ref[0] == '*') {
    why = "no such embedded texture";
    return false;
  }
  // As written; with Windows separators turned round (".\\tex.jpg" in many OBJ files); and
  // the file name alone, beside the mesh (an absolute path from another machine, such as
  // "D:\\models\\wood.jpg", or a folder that was not copied along).
  const fs::path dir = fs::path(path).parent_path();
  std::string slashed = ref;
  std::replace(slashed.begin(), slashed.end(), '\\', '/');
  fs::path file;
  by_name = false;
  const fs::path tries[3] = {fs::path(ref), fs::path(slashed), fs::path(slashed).filename()};
  for (int i = 0; i < 3; ++i) {
    file = tries[i].is_absolute() ? tries[i] : dir / tries[i];
    std::error_code ec;
    if (fs::is_regular_file(file, ec)) {
      files.push_back(file.string());
      by_name = i == 2 && tries[2] != tries[1];
      break;
    }
  }
  std::vector<std::uint8_t> bytes;
  if (!read_bytes(file, std::uintmax_t{1} << 30, bytes, why)) return false;
  return decode_image(bytes.data(), bytes.size(), max_texels, side, t, why);
}

const char* light_kind(aiLightSourceType t) {
  switch (t) {
    case aiLightSource_SPOT:
      return "spot";
    case aiLightSource_AREA:
      return "area";
    case aiLightSource_AMBIENT:
      return "ambient";
    default:
      return "undefined";
  }
}

bool finite(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// The file's perspective cameras placed by their nodes, into `out.cameras`; what cannot be
/// used, into `notes`.
void read_cameras(const aiScene& scene, const std::string& path, bool gltf, Notes& notes,
                  ImportedMesh& out) {
  constexpr float kDeg = 180.0f / std::numbers::pi_v<float>;
  std::string ext = fs::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const bool three_ds = ext == ".3ds" || ext == ".prj";
  for (unsigned i = 0; i < scene.mNumCameras; ++i) {
    const aiCamera* c = scene.mCameras[i];
    if (c == nullptr) continue;
    const std::string name = quoted(c->mName);
    const aiNode* node = scene.mRootNode ? scene.mRootNode->FindNode(c->mName) : nullptr;
    if (three_ds) {
      // Assimp 5.2 adds a 3DS camera's position twice (node and mPosition) and loses its
      // target: the view it gives looks away from the scene.
      notes.add("3DS cameras not used (Assimp misplaces them)", name);
      continue;
    }
    if (c->mHorizontalFOV == 0.0f || c->mOrthographicWidth > 0.0f) {
      notes.add("orthographic cameras not supported, not used", name);
      continue;
    }
    if (node == nullptr) {
      notes.add("cameras placed by no node, not used", name);
      continue;
    }
    const aiMatrix4x4 g = global_transform(node);
    const float aspect = c->mAspect > 0.0f ? c->mAspect : 1.0f;
    Camera cam;
    if (gltf) {
      // Assimp 5.2's glTF 2 importer stores yfov * aspectRatio as the horizontal field of view
      // (yfov when there is no aspect ratio), and the node's translation as mPosition although
      // the node transform holds it too: a glTF camera sits at its node's origin, looking down
      // its -z axis with +y up.
      cam.vfov_deg = c->mHorizontalFOV / aspect * kDeg;
      cam.position = point(g, aiVector3D(0, 0, 0));
    } else {
      // The other importers (Collada, FBX, OpenGEX, 3DS, ...) store the full horizontal angle
      // (Collada's yfov 37.85 at aspect 1.5 comes as 54.43 degrees), mPosition, mLookAt and
      // mUp in the node's space; without an aspect ratio the film is taken as square.
      cam.vfov_deg = 2.0f * std::atan(std::tan(0.5f * c->mHorizontalFOV) / aspect) * kDeg;
      cam.position = point(g, c->mPosition);
    }
    const Vec3 dir = vector(g, c->mLookAt), up = vector(g, c->mUp);
    const float scale = std::max(1.0f, max_component(abs(cam.position)));
    if (!(cam.vfov_deg > 0.0f && cam.vfov_deg < 180.0f) || !finite(cam.position) || !finite(dir) ||
        !(length(dir) > 0.0f) || !finite(up) ||
        !(length(cross(dir, up)) > 1e-6f * length(dir) * length(up))) {
      notes.add("cameras with a degenerate transform or field of view, not used", name);
      continue;
    }
    cam.look_at = cam.position + normalize(dir) * scale;
    cam.up = normalize(up);
    out.cameras.push_back({one_line(c->mName.C_Str(), 200), cam});
  }
}

}  // namespace

void read_cameras_lights(const aiScene& scene, const std::string& path, bool gltf,
                         ImportedMesh& out) {
  Notes notes(path);
  read_cameras(scene, path, gltf, notes, out);
  for (unsigned i = 0; i < scene.mNumLights; ++i) {
    const aiLight* l = scene.mLights[i];
    if (l == nullptr) continue;
    const std::string name = quoted(l->mName);
    if (l->mType != aiLightSource_POINT && l->mType != aiLightSource_DIRECTIONAL &&
        l->mType != aiLightSource_SPOT) {
      notes.add(std::string(light_kind(l->mType)) + " lights not supported, not used", name);
      continue;
    }
    const aiNode* node = scene.mRootNode ? scene.mRootNode->FindNode(l->mName) : nullptr;
    const aiMatrix4x4 g = node ? global_transform(node) : aiMatrix4x4();
    Light light;
    light.intensity = {l->mColorDiffuse.r, l->mColorDiffuse.g, l->mColorDiffuse.b};
    if (l->mType == aiLightSource_POINT || l->mType == aiLightSource_SPOT) {
      light.kind = l->mType == aiLightSource_SPOT ? LightKind::kSpot : LightKind::kPoint;
      light.position = point(g, l->mPosition);
      if (l->mType == aiLightSource_SPOT) {
        // Assimp's cone angles are glTF's: half-angles from the axis, in radians.
        const Vec3 d = vector(g, l->mDirection);
        light.direction = length(d) > 0.0f ? normalize(d) : Vec3{};
        const float outer = std::clamp(l->mAngleOuterCone, 0.0f, 1.5707963f);
        const float inner = std::clamp(l->mAngleInnerCone, 0.0f, outer);
        light.cos_inner = std::cos(inner), light.cos_outer = std::cos(outer);
      }
      if (l->mAttenuationConstant != 0.0f || l->mAttenuationLinear != 0.0f)
        notes.add("light falloff rendered as inverse-square instead of the file's, lights", name);
      if (node && node->mMetaData && node->mMetaData->HasKey("PBR_LightRange"))
        notes.add("light ranges ignored (inverse-square falloff without cut-off), lights", name);
    } else {
      light.kind = LightKind::kDirectional;
      const Vec3 d = vector(g, l->mDirection);
      light.direction = length(d) > 0.0f ? normalize(d) : Vec3{};
    }
    if (!finite(light.position) || !finite(light.intensity) || light.direction == Vec3{} ||
        std::min({light.intensity.x, light.intensity.y, light.intensity.z}) < 0.0f) {
      notes.add("lights with a degenerate transform or a negative intensity, not used", name);
      continue;
    }
    out.lights.push_back(light);
  }
  notes.flush(out.dropped);
}

void note_unrendered(const aiScene& scene, const std::string& path, ImportedMesh& out) {
  Notes notes(path);
  for (unsigned i = 0; i < scene.mNumMaterials; ++i) {
    const aiMaterial* m = scene.mMaterials[i];
    if (m == nullptr) continue;
    const std::string name = material_name(*m, i);
    aiColor4D c;
    float f = 0.0f;
    if ((m->Get(AI_MATKEY_COLOR_EMISSIVE, c) == aiReturn_SUCCESS && c.r + c.g + c.b > 0.0f) ||
        m->GetTextureCount(aiTextureType_EMISSIVE) > 0 ||
        m->GetTextureCount(aiTextureType_EMISSION_COLOR) > 0)
      notes.add("emission not rendered, materials", name);
    if (m->Get(AI_MATKEY_TRANSMISSION_FACTOR, f) == aiReturn_SUCCESS && f > 0.0f)
      notes.add("transmission not rendered, materials", name);
    if (m->Get(AI_MATKEY_CLEARCOAT_FACTOR, f) == aiReturn_SUCCESS && f > 0.0f)
      notes.add("clearcoat not rendered, materials", name);
    if (m->Get(AI_MATKEY_SHEEN_COLOR_FACTOR, c) == aiReturn_SUCCESS)
      notes.add("sheen not rendered, materials", name);
    if (m->Get(AI_MATKEY_VOLUME_THICKNESS_FACTOR, f) == aiReturn_SUCCESS && f > 0.0f)
      notes.add("volumes not rendered, materials", name);
    aiString mode;
    if ((m->Get(AI_MATKEY_GLTF_ALPHAMODE, mode) == aiReturn_SUCCESS &&
         std::string(mode.C_Str()) != "OPAQUE") ||
        (m->Get(AI_MATKEY_OPACITY, f) == aiReturn_SUCCESS && f < 1.0f))
      notes.add("transparency not rendered (drawn opaque), materials", name);
    int shading = 0;
    if (m->Get(AI_MATKEY_SHADING_MODEL, shading) == aiReturn_SUCCESS) {
      if (shading == aiShadingMode_Unlit)
        notes.add("unlit materials shaded as lit", name);
      else if (shading != aiShadingMode_Flat && shading != aiShadingMode_Gouraud &&
               shading != aiShadingMode_Phong && shading != aiShadingMode_Blinn &&
               shading != aiShadingMode_PBR_BRDF)
        notes.add("shading models other than Phong or PBR rendered as Lambertian, materials", name);
    }
    const std::pair<aiTextureType, const char*> unused[] = {
        {aiTextureType_NORMALS, "normal"},
        {aiTextureType_HEIGHT, "height"},
        {aiTextureType_DISPLACEMENT, "displacement"},
        {aiTextureType_LIGHTMAP, "occlusion"},
        {aiTextureType_AMBIENT_OCCLUSION, "occlusion"},
        {aiTextureType_METALNESS, "metallic-roughness"},
        {aiTextureType_DIFFUSE_ROUGHNESS, "metallic-roughness"},
        {aiTextureType_SPECULAR, "specular"},
        {aiTextureType_SHININESS, "shininess"},
        {aiTextureType_OPACITY, "opacity"},
    };
    for (const auto& [type, what] : unused)
      if (m->GetTextureCount(type) > 0)
        notes.add(std::string(what) + " textures not used, materials", name);
    for (aiTextureType t : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
      aiUVTransform tr;
      if (m->GetTextureCount(t) > 0 && m->Get(AI_MATKEY_UVTRANSFORM(t, 0), tr) == aiReturn_SUCCESS)
        notes.add("texture transforms ignored, materials", name);
    }
  }
  for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
    const aiMesh* m = scene.mMeshes[i];
    if (m == nullptr) continue;
    const std::string name = m->mName.length ? quoted(m->mName) : numbered(i);
    if (m->HasVertexColors(0)) notes.add("vertex colours ignored, meshes", name);
    if (m->mNumBones > 0) notes.add("skins ignored (rest pose), meshes", name);
    if (m->mNumAnimMeshes > 0) notes.add("morph targets ignored, meshes", name);
  }
  for (unsigned i = 0; i < scene.mNumAnimations; ++i) {
    const aiAnimation* a = scene.mAnimations[i];
    notes.add("animations ignored (rest pose)",
              a && a->mName.length ? quoted(a->mName) : numbered(i));
  }
  notes.flush(out.dropped);
}

/// The wrap mode of texture `type` 0 of `m` along u (`v` false) or v.
static Wrap wrap_mode(const aiMaterial& m, aiTextureType type, bool v) {
  aiTextureMapMode mode = aiTextureMapMode_Wrap;
  const aiReturn got = v ? m.Get(AI_MATKEY_MAPPINGMODE_V(type, 0), mode)
                         : m.Get(AI_MATKEY_MAPPINGMODE_U(type, 0), mode);
  if (got != aiReturn_SUCCESS) return Wrap::kRepeat;
  return mode == aiTextureMapMode_Clamp || mode == aiTextureMapMode_Decal ? Wrap::kClamp
         : mode == aiTextureMapMode_Mirror                                ? Wrap::kMirror
                                                                          : Wrap::kRepeat;
}

std::vector<unsigned> read_materials(const aiScene& scene, const std::string& path,
                                     ImportedMesh& out) {
  Notes notes(path);
  std::vector<unsigned> channel;
  std::map<std::string, std::int32_t> loaded;  // texture reference -> index, or -1: failed
  std::uint64_t budget = import_protocol::kMaxTextureBytes;
  for (unsigned i = 0; i < scene.mNumMaterials; ++i) {
    Surface s;
    unsigned uv = 0;
    if (const aiMaterial* m = scene.mMaterials[i]) {
      // glTF: the base colour; specular-glossiness and other formats: the diffuse colour.
      const bool sg = is_spec_gloss(*m);
      aiColor4D c;
      if ((!sg && m->Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS) ||
          m->Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
        s.colour = {clamp01(c.r), clamp01(c.g), clamp01(c.b)};
      // Phong materials (OBJ's Ks and Ns): the specular lobe's weight and exponent.
      int shading = 0;
      aiColor4D ks;
      float ns = 0.0f, strength = 1.0f;
      if (m->Get(AI_MATKEY_SHADING_MODEL, shading) == aiReturn_SUCCESS &&
          (shading == aiShadingMode_Phong || shading == aiShadingMode_Blinn) &&
          m->Get(AI_MATKEY_COLOR_SPECULAR, ks) == aiReturn_SUCCESS &&
          m->Get(AI_MATKEY_SHININESS, ns) == aiReturn_SUCCESS && ns > 0.0f) {
        m->Get(AI_MATKEY_SHININESS_STRENGTH, strength);
        const float top = std::max({ks.r, ks.g, ks.b}), low = std::min({ks.r, ks.g, ks.b});
        s.reflectance = clamp01(top * strength);
        s.shininess = std::isfinite(ns) ? std::clamp(ns, 1.0f, 1e4f) : 32.0f;
        if (s.reflectance > 0.0f && top - low > 0.01f * top)
          notes.add("coloured specular rendered grey (its largest component), materials",
                    material_name(*m, i));
      }
      aiString ref;
      aiTextureType type = aiTextureType_BASE_COLOR;
      if ((!sg && m->GetTexture(type, 0, &ref, nullptr, &uv) == aiReturn_SUCCESS) ||
          m->GetTexture(type = aiTextureType_DIFFUSE, 0, &ref, nullptr, &uv) == aiReturn_SUCCESS) {
        const Wrap wrap_u = wrap_mode(*m, type, false), wrap_v = wrap_mode(*m, type, true);
        // One image under two samplers is two textures (rare; the texels are copied).
        const std::string key = std::string(ref.C_Str()) + '\0' +
                                std::to_string(static_cast<int>(wrap_u)) +
                                std::to_string(static_cast<int>(wrap_v));
        auto it = loaded.find(key);
        if (it == loaded.end()) {
          Texture t;
          std::string why;
          std::int32_t index = -1;
          bool by_name = false;
          const bool read =
              load_texture(scene, path, ref.C_Str(), budget, t, why, out.files_read, by_name);
          if (by_name)
            notes.add("textures not where the file says, read by file name beside it", quoted(ref));
          if (read) {
            budget -= t.texels.size();
            t.wrap_u = wrap_u, t.wrap_v = wrap_v;
            index = static_cast<std::int32_t>(out.textures.size());
            out.textures.push_back(std::move(t));
          } else {
            notes.add("textures that cannot be read (" + one_line(why, 200) +
                          "), rendered with their material's colour",
                      quoted(ref));
          }
          it = loaded.emplace(key, index).first;
        }
        s.texture = it->second;
      }
    }
    out.materials.push_back(s);
    channel.push_back(uv);
  }
  if (out.materials.empty()) out.materials.push_back(Surface{}), channel.push_back(0);
  notes.flush(out.dropped);
  return channel;
}

}  // namespace amalgam::assimp_scene
