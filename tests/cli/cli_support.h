#pragma once
// What the end-to-end tests of the `amalgam` binary share: running a shell command with its
// stdout captured, reading a file whole, a scratch directory per test process, and the sample
// count an interrupted render reports.

#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
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

/// "... holds N of M samples per pixel ..." in an interrupted render's stderr -> N (-1 if
/// absent). Parsed by hand, not with std::regex: GCC 12 warns inside <regex> under the
/// sanitizers (-Wmaybe-uninitialized in std::function).
inline int samples_held(const std::string& err) {
  const auto digits = [&](std::size_t& i) {
    const std::size_t from = i;
    while (i < err.size() && std::isdigit(static_cast<unsigned char>(err[i]))) ++i;
    return i > from;
  };
  const std::string head = "holds ", of = " of ", tail = " samples per pixel";
  for (std::size_t at = err.find(head); at != std::string::npos; at = err.find(head, at + 1)) {
    std::size_t i = at + head.size();
    const std::size_t n = i;
    if (!digits(i)) continue;
    const std::size_t n_end = i;
    if (err.compare(i, of.size(), of) != 0) continue;
    i += of.size();
    if (!digits(i) || err.compare(i, tail.size(), tail) != 0) continue;
    return std::stoi(err.substr(n, n_end - n));
  }
  return -1;
}

}  // namespace amalgam::test
