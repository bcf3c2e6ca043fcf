#include "amalgam/io/mesh_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <new>
#include <set>
#include <sstream>
#include <system_error>
#include <type_traits>
#include <vector>

#include "amalgam/builtin/params.h"

namespace amalgam {
namespace {

/// Assimp's messages can span lines; the contract wants one line, kept whole (one_line).
constexpr std::size_t kUncut = std::string::npos;

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path + ": " + problem);
}

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

/// Log messages by which Assimp reports that it dropped or replaced corrupt data. Other
/// messages (e.g. about invalid normals, which amalgam does not use) are harmless.
constexpr const char* kCorruptionMessages[] = {
    "out-of-range indices",         // glTF 2: faces referencing missing vertices
    "Ignoring empty face",          // OBJ: an 'f' statement without vertices
    "was not compatible with the",  // glTF 2: vertex count does not fit the mode
    "Invalid face index",           // OBJ
    "fails on mesh positions",      // FindInvalidData: NaN or infinite vertex positions
};

/// Some formats declare element counts in a text header and Assimp trusts them (the
/// testmodels' invalid/OutOfMemory.off declares 3.5e11 vertices and takes a minute to fail).
/// Rejects counts that the file's size cannot possibly hold.
void check_declared_counts(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".off" && ext != ".ply") {
    // Assimp also picks its PLY reader by content for other extensions.
    std::ifstream probe(path, std::ios::binary);
    char magic[4] = {};
    if (!probe.read(magic, 4) || std::string(magic, 3) != "ply" ||
        (magic[3] != '\n' && magic[3] != '\r'))
      return;
    ext = ".ply";
  }
  std::error_code ec;
  const auto size = static_cast<double>(std::filesystem::file_size(path, ec));
  if (ec) return;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  auto too_many = [&](double count, const char* what) {
    // Every vertex or face takes at least two bytes in any encoding Assimp reads.
    if (count * 2.0 > size) {
      std::ostringstream m;
      m << "the header declares " << count << " " << what << " but the file has only "
        << static_cast<std::uint64_t>(size) << " bytes";
      fail(path, m.str());
    }
  };
  if (ext == ".off") {
    // "OFF" (possibly with prefixes such as C, N, ST) then "nv nf ne", possibly on one line.
    std::string magic;
    if (!(in >> magic) || magic.find("OFF") == std::string::npos) return;
    std::string rest = magic.substr(magic.find("OFF") + 3);
    double nv = 0, nf = 0;
    std::istringstream counts(rest);
    if (!(counts >> nv >> nf) && !(in >> nv >> nf)) return;
    too_many(nv, "vertices");
    too_many(nf, "faces");
  } else {
    // The header grammar is checked: Assimp 5.2 crashes on some malformed headers (reads
    // past a header without end_header; asserts in its triangulation on faces read through a
    // garbled element or property line). Found by fuzz/mesh_fuzz.cpp; see
    // tests/fuzz_regressions_test.cpp.
    bool end = false;
    std::set<std::string> elements;
    int properties = 0;
    for (int i = 0; i < 100'000 && std::getline(in, line); ++i) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream words(line);
      std::vector<std::string> w;
      for (std::string word; words >> word;) w.push_back(word);
      const std::string kw = w.empty() ? "" : w[0];
      if (kw == "end_header" && w.size() == 1) {
        end = true;
        break;
      }
      // element and property lines exactly as the format says; other lines (format, comment,
      // and the bare comments that some exporters write, e.g. Wuson.ply's) must be text.
      // Elements have unique names and at least one property; property types are PLY's.
      static const std::set<std::string> kTypes = {
          "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
          "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
      bool ok =
          kw == "element" ? w.size() == 3 && elements.insert(w[1]).second &&
                                (properties > 0 || elements.size() == 1)
          : kw == "property"
              ? !elements.empty() &&
                    ((w.size() == 3 && kTypes.count(w[1])) ||
                     (w.size() == 5 && w[1] == "list" && kTypes.count(w[2]) && kTypes.count(w[3])))
              : true;
      // A garbled structural keyword ("property~", "elemen") is not a bare comment: Assimp
      // reads it as the keyword and miscounts the properties.
      for (const char* k : {"element", "property", "end_header", "format"}) {
        const std::string key = k;
        if (kw != key && !kw.empty() && (kw.starts_with(key) || key.starts_with(kw))) ok = false;
      }
      if (kw == "element") properties = 0;
      if (kw == "property") ++properties;
      for (char c : line)
        ok = ok && (c == '\t' ||
                    (static_cast<unsigned char>(c) >= 32 && static_cast<unsigned char>(c) < 127));
      if (!ok) {
        std::string shown = line.substr(0, 60);
        for (char& c : shown)
          if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
        fail(path, "malformed PLY header: line " + std::to_string(i + 1) + " is '" + shown + "'");
      }
      if (kw == "element") {
        double count = 0;
        std::istringstream(w[2]) >> count;
        too_many(count, "elements");
      }
    }
    if (!end) fail(path, "malformed PLY header: no 'end_header' line");
    if (!elements.empty() && properties == 0)
      fail(path, "malformed PLY header: the last element has no properties");
  }
}

