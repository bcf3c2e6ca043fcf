// util/atomic_file.h (every file amalgam writes) and one_line (util/error.h).

#include "amalgam/util/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace amalgam {
namespace {

namespace fs = std::filesystem;

/// A fresh directory for one test, removed with its contents.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::temp_directory_path() /
              ("amalgam_atomic_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename());
    return names;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The what() of the RuntimeError that `f` throws ("" and a failure if none).
template <class F>
std::string runtime_error_of(F&& f) {
  try {
    f();
  } catch (const RuntimeError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no RuntimeError thrown";
  return "";
}

TEST(AtomicFile, WritesAndReplacesWithoutLeavingTemporaries) {
  TempDir dir("replace");
  const std::string path = dir.file("stats.json");
  write_file_atomic(path, "{\"x\": 1}\n");
  EXPECT_EQ(read_bytes(path), "{\"x\": 1}\n");
  write_file_atomic(path, std::string("a\0b", 3));
  EXPECT_EQ(read_bytes(path), std::string("a\0b", 3));
  write_atomically(path, [](AtomicFile& f) {
    f.write("through ");
    std::fputs("the stream", f.stream());
  });
  EXPECT_EQ(read_bytes(path), "through the stream");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"stats.json"});
}

TEST(AtomicFile, MissingDirectoryIsARuntimeErrorNamingThePath) {
  TempDir dir("missing");
  const std::string path = (dir.path() / "no_such_dir" / "out.json").string();
  EXPECT_EQ(runtime_error_of([&] { write_file_atomic(path, "{}"); }),
            path + ": the directory " + (dir.path() / "no_such_dir").string() + " does not exist");
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, AFailingBodyLeavesTheOldFileAndNoTemporary) {
  TempDir dir("body");
  const std::string path = dir.file("image.png");
  write_file_atomic(path, "old contents");
  std::string temp;
  const std::string e = runtime_error_of([&] {
    write_atomically(path, [&](AtomicFile& f) {
      temp = f.temp_path();
      EXPECT_TRUE(fs::exists(temp));
      EXPECT_EQ(fs::path(temp).parent_path(), dir.path()) << "same directory as the target";
      f.write("half of the new");
      throw std::runtime_error("encoding failed:\nline two  \n");
    });
  });
  EXPECT_EQ(e, path + ": encoding failed: line two");
  EXPECT_EQ(read_bytes(path), "old contents");
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"image.png"});
}

struct CodecError : RuntimeError {
  using RuntimeError::RuntimeError;
};

TEST(AtomicFile, ThrowsTheRequestedKindOfRuntimeError) {
  TempDir dir("kind");
  const std::string path = (dir.path() / "missing" / "x.pfm").string();
  EXPECT_THROW(write_atomically<CodecError>(path, [](AtomicFile&) {}), CodecError);
  EXPECT_THROW(
      write_atomically<CodecError>(dir.file("y.pfm"), [](AtomicFile&) { throw std::bad_alloc(); }),
      CodecError);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(OneLine, FlattensTrimsAndCuts) {
  EXPECT_EQ(one_line("a\nb\r\tc  \n"), "a b  c");
  EXPECT_EQ(one_line(std::string(200, 'x')).size(), 120u);
  EXPECT_EQ(one_line(std::string(200, 'x')).substr(117), "...");
  EXPECT_EQ(one_line(std::string(200, 'x'), std::string::npos), std::string(200, 'x'));
  EXPECT_EQ(one_line("abcdef", 5), "ab...");
}

}  // namespace
}  // namespace amalgam
