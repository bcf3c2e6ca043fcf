// Mesh import (Assimp), scene files (JSON) and how bad input of either kind is reported.

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../sanitized.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "test_models.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;
using test::kModels;

/// The directories of temp_dir, removed when the test process ends.
struct TempDirs {
  std::vector<fs::path> dirs;
  ~TempDirs() {
    std::error_code ec;
    for (const fs::path& d : dirs) fs::remove_all(d, ec);
  }
};
TempDirs g_temp_dirs;

/// A fresh directory for one test's files. Named by the process too: ctest runs tests in
/// parallel processes, and two of them (both ImportCli tests use "cli_log") must not remove
/// each other's files.
fs::path temp_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("amalgam_import_test_" + name + "_" + std::to_string(getpid()));
  g_temp_dirs.dirs.push_back(d);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << p;
}

/// The message of the InputError that `f` throws ("" and a test failure if it throws none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

LoadedScene load(const std::string& path) {
  return load_scene(path, Params(path));
}

RenderOptions tiny() {
  RenderOptions o;
  o.width = 40, o.height = 32, o.spp = 1, o.threads = 2;
  return o;
}

/// Fraction of pixels that differ from the background.
double coverage(const LoadedScene& s, const RenderOutput& r) {
  int hit = 0;
  for (const Vec3& c : r.image) hit += !(c == s.env.background);
  return static_cast<double>(hit) / static_cast<double>(r.image.size());
}

// -- real models ------------------------------------------------------------------------------

