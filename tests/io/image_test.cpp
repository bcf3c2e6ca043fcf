#include "amalgam/io/image.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace amalgam {
namespace {

namespace fs = std::filesystem;

/// A fresh directory under the system temporary directory, removed with its contents.
class ScopedTempDir {
 public:
  ScopedTempDir() {
    static std::atomic<int> counter{0};
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() / ("amalgam_image_test_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(stamp) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~ScopedTempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_))
      names.push_back(e.path().filename().string());
    return names;
  }

 private:
  fs::path path_;
};

double to_srgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

/// A small test image with distinct, non-trivial values in every channel.
std::vector<Vec3> test_pattern(int w, int h) {
  std::vector<Vec3> px;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      px.push_back({static_cast<float>(x) / static_cast<float>(w - 1),
                    static_cast<float>(y) / static_cast<float>(h - 1),
                    0.001f + 0.37f * static_cast<float>((x * 7 + y * 3) % 11) / 10.0f});
  return px;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ImageIoError& e) {
    return e.what();
  }
  return "";
}

TEST(Image, PngRoundTripWithinOneStepAfterSrgb) {
  ScopedTempDir dir;
  const int w = 13, h = 7;
  std::vector<Vec3> px = test_pattern(w, h);
  px[0] = {-0.5f, 2.0f, std::numeric_limits<float>::quiet_NaN()};  // clamped to [0, 1]
  const std::string path = dir.file("round.png");
  write_image(path, w, h, px);
  int rw = 0, rh = 0;
  const std::vector<Vec3> back = read_image(path, rw, rh);
  ASSERT_EQ(rw, w);
  ASSERT_EQ(rh, h);
  ASSERT_EQ(back.size(), px.size());
  for (std::size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double want = std::isnan(px[i][c]) ? 0.0 : to_srgb(px[i][c]);
      EXPECT_NEAR(to_srgb(back[i][c]), want, 1.0 / 255.0) << "pixel " << i << " channel " << c;
    }
  EXPECT_EQ(back[0].x, 0.0f);
  EXPECT_NEAR(back[0].y, 1.0f, 1e-6f);
}

TEST(Image, ExtensionIsCaseInsensitive) {
  ScopedTempDir dir;
  const std::vector<Vec3> px = test_pattern(4, 3);
  for (const char* name : {"upper.PNG", "mixed.Pfm", "upper.EXR"}) {
    const std::string path = dir.file(name);
    ASSERT_NO_THROW(write_image(path, 4, 3, px)) << name;
    int w = 0, h = 0;
    ASSERT_NO_THROW(read_image(path, w, h)) << name;
    EXPECT_EQ(w, 4);
    EXPECT_EQ(h, 3);
  }
}

TEST(Image, PfmRoundTripIsExact) {
  ScopedTempDir dir;
  const int w = 5, h = 4;
  std::vector<Vec3> px = test_pattern(w, h);
  px[1] = {-3.25f, 1e30f, 1e-30f};
  px[2] = {std::numeric_limits<float>::denorm_min(), 123456.789f, -0.0f};
  const std::string path = dir.file("exact.pfm");
  write_image(path, w, h, px);
  int rw = 0, rh = 0;
  const std::vector<Vec3> back = read_image(path, rw, rh);
  ASSERT_EQ(rw, w);
  ASSERT_EQ(rh, h);
  ASSERT_EQ(back.size(), px.size());
  for (std::size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(std::bit_cast<std::uint32_t>(back[i][c]), std::bit_cast<std::uint32_t>(px[i][c]))
          << "pixel " << i << " channel " << c;
}

TEST(Image, PfmLayoutIsLittleEndianBottomRowFirst) {
  ScopedTempDir dir;
  // 1 x 2 image: top pixel (1, 2, 3), bottom pixel (4, 5, 6).
  const std::string path = dir.file("layout.pfm");
  write_image(path, 1, 2, {{1, 2, 3}, {4, 5, 6}});
  const std::string bytes = read_bytes(path);
  const std::string header = "PF\n1 2\n-1.0\n";
  ASSERT_EQ(bytes.size(), header.size() + 6 * 4);
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  const float expected[6] = {4, 5, 6, 1, 2, 3};
  for (int i = 0; i < 6; ++i) {
    std::uint32_t bits = 0;
    for (int b = 0; b < 4; ++b)
      bits |=
          static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[header.size() + 4 * i + b]))
          << (8 * b);
    float v;
    std::memcpy(&v, &bits, 4);
    EXPECT_EQ(v, expected[i]) << "float " << i;
  }
}

