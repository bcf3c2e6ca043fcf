// A scene file's memory limit holds before the bytes are spent: the document is sized before
// it is built, generated instances and subdivided meshes are totalled across entries before
// each is generated, and parsing takes time linear in the file.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "amalgam/io/json_reader.h"
#include "amalgam/io/scene_json.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;

/// A directory holding tri.obj (one triangle) and twelve.obj (a closed box of 12).
class SceneMemory : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("amalgam_scene_memory_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    std::ofstream(dir_ / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// read_scene_json's message on `text` under a limit of `mib` MiB, "" if it read it.
  std::string refusal(const std::string& text, double mib) const {
    const fs::path path = dir_ / "s.json";
    std::ofstream(path) << text;
    SceneFileConfig config;
    config.max_bytes = static_cast<std::uint64_t>(mib * (1 << 20));
    config.limit_name = "the test's limit";
    try {
      (void)read_scene_json(path.string(), config);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

const char* const kCamera =
    R"("camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]},
       "spheres": [{"centre": [0, 0, 0], "radius": 1}])";

// 60,000 small objects in a comment take about 12 MiB once parsed, 2 MiB as text: refused from
// a first pass that builds nothing, under a limit of 12 MiB that the text and the (empty) scene
// fit.
TEST_F(SceneMemory, TheDocumentIsSizedBeforeItIsBuilt) {
  std::string many = "[";
  for (int i = 0; i < 60000; ++i) many += std::string(i ? "," : "") + R"({"k": [1, 2]})";
  many += "]";
  const std::string text = std::string("{") + kCamera + R"(, "comment": )" + many + "}";
  const std::string m = refusal(text, 12);
  EXPECT_NE(m.find("its JSON needs about"), std::string::npos) << m;
  EXPECT_NE(m.find("the test's limit"), std::string::npos) << m;
  EXPECT_EQ(refusal(text, 64), "");
}

/// The peak resident set of this process so far, in bytes (each test is a process of its own
/// under ctest).
double peak_bytes() {
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_maxrss) * 1024.0;
}

// Three scatters of 7 million instances each (2.1e7 triangles, about 5 GiB by the estimate)
// under a limit of 100 MiB: refused from the entries' counts, before any transform is generated
// (each entry's 7 million transforms took 650 MiB, the three 1.9 GB, before the refusal).
TEST_F(SceneMemory, GeneratedInstancesAreTotalledBeforeAnyIsGenerated) {
  const std::string scatter = R"({"mesh": "t", "scatter": {"count": 7000000, "radius": 50}})";
  const std::string text = std::string("{") + kCamera +
                           R"(, "meshes": [{"name": "t", "file": "tri.obj", "place": false}],
      "instances": [)" + scatter +
                           ", " + scatter + ", " + scatter + "]}";
  const double before = peak_bytes();
  const std::string m = refusal(text, 100);
  EXPECT_NE(m.find("the scene needs about"), std::string::npos) << m;
  EXPECT_LT(peak_bytes() - before, 200.0 * (1 << 20));
}

// Each of 40 entries of one mesh subdivided 7 times (16,384 triangles, about 1 MiB) fits a
// limit of 16 MiB; all of them, each a copy, do not.
TEST_F(SceneMemory, SubdividedMeshesAreTotalledAcrossEntries) {
  std::string meshes;
  for (int i = 0; i < 40; ++i)
    meshes += std::string(i ? "," : "") + R"({"name": "m)" + std::to_string(i) +
              R"(", "file": "tri.obj", "subdivide": 7, "place": false})";
  const std::string text = std::string("{") + kCamera + R"(, "meshes": [)" + meshes + "]}";
  const std::string m = refusal(text, 16);
  EXPECT_NE(m.find("subdivide: the meshes so far, subdivided, need at least"), std::string::npos)
      << m;
}

// The file is read twice over (the stream and its copy): a file of more than half the limit is
// refused before it is read (6 MiB under 11 MiB; its document alone would fit).
TEST_F(SceneMemory, AFileBeyondHalfTheLimitIsRefusedBeforeItIsRead) {
  const std::string text =
      std::string("{") + kCamera + R"(, "comment": ")" + std::string(6 << 20, 'x') + "\"}";
  const std::string m = refusal(text, 11);
  EXPECT_NE(m.find("reading the file needs"), std::string::npos) << m;
}

// Parsing is linear in the number of objects: 400,000 objects in one array took nlohmann's
// callback parser (which rescans the array at the end of every object) about a minute; a
// linear parse takes well under a second (a bound 30x that, for sanitizers and loaded
// machines).
TEST(SceneJsonParse, AnArrayOfManyObjectsParsesInLinearTime) {
  std::string text = "[";
  for (int i = 0; i < 400000; ++i) text += i ? ",{\"a\":1}" : "{\"a\":1}";
  text += "]";
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(parse_json(text, "f.json").size(), 400000u);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30));
}

}  // namespace
}  // namespace amalgam