TEST(MeshImport, RealModelsLoadAndRender) {
  REQUIRE_MODELS();
  for (const char* rel : {"PLY/Wuson.ply", "OBJ/spider.obj",
                          "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}) {
    SCOPED_TRACE(rel);
    const std::string path = (kModels / rel).string();
    const auto t0 = std::chrono::steady_clock::now();
    const LoadedScene s = load(path);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GT(s.info().primitives, 1000);
    EXPECT_GE(s.info().levels, 3);
    EXPECT_EQ(s.env.lights.size(), 2u);
    // The stats' time_s.load and .build: measured (the import starts a helper process, so it
    // takes time), and together no longer than the whole call.
    EXPECT_GT(s.load_seconds, 0.0);
    EXPECT_GT(s.build_seconds, 0.0);
    EXPECT_LE(s.load_seconds + s.build_seconds, wall)
        << "load " << s.load_seconds << " s + build " << s.build_seconds << " s > " << wall;
    const RenderOutput r = render(s, tiny());
    const double cov = coverage(s, r);
    EXPECT_GT(cov, 0.03) << "the default camera should see the mesh";
    EXPECT_LT(cov, 0.95) << "the default camera should see all of the mesh";
    // The default camera's centre ray hits the mesh.
    const TraceOutput t = trace(s, tiny(), s.env.camera.centre_ray(40, 32));
    EXPECT_NE(t.hit.kind, TraceHit::Kind::kNone);
  }
}

// Assimp runs in a helper process (amalgam-import): a crash inside it (here: a stand-in helper,
// tests/io/fake_importer.cpp, aborts as Assimp 5.2 does on an assertion for some corrupt
// files) is one InputError naming the file, and the process that asked carries on (the next
// import, with the real helper, works).
TEST(MeshImport, AnImporterCrashIsAnInputError) {
  REQUIRE_MODELS();
  const std::string path = (kModels / "PLY/Wuson.ply").string();
  ImportConfig crashing;
  crashing.helper = AMALGAM_FAKE_IMPORTER;
  const std::string e = input_error([&] { (void)import_mesh(path, crashing); });
  EXPECT_EQ(e, path + ": the importer crashed on this file (signal 6); is it corrupt?");
  const ImportedMesh m = import_mesh(path);
  EXPECT_EQ(m.triangles.size(), 3732u);
  EXPECT_FALSE(m.materials.empty());
  EXPECT_FALSE(m.bounds.empty());
}

/// The message of the RuntimeError that `f` throws ("" and a test failure if it throws none).
template <class F>
std::string runtime_error(F&& f) {
  try {
    f();
  } catch (const RuntimeError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no RuntimeError thrown";
  return "";
}

// A helper that replies with more than it may, or in another protocol, is stopped (it would
// wait forever) and reaped; a helper that cannot be started is a RuntimeError (exit status 1),
// not bad input.
TEST(MeshImport, AMisbehavingOrMissingHelperIsStoppedAndReported) {
  const fs::path d = temp_dir("helper");
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  for (const char* name : {"too-many.obj", "other-protocol.obj"}) write_file(d / name, tri);
  ImportConfig fake;
  fake.helper = AMALGAM_FAKE_IMPORTER;
  fake.max_triangles = 1;
  const std::string too_many = (d / "too-many.obj").string();
  EXPECT_EQ(input_error([&] { (void)import_mesh(too_many, fake); }),
            too_many + ": the importer crashed on this file (signal 9); is it corrupt?");
  const std::string other =
      runtime_error([&] { (void)import_mesh((d / "other-protocol.obj").string(), fake); });
  EXPECT_EQ(other.rfind(fake.helper + ": not the mesh importer of this build", 0), 0u) << other;
  ImportConfig missing;
  missing.helper = (d / "no-such-helper").string();
  EXPECT_EQ(runtime_error([&] { (void)import_mesh(too_many, missing); }),
            missing.helper + ": cannot start the mesh importer: No such file or directory");
  // The environment variable names the helper when ImportConfig does not.
  ::setenv("AMALGAM_IMPORT_HELPER", AMALGAM_FAKE_IMPORTER, 1);
  const std::string e = input_error([&] { (void)import_mesh((d / "crash.obj").string()); });
  ::unsetenv("AMALGAM_IMPORT_HELPER");
  EXPECT_NE(e.find("no such file"), std::string::npos) << "checked before any helper: " << e;
  write_file(d / "crash.obj", tri);
  ::setenv("AMALGAM_IMPORT_HELPER", AMALGAM_FAKE_IMPORTER, 1);
  const std::string c = input_error([&] { (void)import_mesh((d / "crash.obj").string()); });
  ::unsetenv("AMALGAM_IMPORT_HELPER");
  EXPECT_NE(c.find("the importer crashed on this file (signal 6)"), std::string::npos) << c;
  EXPECT_EQ(import_mesh((d / "crash.obj").string()).triangles.size(), 1u);
}

// A helper that never answers (an importer caught in a loop, or blocked) is killed at the
// deadline (ImportConfig::timeout_seconds, else AMALGAM_IMPORT_TIMEOUT): one InputError, not a
// wait forever (it used to block amalgam for good).
TEST(MeshImport, AHelperThatNeverAnswersIsStoppedAtTheDeadline) {
  const fs::path d = temp_dir("deadline");
  const std::string mesh = (d / "never-answers.obj").string();
  write_file(mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ImportConfig fake;
  fake.helper = AMALGAM_FAKE_IMPORTER;
  fake.timeout_seconds = 0.5;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(input_error([&] { (void)import_mesh(mesh, fake); }),
            mesh +
                ": the importer did not finish within 0.5 s (is the file corrupt? "
                "AMALGAM_IMPORT_TIMEOUT sets the limit)");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  fake.timeout_seconds = 0;
  ::setenv("AMALGAM_IMPORT_TIMEOUT", "0.25", 1);
  const std::string by_env = input_error([&] { (void)import_mesh(mesh, fake); });
  ::setenv("AMALGAM_IMPORT_TIMEOUT", "soon", 1);
  const std::string bad_env = input_error([&] { (void)import_mesh(mesh, fake); });
  ::unsetenv("AMALGAM_IMPORT_TIMEOUT");
  EXPECT_NE(by_env.find("did not finish within 0.25 s"), std::string::npos) << by_env;
  EXPECT_EQ(bad_env, "AMALGAM_IMPORT_TIMEOUT=soon: expected seconds, a number in (0, 1e7]");
  // The real helper, well within its deadline.
  EXPECT_EQ(import_mesh(mesh).triangles.size(), 1u);
}

// The helper allocates no more than the memory limit it is given (RLIMIT_DATA): an import that
// needs more is one InputError naming the limit. Not under AddressSanitizer, whose shadow
// memory counts against RLIMIT_DATA (the helper does not set the limit there).
TEST(MeshImport, TheHelperStaysUnderTheMemoryLimit) {
  REQUIRE_MODELS();
  if (kSanitized) GTEST_SKIP() << "RLIMIT_DATA counts AddressSanitizer's shadow memory";
  const std::string path = (kModels / "PLY/Wuson.ply").string();
  ImportConfig small;
  small.max_bytes = 1 << 20;
  small.limit_name = "--max-memory 1 MiB";
  EXPECT_EQ(input_error([&] { (void)import_mesh(path, small); }),
            path +
                ": the importer ran out of memory under --max-memory 1 MiB (is the file "
                "corrupt?)");
  ImportConfig ample;
  ample.max_bytes = std::uint64_t{1} << 30;
  EXPECT_EQ(import_mesh(path, ample).triangles.size(), 3732u);
}

// Sizes and indices that Assimp 5.2 trusts or repairs without a word are refused before it
// reads, or from its own log: a 200-byte GLB whose chunk claims 2 GB (it allocated 2.1 GB and
// took 17 s to fail), a glTF byteOffset of -100, an OFF face index beyond the vertices, a PLY
// face list longer than its line (each of the last three rendered one triangle, exit 0).
TEST(BadInput, DeclaredSizesAndIndicesTheFileCannotHoldAreRefused) {
  const fs::path d = temp_dir("declared");
  auto le32 = [](std::uint32_t v) {
    std::string s(4, '\0');
    for (int i = 0; i < 4; ++i) s[i] = static_cast<char>(v >> (8 * i));
    return s;
  };
  std::string glb = "glTF" + le32(2) + le32(200) + le32(0x7ffffff0) + "JSON{}";
  glb.resize(200, ' ');
  write_file(d / "hostile.glb", glb);
  write_file(d / "short.glb", "glTF" + le32(2) + le32(4000) + le32(2) + "JSON{}");
  const std::string triangle =
      R"("scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
      R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)"
      R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],)";
  write_file(d / "view.gltf",
             R"({"asset":{"version":"2.0"},)" + triangle +
                 R"("bufferViews":[{"buffer":0,"byteOffset":-100,"byteLength":36}],)"
                 R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
                 R"("min":[0,0,0],"max":[1,1,0]}]})");
  write_file(d / "accessor.gltf",
             R"({"asset":{"version":"2.0"},)" + triangle +
                 R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                 R"("accessors":[{"bufferView":0,"byteOffset":1.5,"componentType":5126,)"
                 R"("count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})");
  write_file(d / "index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n");
  // Assimp 5.2 reads -1 and 2.5 as some vertex: these imported (two triangles) and rendered.
  write_file(d / "negative.off",
             "OFF 4 2 0\n# a comment\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 -1 2\n");
  write_file(d / "fraction.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n\n3 0 1 2\n3 1 2.5 2\n");
  write_file(d / "list.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n200 0 1 2\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"hostile.glb",
       "binary glTF: chunk 0 (at byte 12) ends at byte 2147483652, beyond the end of the file "
       "(200 bytes)"},
      {"short.glb",
       "binary glTF: the header's total length ends at byte 4000, beyond the end of the file "
       "(22 bytes)"},
      {"view.gltf", "bufferViews/0/byteOffset is -100, not a non-negative integer"},
      {"accessor.gltf", "accessors/0/byteOffset is 1.5, not a non-negative integer"},
      {"index.off",
       "face 0 has vertex index '9': expected a whole number below 3, the vertices the header "
       "declares"},
      {"negative.off",
       "face 1 has vertex index '-1': expected a whole number below 4, the vertices the header "
       "declares"},
      {"fraction.off",
       "face 1 has vertex index '2.5': expected a whole number below 4, the vertices the header "
       "declares"},
      {"list.ply",
       "corrupt data: Unable to parse property instance. Skipping this element instance"},
  };
  for (const auto& [name, problem] : cases) {
    const std::string path = (d / name).string();
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(input_error([&] { (void)import_mesh(path); }), path + ": " + problem);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5)) << name;
  }
  // The same files with sizes and indices in range import.
  write_file(d / "good.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_file(d / "good.gltf",
             R"({"asset":{"version":"2.0"},)" + triangle +
                 R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],)"
                 R"("accessors":[{"bufferView":0,"byteOffset":0,"componentType":5126,)"
                 R"("count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})");
  for (const char* name : {"good.off", "good.gltf"})
    EXPECT_EQ(import_mesh((d / name).string()).triangles.size(), 1u) << name;
}