TEST(Image, ReadsBigEndianGreyPfm) {
  ScopedTempDir dir;
  // 2 x 1 grey image, big-endian (positive scale): values 0.5 and -2.
  std::string data = "Pf\n2 1\n1.0\n";
  for (float v : {0.5f, -2.0f}) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int b = 3; b >= 0; --b) data.push_back(static_cast<char>((bits >> (8 * b)) & 0xff));
  }
  const std::string path = dir.file("grey.pfm");
  std::ofstream(path, std::ios::binary) << data;
  int w = 0, h = 0;
  const std::vector<Vec3> px = read_image(path, w, h);
  ASSERT_EQ(w, 2);
  ASSERT_EQ(h, 1);
  EXPECT_EQ(px[0], (Vec3{0.5f, 0.5f, 0.5f}));
  EXPECT_EQ(px[1], (Vec3{-2.0f, -2.0f, -2.0f}));
}

TEST(Image, ExrRoundTripIsExact) {
  ScopedTempDir dir;
  const int w = 9, h = 6;
  std::vector<Vec3> px = test_pattern(w, h);
  px[3] = {1000.5f, 0.0001f, 17.0f};
  px[4] = {2049.0f, 123456.0f, 1e30f};  // not representable in half
  const std::string path = dir.file("round.exr");
  write_image(path, w, h, px);
  int rw = 0, rh = 0;
  const std::vector<Vec3> back = read_image(path, rw, rh);
  ASSERT_EQ(rw, w);
  ASSERT_EQ(rh, h);
  ASSERT_EQ(back.size(), px.size());
  for (std::size_t i = 0; i < px.size(); ++i) EXPECT_EQ(back[i], px[i]) << "pixel " << i;
}

TEST(Image, UnsupportedExtensionThrows) {
  ScopedTempDir dir;
  const std::string path = dir.file("picture.bmp");
  const std::string msg = error_of([&] { write_image(path, 2, 2, test_pattern(2, 2)); });
  EXPECT_EQ(msg, path + ": unsupported image format '.bmp' (expected .png, .exr or .pfm)");
  EXPECT_NE(error_of([&] { write_image(dir.file("noext"), 2, 2, test_pattern(2, 2)); }), "");
  int w = 0, h = 0;
  EXPECT_THROW(read_image(path, w, h), ImageIoError);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Image, SizeMismatchThrows) {
  ScopedTempDir dir;
  EXPECT_THROW(write_image(dir.file("a.png"), 3, 3, test_pattern(2, 2)), ImageIoError);
  EXPECT_THROW(write_image(dir.file("b.pfm"), 0, 0, {}), ImageIoError);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Image, WritingIntoMissingDirectoryThrowsAndLeavesNothing) {
  ScopedTempDir dir;
  const fs::path missing = dir.path() / "no_such_dir";
  for (const char* name : {"x.png", "x.pfm", "x.exr"}) {
    const std::string path = (missing / name).string();
    const std::string msg = error_of([&] { write_image(path, 2, 2, test_pattern(2, 2)); });
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(missing));
  }
  EXPECT_TRUE(dir.entries().empty());
}

/// While alive, the process may not write files beyond `bytes` (RLIMIT_FSIZE binds root too)
/// and a write beyond fails with EFBIG instead of raising SIGXFSZ: an injected write error.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &lim), 0);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
};

/// Noise: incompressible, so every format needs about its raw size.
std::vector<Vec3> noise(int w, int h) {
  std::vector<Vec3> px;
  std::uint32_t s = 12345;
  auto next = [&] { return (s = s * 1664525u + 1013904223u) / 4294967296.0f; };
  for (int i = 0; i < w * h; ++i) px.push_back({next(), next(), next()});
  return px;
}

