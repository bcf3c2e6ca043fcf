#include "amalgam/io/assimp_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "amalgam/io/assimp_scene.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

/// Assimp's messages can span lines; the contract wants one line, kept whole (one_line).
constexpr std::size_t kUncut = std::string::npos;
/// Generated normals (ImportConfig::smooth_normals) are split where faces meet at more than
/// this angle in degrees, so a cube keeps its edges and a tessellated sphere is smooth.
constexpr float kSmoothingAngle = 80.0f;

/// Collects Assimp's warnings and errors instead of printing them.
class CaptureLogger : public Assimp::Logger {
 public:
  std::vector<std::string> errors, warnings;
  bool attachStream(Assimp::LogStream*, unsigned) override { return false; }
  bool detachStream(Assimp::LogStream*, unsigned) override { return false; }

 private:
  void OnDebug(const char*) override {}
  void OnVerboseDebug(const char*) override {}
  void OnInfo(const char*) override {}
  void OnWarn(const char* m) override { warnings.push_back(one_line(m, kUncut)); }
  void OnError(const char* m) override { errors.push_back(one_line(m, kUncut)); }
};

/// Assimp's file access, noting every file it opens besides the mesh itself (an OBJ's
/// material library, a glTF's buffers and images): inputs an output must never replace.
class RecordingIO : public Assimp::DefaultIOSystem {
 public:
  RecordingIO(std::string mesh, std::vector<std::string>& read)
      : mesh_(std::move(mesh)), read_(read) {}
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    Assimp::IOStream* stream = Assimp::DefaultIOSystem::Open(file, mode);
    if (stream != nullptr && file != nullptr && file != mesh_ &&
        std::find(read_.begin(), read_.end(), file) == read_.end())
      read_.emplace_back(file);
    return stream;
  }

 private:
  std::string mesh_;
  std::vector<std::string>& read_;
};

/// Log messages by which Assimp reports that it dropped or replaced corrupt data. Other
/// messages (e.g. about invalid normals, which amalgam does not use) are harmless.
constexpr const char* kCorruptionMessages[] = {
    "out-of-range indices",               // glTF 2: faces referencing missing vertices
    "Ignoring empty face",                // OBJ: an 'f' statement without vertices
    "was not compatible with the",        // glTF 2: vertex count does not fit the mode
    "Invalid face index",                 // OBJ
    "fails on mesh positions",            // FindInvalidData: NaN or infinite vertex positions
    "OFF: Vertex index is out of range",  // replaced by the last vertex
    "OFF: Faces with zero indices",       // the face dropped
    "OFF: The number of faces in the header is incorrect",
    "Unable to parse property instance",  // PLY: a line shorter than its properties say
};

/// Points and lines are dropped; files are opened through a RecordingIO noting them in `read`.
void set_up(Assimp::Importer& importer, const std::string& path, std::vector<std::string>& read) {
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetIOHandler(new RecordingIO(path, read));  // owned by the importer
}

bool is_gltf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gltf" || ext == ".glb";
}

}  // namespace

std::string out_of_memory_message(const std::string& path, const ImportConfig& config) {
  return path + ": the importer ran out of memory under " + config.limit_name +
         " (is the file corrupt?)";
}