/// The state letter of /proc/PID/stat ('S' sleeping, 'Z' zombie, ...), '?' once it is gone,
/// and the command name in `comm`.
char process_state(pid_t pid, std::string* comm = nullptr) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string id, name, state;
  if (!(stat >> id >> name >> state)) return '?';
  if (comm) *comm = name;
  return state[0];
}

// The real helper dies with the process that started it, even one killed with SIGKILL (which
// runs no clean-up). Here its parent is a shell, and it blocks opening a FIFO that nobody
// writes (import_mesh only ever passes regular files; the helper is run by hand here).
TEST(MeshImport, TheHelperDiesWithItsParent) {
  const fs::path d = temp_dir("orphan");
  const std::string fifo = (d / "never.obj").string(), pid_file = (d / "helper.pid").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::vector<std::string> args = {
      "/bin/sh",
      "-c",
      "\"$0\" --parent $$ --max-triangles 10 -- \"$1\" & echo $! > \"$2\"; wait",
      AMALGAM_IMPORT_HELPER,
      fifo,
      pid_file};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t shell = 0;
  ASSERT_EQ(::posix_spawn(&shell, "/bin/sh", nullptr, nullptr, argv.data(), environ), 0);
  pid_t helper = 0;
  std::string comm;
  for (int i = 0; i < 1000; ++i, ::usleep(10'000)) {
    std::ifstream in(pid_file);
    if (helper == 0 && !(in >> helper)) helper = 0;
    if (helper != 0 && process_state(helper, &comm) == 'S' && comm == "(amalgam-import)") break;
  }
  ASSERT_GT(helper, 0) << "the helper did not start";
  ASSERT_EQ(process_state(helper), 'S') << "the helper waits for the FIFO " << comm;
  ::kill(shell, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(shell, &status, 0), shell);
  // Gone, or a zombie if nothing reaps orphans here, within a few seconds.
  char state = 'S';
  for (int i = 0; i < 500 && state != '?' && state != 'Z'; ++i, ::usleep(10'000))
    state = process_state(helper);
  EXPECT_TRUE(state == '?' || state == 'Z') << "helper " << helper << " outlived its parent";
  if (state != '?' && state != 'Z') ::kill(helper, SIGKILL);
}

// Started with a --parent that is not its parent (it was orphaned before it could ask to die
// with it), the helper stops at once, writing nothing.
TEST(MeshImport, TheHelperStopsWhenItsParentIsAlreadyGone) {
  REQUIRE_MODELS();
  const std::string cmd = std::string(AMALGAM_IMPORT_HELPER) + " --parent 999999999 " +
                          "--max-triangles 10 -- " + (kModels / "PLY/Wuson.ply").string() +
                          " | wc -c";
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  int bytes = -1;
  EXPECT_EQ(std::fscanf(p, "%d", &bytes), 1);
  ::pclose(p);
  EXPECT_EQ(bytes, 0);
}

TEST(MeshImport, Gltf2BaseColours) {
  REQUIRE_MODELS();
  const ImportedMesh m =
      import_mesh((kModels / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb").string());
  EXPECT_EQ(m.triangles.size() + m.dropped_degenerate, 121496u);  // faces Assimp delivers
  bool coloured = false;  // the engine has cyan parts: base colour factors were read
  for (const Surface& s : m.materials)
    coloured =
        coloured || max_component(s.colour) - std::min({s.colour.x, s.colour.y, s.colour.z}) > 0.3f;
  EXPECT_TRUE(coloured);
  for (const Primitive& p : m.triangles) ASSERT_LT(p.material, m.materials.size());
}

TEST(MeshImport, DropsZeroAreaTrianglesAndRejectsNonFiniteVertices) {
  const fs::path d = temp_dir("degenerate");
  write_file(d / "two.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
             "f 1 2 3\nf 1 2 4\n");  // the second triangle is a segment
  const ImportedMesh m = import_mesh((d / "two.obj").string());
  EXPECT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.dropped_degenerate, 1u);
  EXPECT_EQ(m.bounds, (Bbox{{0, 0, 0}, {1, 1, 0}}));

  write_file(d / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  EXPECT_NE(input_error([&] { import_mesh((d / "flat.obj").string()); }).find("zero area"),
            std::string::npos);

  const std::string nan_ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n";
  write_file(d / "nan.ply", nan_ply);
  const std::string e = input_error([&] { import_mesh((d / "nan.ply").string()); });
  EXPECT_NE(e.find((d / "nan.ply").string()), std::string::npos) << e;

  write_file(d / "huge.off", "OFF\n99999999999 1 0\n0 0 0\n");
  EXPECT_NE(input_error([&] { import_mesh((d / "huge.off").string()); }).find("declares"),
            std::string::npos);
}

// -- bad input: every invalid test model is one clear InputError, never a crash ---------------

std::vector<fs::path> broken_models() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(kModels / "invalid"))
    if (e.is_regular_file()) out.push_back(e.path());
  out.push_back(kModels / "OFF/invalid.off");
  for (const char* dir :
       {"glTF2/IndexOutOfRange", "glTF2/BoxWithInfinites-glTF-Binary", "glTF2/MissingBin",
        "glTF2/SchemaFailures", "glTF2/wrongTypes", "glTF2/RecursiveNodes",
        "glTF2/IncorrectVertexArrays", "glTF2/TestNoRootNode"})
    for (const auto& e : fs::directory_iterator(kModels / dir)) {
      const std::string ext = e.path().extension().string();
      if (ext == ".gltf" || ext == ".glb") out.push_back(e.path());
    }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(BadInput, EveryBrokenModelIsOneInputErrorNamingTheFile) {
  REQUIRE_MODELS();
  const std::vector<fs::path> files = broken_models();
  EXPECT_GE(files.size(), 30u);
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    const std::string e = input_error([&] { load(f.string()); });
    EXPECT_EQ(e.rfind(f.string() + ": ", 0), 0u) << e;
    EXPECT_GT(e.size(), f.string().size() + 8) << "names the problem: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  }
}

TEST(BadInput, SpecificProblemsAreNamed) {
  REQUIRE_MODELS();
  auto error_of = [&](const char* rel) {
    return input_error([&] { load((kModels / rel).string()); });
  };
  EXPECT_NE(error_of("glTF2/IndexOutOfRange/IndexOutOfRange.gltf").find("out-of-range"),
            std::string::npos);
  EXPECT_NE(error_of("glTF2/MissingBin/BoxTextured.gltf").find("BoxTextured0.bin"),
            std::string::npos);
  EXPECT_NE(error_of("invalid/OutOfMemory.off").find("declares"), std::string::npos);
  EXPECT_NE(error_of("glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb").find("INF/NAN"),
            std::string::npos);
  EXPECT_NE(error_of("glTF2/wrongTypes/badNumber.gltf").find("number"), std::string::npos);
}

TEST(BadInput, EveryTestModelImportsOrIsAnInputError) {
  REQUIRE_MODELS();
  int ok = 0, rejected = 0;
  for (const auto& e : fs::recursive_directory_iterator(kModels)) {
    if (!e.is_regular_file()) continue;
    SCOPED_TRACE(e.path().string());
    try {
      const ImportedMesh m = import_mesh(e.path().string());
      ASSERT_FALSE(m.triangles.empty());
      ASSERT_TRUE(is_finite(m.bounds.lo) && is_finite(m.bounds.hi));
      ++ok;
    } catch (const InputError& err) {
      ASSERT_EQ(std::string(err.what()).rfind(e.path().string() + ": ", 0), 0u) << err.what();
      ++rejected;
    }
  }
  EXPECT_GT(ok, 250);  // about 310 of the package's 595 files hold triangles
  EXPECT_GT(rejected, 100);
}

TEST(BadInput, PathsThatAreNotFiles) {
  EXPECT_NE(input_error([] { load("/nonexistent/mesh.obj"); }).find("no such file"),
            std::string::npos);
  const fs::path d = temp_dir("notfile");
  EXPECT_NE(input_error([&] { import_mesh(d.string()); }).find("not a regular file"),
            std::string::npos);
}

TEST(BadInput, SetIsRejectedForPaths) {
  const fs::path d = temp_dir("set");
  write_file(d / "s.json", R"({"spheres": [{"centre": [0, 0, 0], "radius": 1}]})");
  Params p((d / "s.json").string());
  p.set("n=3");
  EXPECT_NE(input_error([&] { load_scene((d / "s.json").string(), p); }).find("'n'"),
            std::string::npos);
}

// -- scene files ------------------------------------------------------------------------------

std::string json_error(const std::string& text) {
  return input_error([&] { parse_scene_json(text, "scene.json"); });
}

TEST(SceneFile, ErrorsNameTheJsonPointer) {
  const std::string sphere = R"("spheres": [{"centre": [0, 0, 0], "radius": 1}])";
  EXPECT_EQ(json_error(R"({)" + sphere +
                       R"(, "lights": [{"type": "point", "position": [0,0,0],
                           "intensity": 3}]})"),
            "scene.json: /lights/0/intensity: expected an array of 3 numbers, found a number");
  EXPECT_EQ(json_error(R"({)" + sphere + R"(, "camera": {"look_at": [0, 0, 0]}})"),
            "scene.json: /camera: missing key 'position'");
  EXPECT_EQ(json_error(R"({"spheres": [{"centre": [0, 0, 0], "radius": 1, "radus": 2}]})")
                .rfind("scene.json: /spheres/0/radus: unknown key", 0),
            0u);
  EXPECT_EQ(json_error(R"({"spheres": [{"centre": [0, 0, 0], "radius": -1}]})"),
            "scene.json: /spheres/0/radius: expected a number > 0, found -1");
  EXPECT_EQ(json_error(R"({"spheres": {"centre": [0, 0, 0]}})"),
            "scene.json: /spheres: expected an array, found an object");
  EXPECT_EQ(json_error(R"({"spheres": [{"centre": [0, "x", 0], "radius": 1}]})")
                .rfind("scene.json: /spheres/0/centre: expected an array of 3 numbers", 0),
            0u);
  EXPECT_EQ(json_error(R"({"boxes": [{"min": [0, 0, 0], "max": [1, 1, 1], "material": "x"}]})"),
            "scene.json: /boxes/0/material: unknown material 'x' (no materials are defined)");
  EXPECT_EQ(json_error(R"({)" + sphere + R"(, "lights": [{"type": "area"}]})"),
            "scene.json: /lights/0/type: expected \"point\", \"directional\", \"spot\" or "
            "\"sky\", found \"area\"");
  EXPECT_EQ(json_error(R"({)" + sphere + R"(, "lights": [{"type": "spot"}]})"),
            "scene.json: /lights/0: missing key 'position'");
  EXPECT_EQ(
      json_error(R"({)" + sphere +
                 R"(, "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0],
                       "intensity": 1, "inner_deg": 50, "outer_deg": 40}]})"),
      "scene.json: /lights/0/inner_deg: expected a number in degrees, [0, outer_deg], found 50");
  EXPECT_EQ(json_error(R"({)" + sphere + R"(, "lights": [{"type": "sky"}, {"type": "sky"}]})"),
            "scene.json: /lights/1/type: a scene has at most one sky");
  EXPECT_EQ(json_error(R"({)" + sphere + R"(, "lights": [{"type": "sky", "map": "none.exr"}]})")
                .rfind("scene.json: /lights/0/map: ", 0),
            0u);
  EXPECT_EQ(json_error(R"({"instances": [{"mesh": "bunny", "grid": {}}]})"),
            "scene.json: /instances/0/mesh: no mesh named 'bunny' (no meshes are defined)");
  EXPECT_EQ(json_error(R"({"a/b": 1})").rfind("scene.json: /a~1b: unknown key", 0), 0u);
  EXPECT_EQ(json_error(R"([1, 2])"), "scene.json: top level: expected an object, found an array");
  EXPECT_EQ(json_error(R"({})").rfind("scene.json: top level: the scene has no geometry", 0), 0u);
  EXPECT_EQ(json_error(R"({)" + sphere + R"(, "camera": {"position": [0, 0, 1],
                       "look_at": [0, 0, 0], "vfov": 180}})"),
            "scene.json: /camera/vfov: expected a number in (0, 180) degrees, found 180");
}

