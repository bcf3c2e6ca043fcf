#pragma once
/// \file Helpers shared by the libFuzzer targets (fuzz/*_fuzz.cpp).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace amalgam::fuzz {

/// A file in the temporary directory named after this process, removed on destruction, that
/// holds `size` bytes of `data`. One per target and extension, so parallel fuzzers
/// (-jobs/-workers) never share a file.
class TempFile {
 public:
  TempFile(const std::string& stem, const std::string& extension, const std::uint8_t* data,
           std::size_t size)
      : path_((std::filesystem::temp_directory_path() /
               (stem + "-" + std::to_string(::getpid()) + extension))
                  .string()) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  ~TempFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace amalgam::fuzz