float clamp01(float v) {
  return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.8f;
}

Surface read_material(const aiMaterial& m) {
  Surface s;
  aiColor4D c;
  if (m.Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS ||
      m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
    s.colour = {clamp01(c.r), clamp01(c.g), clamp01(c.b)};
  return s;
}

/// The import proper, in whatever process calls it (see import_mesh).
ImportedMesh import_here(const std::string& path, const ImportConfig& config) {
  auto* logger = new CaptureLogger;  // owned by Assimp until set(nullptr) below
  Assimp::DefaultLogger::set(logger);
  struct Restore {
    ~Restore() { Assimp::DefaultLogger::set(nullptr); }  // deletes `logger`, back to silence
  } restore;

  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  constexpr unsigned kFlags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                              aiProcess_PreTransformVertices | aiProcess_SortByPType |
                              aiProcess_FindInvalidData | aiProcess_ValidateDataStructure;
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path, kFlags);
  } catch (const std::bad_alloc&) {
    fail(path, "the importer ran out of memory (is the file corrupt?)");
  } catch (const std::exception& e) {
    fail(path, "cannot import: " + one_line(e.what(), kUncut));
  }
  // Assimp repairs some corrupt data with no more than a log message, and fails on other
  // corrupt data with a message about the consequence ("No meshes remaining"): name the cause.
  for (const auto* messages : {&logger->errors, &logger->warnings})
    for (const std::string& m : *messages)
      for (const char* pattern : kCorruptionMessages)
        if (m.find(pattern) != std::string::npos) fail(path, "corrupt data: " + m);
  if (scene == nullptr) {
    std::string why = one_line(importer.GetErrorString(), kUncut);
    if (why.empty() && !logger->errors.empty()) why = logger->errors.front();
    fail(path, "cannot import: " + (why.empty() ? std::string("unknown error") : why));
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
    fail(path, "cannot import: the file holds no complete scene");

  ImportedMesh out;
  out.warnings = std::move(logger->warnings);
  for (unsigned i = 0; i < scene->mNumMaterials; ++i)
    out.materials.push_back(scene->mMaterials[i] ? read_material(*scene->mMaterials[i])
                                                 : Surface{});
  if (out.materials.empty()) out.materials.push_back(Surface{});

  std::uint64_t faces = 0;
  for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
    const aiMesh* m = scene->mMeshes[mi];
    if (m != nullptr && (m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) faces += m->mNumFaces;
  }
  if (faces > config.max_triangles)
    fail(path, std::to_string(faces) + " triangles, more than the limit of " +
                   std::to_string(config.max_triangles));
  out.triangles.reserve(faces);

  for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
    const aiMesh* m = scene->mMeshes[mi];
    if (m == nullptr || !(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || m->mVertices == nullptr)
      continue;
    const std::string where = "mesh " + std::to_string(mi) +
                              (m->mName.length ? " ('" + one_line(m->mName.C_Str(), kUncut) + "')" : "");
    for (unsigned v = 0; v < m->mNumVertices; ++v) {
      const aiVector3D& p = m->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(path, where + ": vertex " + std::to_string(v) + " is not finite (NaN or infinite)");
    }
    const std::uint32_t material = m->mMaterialIndex < out.materials.size() ? m->mMaterialIndex : 0;
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const aiFace& face = m->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      Vec3 p[3];
      for (int k = 0; k < 3; ++k) {
        const unsigned idx = face.mIndices[k];
        if (idx >= m->mNumVertices)
          fail(path, where + ": face " + std::to_string(f) + " uses vertex " + std::to_string(idx) +
                         " of " + std::to_string(m->mNumVertices));
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
      out.bounds.extend(p[0]);
      out.bounds.extend(p[1]);
      out.bounds.extend(p[2]);
    }
  }
  if (out.triangles.empty())
    fail(path, out.dropped_degenerate
                   ? "all " + std::to_string(out.dropped_degenerate) + " triangles have zero area"
                   : std::string("contains no triangles"));
  return out;
}

// ---- running the importer in a child process ---------------------------------------------
// Assimp 5.2 still aborts or crashes on some corrupt files that no header check catches (the
// fuzzer keeps finding them: tests/fuzz_regressions_test.cpp). So the import runs in a forked
// child that sends the result, or the InputError's message, back through a pipe; a child that
// dies is a clean InputError in the parent ("the importer crashed").

bool write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w, n -= static_cast<std::size_t>(w);
  }
  return true;
}