TEST(SceneFile, SyntaxErrorsNameLineAndColumn) {
  const std::string e = json_error("{\n  \"spheres\": [\n    {\"centre\": [0, 0, 0],, }\n]}");
  EXPECT_EQ(e.rfind("scene.json: line 3, column 26: invalid JSON: ", 0), 0u) << e;
  const std::string eof = json_error("{\"spheres\": [");
  EXPECT_EQ(eof.rfind("scene.json: line 1, column ", 0), 0u) << eof;
  // Comments are allowed.
  EXPECT_NO_THROW(parse_scene_json(
      "// a sphere\n{\"spheres\": [{\"centre\": [0, 0, 0], \"radius\": 1}]}", "c.json"));
}

TEST(SceneFile, PrimitivesMaterialsCameraLights) {
  const SceneDescription d = parse_scene_json(R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vfov": 30},
    "background": [0.1, 0.2, 0.3],
    "lights": [{"type": "directional", "direction": [0, -2, 0], "intensity": [1, 1, 1]}],
    "materials": {"red": {"colour": [1, 0, 0], "reflectance": 0.5}},
    "spheres": [{"centre": [0, 0, 0], "radius": 1, "material": "red"}],
    "boxes": [{"min": [2, 0, 0], "max": [3, 1, 1]}],
    "triangles": [{"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "material": {"color": [0, 1, 0]}}]
  })",
                                              "p.json");
  ASSERT_EQ(d.prims.size(), 3u);
  EXPECT_EQ(d.env.camera.vfov_deg, 30.0f);
  EXPECT_EQ(d.env.background, (Vec3{0.1f, 0.2f, 0.3f}));
  ASSERT_EQ(d.env.lights.size(), 1u);
  EXPECT_EQ(d.env.lights[0].direction, (Vec3{0, -1, 0}));
  EXPECT_EQ(d.materials[d.prims[0].material].colour, (Vec3{1, 0, 0}));
  EXPECT_EQ(d.materials[d.prims[0].material].reflectance, 0.5f);
  EXPECT_EQ(d.prims[1].material, 0u);  // the default material
  EXPECT_EQ(d.materials[d.prims[2].material].colour, (Vec3{0, 1, 0}));
}