ImportedMesh import_with_assimp(const std::string& path, const ImportConfig& config) {
  auto* logger = new CaptureLogger;  // owned by Assimp until set(nullptr) below
  Assimp::DefaultLogger::set(logger);
  struct Restore {
    ~Restore() { Assimp::DefaultLogger::set(nullptr); }  // deletes `logger`, back to silence
  } restore;

  Assimp::Importer importer;
  constexpr unsigned kFlags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                              aiProcess_PreTransformVertices | aiProcess_SortByPType |
                              aiProcess_FindInvalidData | aiProcess_ValidateDataStructure;
  const aiScene* scene = nullptr;
  ImportedMesh out;
  set_up(importer, path, out.files_read);
  try {
    // Read, then bake the node transforms: cameras and lights are placed by nodes, which
    // aiProcess_PreTransformVertices removes. (ReadFile runs the validation, then the other
    // steps in Assimp's fixed order: the same as one ReadFile with all the flags.)
    scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
    if (scene != nullptr && !(scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
      assimp_scene::read_cameras_lights(*scene, path, is_gltf(path), out);
      assimp_scene::note_unrendered(*scene, path, out);
      // Generated normals only for meshes without (Assimp leaves a mesh's own alone).
      if (config.smooth_normals)
        importer.SetPropertyFloat(AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, kSmoothingAngle);
      scene = importer.ApplyPostProcessing(
          (kFlags & ~aiProcess_ValidateDataStructure) |
          (config.smooth_normals ? unsigned{aiProcess_GenSmoothNormals} : 0u));
    }
  } catch (const std::bad_alloc&) {
    throw InputError(out_of_memory_message(path, config));
  } catch (const std::exception& e) {
    fail_input(path, "cannot import: " + one_line(e.what(), kUncut));
  }
  // Assimp repairs some corrupt data with no more than a log message, and fails on other
  // corrupt data with a message about the consequence ("No meshes remaining"): name the cause.
  for (const auto* messages : {&logger->errors, &logger->warnings})
    for (const std::string& m : *messages)
      for (const char* pattern : kCorruptionMessages)
        if (m.find(pattern) != std::string::npos) fail_input(path, "corrupt data: " + m);
  if (scene == nullptr) {
    std::string why = one_line(importer.GetErrorString(), kUncut);
    // Assimp catches an exception from a reader itself and keeps only its what().
    if (why.find("bad_alloc") != std::string::npos)
      throw InputError(out_of_memory_message(path, config));
    if (why.empty() && !logger->errors.empty()) why = logger->errors.front();
    fail_input(path, "cannot import: " + (why.empty() ? std::string("unknown error") : why));
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
    fail_input(path, "cannot import: the file holds no complete scene");

  out.warnings = std::move(logger->warnings);
  const std::vector<unsigned> channel = assimp_scene::read_materials(*scene, path, out);
  std::vector<std::uint32_t> untextured(out.materials.size(), ~0u);  // copies without texture

  std::uint64_t faces = 0;
  for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
    const aiMesh* m = scene->mMeshes[mi];
    if (m != nullptr && (m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) faces += m->mNumFaces;
  }
  if (faces > config.max_triangles)
    fail_input(path, std::to_string(faces) + " triangles, more than the limit of " +
                         std::to_string(config.max_triangles));
  out.triangles.reserve(faces);
  const bool textured = std::any_of(out.materials.begin(), out.materials.end(),
                                    [](const Surface& s) { return s.texture >= 0; });
  if (textured) out.uvs.reserve(faces);
  const bool smooth = std::any_of(scene->mMeshes, scene->mMeshes + scene->mNumMeshes,
                                  [](const aiMesh* m) { return m != nullptr && m->HasNormals(); });
  if (smooth) out.normals.reserve(faces);

  for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
    const aiMesh* m = scene->mMeshes[mi];
    if (m == nullptr || !(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || m->mVertices == nullptr)
      continue;
    const std::string where =
        "mesh " + std::to_string(mi) +
        (m->mName.length ? " ('" + one_line(m->mName.C_Str(), kUncut) + "')" : "");
    for (unsigned v = 0; v < m->mNumVertices; ++v) {
      const aiVector3D& p = m->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail_input(path,
                   where + ": vertex " + std::to_string(v) + " is not finite (NaN or infinite)");
    }
    std::uint32_t material = m->mMaterialIndex < out.materials.size() ? m->mMaterialIndex : 0;
    const aiVector3D* uv = nullptr;
    if (out.materials[material].texture >= 0) {
      const unsigned ch = channel[material];
      if (ch < AI_MAX_NUMBER_OF_TEXTURECOORDS && m->HasTextureCoords(ch)) {
        uv = m->mTextureCoords[ch];
      } else {  // nothing to sample the texture with: the material's colour alone
        if (untextured[material] == ~0u) {
          untextured[material] = static_cast<std::uint32_t>(out.materials.size());
          out.materials.push_back(out.materials[material]);
          out.materials.back().texture = -1;
        }
        out.dropped.push_back(path + ": " + where +
                              " has no texture coordinates for its material's texture: rendered "
                              "with the material's colour");
        material = untextured[material];
      }
    }
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const aiFace& face = m->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      Vec3 p[3];
      for (int k = 0; k < 3; ++k) {
        const unsigned idx = face.mIndices[k];
        if (idx >= m->mNumVertices)
          fail_input(path, where + ": face " + std::to_string(f) + " uses vertex " +
                               std::to_string(idx) + " of " + std::to_string(m->mNumVertices));
        const aiVector3D& q = m->mVertices[idx];
        p[k] = {q.x, q.y, q.z};
      }
      // Zero area (in double, so tiny but proper triangles survive).
      const double ux = double(p[1].x) - p[0].x, uy = double(p[1].y) - p[0].y,
                   uz = double(p[1].z) - p[0].z;
      const double vx = double(p[2].x) - p[0].x, vy = double(p[2].y) - p[0].y,
                   vz = double(p[2].z) - p[0].z;
      const double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
      if (!(cx * cx + cy * cy + cz * cz > 0.0)) {
        ++out.dropped_degenerate;
        continue;
      }
      out.triangles.push_back(Primitive::triangle(p[0], p[1], p[2], material));
      if (textured) {
        TexCoords tc;
        for (int k = 0; uv != nullptr && k < 3; ++k) {
          const aiVector3D& t = uv[face.mIndices[k]];
          tc.u[k] = std::isfinite(t.x) ? t.x : 0.0f;
          tc.v[k] = std::isfinite(t.y) ? t.y : 0.0f;
        }
        out.uvs.push_back(tc);
      }
      if (smooth) {
        VertexNormals vn;  // zero (faceted) unless all three are finite
        for (int k = 0; m->mNormals != nullptr && k < 3; ++k) {
          const aiVector3D& n = m->mNormals[face.mIndices[k]];
          vn.n[k] = {n.x, n.y, n.z};
        }
        for (const Vec3& n : vn.n)
          if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
            vn = VertexNormals{};
        out.normals.push_back(vn);
      }
      out.bounds.extend(p[0]);
      out.bounds.extend(p[1]);
      out.bounds.extend(p[2]);
    }
  }
  if (out.triangles.empty())
    fail_input(path, out.dropped_degenerate ? "all " + std::to_string(out.dropped_degenerate) +
                                                  " triangles have zero area"
                                            : std::string("contains no triangles"));
  return out;
}

}  // namespace amalgam
