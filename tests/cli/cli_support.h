#pragma once
// What the end-to-end tests of the `amalgam` binary share: running a shell command with its
// stdout captured, reading a file whole, and a scratch directory per test process.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

namespace amalgam::test {

struct CommandResult {
  int status;  ///< exit status, or -1 if the command did not exit (a signal)
  std::string out;
};

/// Runs `cmd` with /bin/sh; returns its exit status and everything it wrote to stdout.
inline CommandResult run_command(const std::string& cmd) {
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, {}};
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

/// The bytes of file `p` ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A scratch directory of this test process, "<tmp>/<prefix>-<pid>", created on first use and
/// removed with everything in it when the process ends. One per prefix.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
  struct Scratch {
    std::filesystem::path dir;
    ~Scratch() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  };
  static std::map<std::string, Scratch> dirs;  // removed at exit
  Scratch& s = dirs[prefix];
  if (s.dir.empty())
    s.dir = std::filesystem::temp_directory_path() / (prefix + "-" + std::to_string(getpid()));
  std::filesystem::create_directories(s.dir);
  return s.dir;
}

}  // namespace amalgam::test