/// A unit right triangle in the xy plane as an OBJ file.
void write_triangle_obj(const fs::path& p) {
  write_file(p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
}

TEST(SceneFile, MeshesInstancesAndTransforms) {
  const fs::path d = temp_dir("instances");
  fs::create_directories(d / "m");
  write_triangle_obj(d / "m" / "tri.obj");
  write_file(d / "scene.json", R"({
    "materials": {"blue": {"colour": [0, 0, 1]}},
    "meshes": [
      {"name": "t", "file": "m/tri.obj", "place": false},
      {"file": "m/tri.obj", "transform": {"translate": [10, 0, 0], "scale": 2}}
    ],
    "instances": [
      {"mesh": "t", "transforms": [{"translate": [0, 5, 0]},
                                   {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 7], [0, 0, 0, 1]]}]},
      {"mesh": "t", "grid": {"nx": 3, "nz": 2, "spacing": 4}, "material": "blue"},
      {"mesh": "t", "scatter": {"count": 50, "radius": 3, "seed": 7, "centre": [0, -20, 0]},
       "transform": {"rotate_y_deg": 90}}
    ]
  })");
  const SceneDescription s = read_scene_json((d / "scene.json").string());
  ASSERT_EQ(s.prims.size(), 1u + 2u + 6u + 50u);
  // The placed mesh: scaled by 2, then moved by 10 in x.
  EXPECT_EQ(s.prims[0].b, (Vec3{12, 0, 0}));
  EXPECT_EQ(s.prims[1].a, (Vec3{0, 5, 0}));
  EXPECT_EQ(s.prims[2].a, (Vec3{0, 0, 7}));
  // Grid: 3 x 2 centred on the origin, spacing 4.
  EXPECT_EQ(s.prims[3].a, (Vec3{-4, 0, -2}));
  EXPECT_EQ(s.prims[8].a, (Vec3{4, 0, 2}));
  EXPECT_EQ(s.materials[s.prims[3].material].colour, (Vec3{0, 0, 1}));
  // Scatter: on the disc of radius 3 in the plane y = -20.
  for (std::size_t i = 9; i < s.prims.size(); ++i) {
    const Vec3 o = s.prims[i].a;
    EXPECT_EQ(o.y, -20.0f);
    EXPECT_LE(o.x * o.x + o.z * o.z, 9.0f + 1e-4f);
  }
  // Same seed, same scene.
  const SceneDescription again = read_scene_json((d / "scene.json").string());
  for (std::size_t i = 0; i < s.prims.size(); ++i) ASSERT_EQ(s.prims[i].a, again.prims[i].a);
  // Through load_scene: a hierarchy, a camera framing everything, default lights.
  const LoadedScene l = load((d / "scene.json").string());
  EXPECT_EQ(l.info().primitives, 59);
  EXPECT_EQ(l.env.lights.size(), 2u);
}