bool read_all(int fd, void* data, std::size_t n) {
  char* p = static_cast<char*>(data);
  while (n > 0) {
    const ssize_t r = ::read(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r, n -= static_cast<std::size_t>(r);
  }
  return true;
}

/// Message framing: a status byte (0: mesh, 1: InputError message), then for a mesh the
/// counts and the raw arrays (Primitive, Surface and Bbox are trivially copyable), the warnings
/// as length-prefixed strings; for an error the message.
void send(int fd, const std::string& path, const ImportConfig& config) {
  static_assert(std::is_trivially_copyable_v<Primitive> && std::is_trivially_copyable_v<Surface> &&
                std::is_trivially_copyable_v<Bbox>);
  auto send_string = [&](const std::string& m) {
    const std::uint64_t n = m.size();
    return write_all(fd, &n, sizeof n) && write_all(fd, m.data(), m.size());
  };
  std::uint8_t status = 0;
  try {
    const ImportedMesh m = import_here(path, config);
    const std::uint64_t counts[4] = {m.triangles.size(), m.materials.size(), m.dropped_degenerate,
                                     m.warnings.size()};
    if (!write_all(fd, &status, 1) || !write_all(fd, counts, sizeof counts) ||
        !write_all(fd, m.triangles.data(), m.triangles.size() * sizeof(Primitive)) ||
        !write_all(fd, m.materials.data(), m.materials.size() * sizeof(Surface)) ||
        !write_all(fd, &m.bounds, sizeof m.bounds))
      return;
    for (const std::string& w : m.warnings)
      if (!send_string(w)) return;
  } catch (const std::exception& e) {
    status = 1;
    (void)(write_all(fd, &status, 1) && send_string(e.what()));
  }
}

}  // namespace

ImportedMesh import_mesh(const std::string& path, const ImportConfig& config) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(path, "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "not a regular file");
  check_declared_counts(path);

  // Assimp's logger is a process-wide singleton: one import at a time (the lock is held
  // across the fork, so the child never inherits it taken by another thread).
  static std::mutex mutex;
  const std::lock_guard lock(mutex);
  int fds[2];
  if (::pipe(fds) != 0) return import_here(path, config);  // no pipe: import in process
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    return import_here(path, config);
  }
  if (pid == 0) {  // the child: import, send, and leave without running exit handlers
    ::close(fds[0]);
    // Assimp's failed assertions print to stderr before aborting; the parent's one-line
    // error says what happened.
    if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, 2);
    // Lets tests/io/import_test.cpp exercise the crash path without a crashing file.
    if (std::getenv("AMALGAM_TEST_IMPORTER_ABORT")) std::abort();
    send(fds[1], path, config);
    ::close(fds[1]);
    ::_exit(0);
  }
  ::close(fds[1]);
  struct Reader {
    int fd;
    ~Reader() { ::close(fd); }
  } reader{fds[0]};
  auto reap = [&] {
    int st = 0;
    while (::waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    return st;
  };
  auto crashed = [&](int st) {
    std::string why = WIFSIGNALED(st) ? "signal " + std::to_string(WTERMSIG(st))
                                      : "exit status " + std::to_string(WEXITSTATUS(st));
    fail(path, "the importer crashed on this file (" + why + "); is it corrupt?");
  };
  auto read_string = [&](std::string& m) {
    std::uint64_t n = 0;
    if (!read_all(fds[0], &n, sizeof n) || n > (std::uint64_t{1} << 24)) return false;
    m.resize(n);
    return read_all(fds[0], m.data(), n);
  };
  std::uint8_t status = 2;
  if (!read_all(fds[0], &status, 1)) crashed(reap());
  if (status == 1) {
    std::string message;
    const bool ok = read_string(message);
    const int st = reap();
    if (!ok) crashed(st);
    throw InputError(message);
  }
  ImportedMesh out;
  std::uint64_t counts[4] = {};
  bool ok = status == 0 && read_all(fds[0], counts, sizeof counts) &&
            counts[0] <= config.max_triangles && counts[1] <= (std::uint64_t{1} << 32);
  if (ok) {
    out.triangles.resize(counts[0]);
    out.materials.resize(counts[1]);
    out.dropped_degenerate = counts[2];
    ok = read_all(fds[0], out.triangles.data(), counts[0] * sizeof(Primitive)) &&
         read_all(fds[0], out.materials.data(), counts[1] * sizeof(Surface)) &&
         read_all(fds[0], &out.bounds, sizeof out.bounds);
    for (std::uint64_t i = 0; ok && i < counts[3]; ++i) {
      std::string w;
      ok = read_string(w);
      out.warnings.push_back(std::move(w));
    }
  }
  const int st = reap();
  if (!ok || !WIFEXITED(st) || WEXITSTATUS(st) != 0) crashed(st);
  return out;
}

}  // namespace amalgam