// Writing fails half-way (the file size limit stops it after 4 KiB): ImageIoError naming the
// file, the previous file intact, no temporary left, for every format; without the limit the
// same write succeeds (so the limit is what failed it).
TEST(Image, AWriteFailingHalfWayKeepsThePreviousFileAndNoTemporary) {
  ScopedTempDir dir;
  const std::vector<Vec3> px = noise(64, 64);  // >= 12 KiB in every format
  for (const char* name : {"x.png", "x.pfm", "x.exr"}) {
    SCOPED_TRACE(name);
    const std::string path = dir.file(name);
    std::ofstream(path, std::ios::binary) << "previous contents";
    std::string msg;
    {
      FileSizeLimit limit(4096);
      msg = error_of([&] { write_image(path, 64, 64, px); });
    }
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(read_bytes(path), "previous contents");
    EXPECT_EQ(dir.entries(), std::vector<std::string>{name}) << "a temporary was left";
    write_image(path, 64, 64, px);
    EXPECT_GT(fs::file_size(path), 4096u);
    fs::remove(path);
  }
}

// The destination is a directory: the temporary is written, the rename fails; the directory
// and its contents are untouched and the temporary is gone.
TEST(Image, ADestinationThatIsADirectoryIsUntouched) {
  ScopedTempDir dir;
  fs::create_directories(dir.path() / "x.png");
  std::ofstream(dir.path() / "x.png" / "inside") << "kept";
  const std::string path = dir.file("x.png");
  const std::string msg = error_of([&] { write_image(path, 6, 5, test_pattern(6, 5)); });
  EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
  EXPECT_TRUE(fs::is_directory(path));
  EXPECT_EQ(read_bytes((dir.path() / "x.png" / "inside").string()), "kept");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"x.png"}) << "a temporary was left";
}

TEST(Image, NoTemporaryFileLeftAfterSuccess) {
  ScopedTempDir dir;
  const std::vector<Vec3> px = test_pattern(6, 5);
  write_image(dir.file("a.png"), 6, 5, px);
  write_image(dir.file("a.pfm"), 6, 5, px);
  write_image(dir.file("a.exr"), 6, 5, px);
  // Overwriting an existing file replaces it.
  const std::string before = read_bytes(dir.file("a.png"));
  write_image(dir.file("a.png"), 6, 5, test_pattern(6, 5));
  EXPECT_EQ(read_bytes(dir.file("a.png")), before);
  write_image(dir.file("a.png"), 6, 5, std::vector<Vec3>(30, Vec3{1, 0, 0}));
  EXPECT_NE(read_bytes(dir.file("a.png")), before);
  const std::vector<std::string> names = dir.entries();
  EXPECT_EQ(names.size(), 3u);
  for (const std::string& n : names) EXPECT_EQ(n.find(".tmp-"), std::string::npos) << n;
}

TEST(Image, ReadingBadInputNamesTheFile) {
  ScopedTempDir dir;
  int w = 0, h = 0;
  const std::string missing = dir.file("missing.png");
  EXPECT_EQ(error_of([&] { read_image(missing, w, h); }).rfind(missing + ": ", 0), 0u);

  const std::string garbage = dir.file("garbage.png");
  std::ofstream(garbage, std::ios::binary) << "this is not a png";
  EXPECT_EQ(error_of([&] { read_image(garbage, w, h); }).rfind(garbage + ": ", 0), 0u);

  // A valid PNG cut short.
  const std::string truncated = dir.file("truncated.png");
  write_image(truncated, 16, 16, test_pattern(16, 16));
  const std::string png = read_bytes(truncated);
  std::ofstream(truncated, std::ios::binary | std::ios::trunc) << png.substr(0, png.size() / 2);
  EXPECT_EQ(error_of([&] { read_image(truncated, w, h); }).rfind(truncated + ": ", 0), 0u);

  const std::string short_pfm = dir.file("short.pfm");
  std::ofstream(short_pfm, std::ios::binary) << "PF\n4 4\n-1.0\n0123";
  EXPECT_EQ(error_of([&] { read_image(short_pfm, w, h); }).rfind(short_pfm + ": ", 0), 0u);

  const std::string bad_header = dir.file("bad.pfm");
  std::ofstream(bad_header, std::ios::binary) << "PF\n-4 x\n-1.0\n";
  EXPECT_EQ(error_of([&] { read_image(bad_header, w, h); }).rfind(bad_header + ": ", 0), 0u);

  const std::string bad_exr = dir.file("bad.exr");
  std::ofstream(bad_exr, std::ios::binary) << "not an exr file at all";
  EXPECT_EQ(error_of([&] { read_image(bad_exr, w, h); }).rfind(bad_exr + ": ", 0), 0u);
}

}  // namespace
}  // namespace amalgam