TEST(SceneFile, MeshErrorsNameThePointerAndTheMesh) {
  const fs::path d = temp_dir("mesherr");
  write_file(d / "bad.obj", "v 0 0 0\nf 1 2 3\n");
  write_file(d / "scene.json", R"({"meshes": [{"file": "bad.obj"}]})");
  const std::string e = input_error([&] { load((d / "scene.json").string()); });
  EXPECT_EQ(
      e.rfind((d / "scene.json").string() + ": /meshes/0/file: " + (d / "bad.obj").string() + ": ",
              0),
      0u)
      << e;
}

TEST(SceneFile, ExpandedTriangleLimit) {
  const fs::path d = temp_dir("limit");
  write_triangle_obj(d / "tri.obj");
  const std::string text = R"({"meshes": [{"name": "t", "file": ")" + (d / "tri.obj").string() +
                           R"(", "place": false}],
    "instances": [{"mesh": "t", "grid": {"nx": 1000, "nz": 1000, "spacing": 1}}]})";
  SceneFileConfig small;
  small.max_triangles = 1000;
  const std::string e = input_error([&] { parse_scene_json(text, "big.json", small); });
  EXPECT_EQ(e.rfind("big.json: /instances/0/grid: ", 0), 0u) << e;
  EXPECT_NE(e.find("limit"), std::string::npos) << e;
  // The default limit admits the million triangles.
  EXPECT_EQ(parse_scene_json(text, "big.json").prims.size(), 1'000'000u);
}

TEST(SceneFile, ExampleScenesLoad) {
  REQUIRE_MODELS();
  const fs::path dir = fs::path(AMALGAM_SOURCE_DIR) / "scenes";
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().string());
    EXPECT_NO_THROW(read_scene_json(e.path().string()));
    ++n;
  }
  EXPECT_GE(n, 2);
}

// -- the CLI ----------------------------------------------------------------------------------

/// Runs the built binary; returns its exit status, stderr in `err`.
int run_cli(const std::string& args, std::string& err) {
  const fs::path log = temp_dir("cli_log") / "stderr.txt";
  const std::string cmd = std::string(AMALGAM_BINARY) + " " + args + " 2> " + log.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  err.assign(std::istreambuf_iterator<char>(in), {});
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ImportCli, BadInputExitsTwoAndWritesNothing) {
  const fs::path d = temp_dir("cli");
  write_file(d / "bad.obj", "this is not a mesh\n");
  write_file(d / "bad.json", R"({"spheres": [{"centre": [0, 0, 0], "radius": "big"}]})");
  for (const fs::path& in : {d / "bad.obj", d / "bad.json"}) {
    SCOPED_TRACE(in.string());
    const fs::path out = d / "out.png";
    std::string err;
    EXPECT_EQ(
        run_cli("render " + in.string() + " --out " + out.string() + " --width 8 --height 8", err),
        2);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_NE(err.find(in.string()), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
}

TEST(ImportCli, RendersAMesh) {
  const fs::path d = temp_dir("cli_ok");
  write_file(d / "quad.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n");
  std::string err;
  EXPECT_EQ(run_cli("render " + (d / "quad.obj").string() + " --out " + (d / "q.png").string() +
                        " --width 16 --height 16 --spp 1",
                    err),
            0)
      << err;
  EXPECT_TRUE(fs::exists(d / "q.png"));
}

}  // namespace
}  // namespace amalgam
