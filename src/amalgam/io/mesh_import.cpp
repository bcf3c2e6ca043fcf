#include "amalgam/io/mesh_import.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <stop_token>
#include <system_error>
#include <thread>
#include <vector>

#include "amalgam/io/import_protocol.h"
#include "amalgam/io/mesh_check.h"
#include "amalgam/util/error.h"

extern char** environ;

namespace amalgam {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int err) {
  return std::error_code(err, std::generic_category()).message();
}

std::mutex& registered_mutex() {
  static std::mutex m;
  return m;
}

std::string& registered_helper() {
  static std::string path;
  return path;
}

/// The file of the executable or shared object that holds this code.
fs::path this_object() {
  Dl_info info{};
  if (::dladdr(reinterpret_cast<const void*>(&this_object), &info) == 0 ||
      info.dli_fname == nullptr)
    return {};
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(info.dli_fname, ec);
  return ec ? fs::path() : p;
}

/// The helper to run (see ImportConfig::helper).
std::string find_helper(const ImportConfig& config) {
  if (!config.helper.empty()) return config.helper;
  if (const char* env = std::getenv("AMALGAM_IMPORT_HELPER"); env != nullptr && *env != '\0')
    return env;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  std::vector<fs::path> candidates;
  if (!self.empty()) candidates.push_back(self.parent_path() / "amalgam-import");
  {
    const std::lock_guard lock(registered_mutex());
    if (!registered_helper().empty()) candidates.emplace_back(registered_helper());
  }
#ifdef AMALGAM_IMPORT_HELPER_FROM_MODULE  // the installed Python module: its bin directory
  if (const fs::path object = this_object(); !object.empty() && object != self)
    candidates.push_back(object.parent_path() / AMALGAM_IMPORT_HELPER_FROM_MODULE);
#endif
#ifdef AMALGAM_IMPORT_HELPER_INSTALL_PATH  // installed where it was configured to be
  candidates.emplace_back(AMALGAM_IMPORT_HELPER_INSTALL_PATH);
#endif
#ifdef AMALGAM_IMPORT_HELPER_BUILD_PATH
  candidates.emplace_back(AMALGAM_IMPORT_HELPER_BUILD_PATH);
#endif
  for (const fs::path& c : candidates)
    if (fs::is_regular_file(c, ec)) return c.lexically_normal().string();
  throw RuntimeError("cannot find the mesh importer 'amalgam-import' (looked next to " +
                     (self.empty() ? std::string("the running executable") : self.string()) +
                     "; set AMALGAM_IMPORT_HELPER to its path)");
}

}  // namespace

void register_import_helper(std::string path) {
  const std::lock_guard lock(registered_mutex());
  registered_helper() = std::move(path);
}

namespace {

/// A running helper: its pid and the read end of its stdout. Unless reap() was called, the
/// destructor kills (SIGKILL) and reaps it, so no failure on our side leaves it running.
class Helper {
 public:
  Helper(const std::string& helper, const std::string& path, const ImportConfig& config,
         std::chrono::duration<double> timeout) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0)
      throw RuntimeError(helper + ": cannot start the mesh importer: " + errno_text(errno));
    const std::string parent = std::to_string(::getpid());
    const std::string max = std::to_string(config.max_triangles);
    std::vector<std::string> args = {helper, "--parent", parent, "--max-triangles", max};
    if (config.max_bytes != 0)
      args.insert(args.end(), {"--max-bytes", std::to_string(config.max_bytes), "--limit-name",
                               config.limit_name});
    if (config.smooth_normals) args.push_back("--smooth-normals");
    args.insert(args.end(), {"--", path});
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    // stdout: the pipe; stdin and stderr: /dev/null (Assimp's failed assertions print before
    // aborting; the one-line error says what happened). Default signal dispositions and an
    // empty signal mask, whatever the calling thread had.
    posix_spawn_file_actions_t actions;
    posix_spawnattr_t attr;
    posix_spawn_file_actions_init(&actions);
    posix_spawnattr_init(&attr);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &all);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    const int err = ::posix_spawn(&pid_, helper.c_str(), &actions, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    ::close(fds[1]);
    if (err != 0) {
      ::close(fds[0]);
      throw RuntimeError(helper + ": cannot start the mesh importer: " + errno_text(err));
    }
    fd_ = fds[0];
    // The watchdog: at the deadline the helper is killed, its pipe ends, the reply is broken.
    watchdog_ = std::jthread([this, timeout](std::stop_token stop) {
      std::mutex m;
      std::condition_variable_any cv;
      std::unique_lock lock(m);
      cv.wait_for(lock, stop, timeout, [] { return false; });
      if (!stop.stop_requested()) {
        timed_out_ = true;
        ::kill(pid_, SIGKILL);
      }
    });
  }
  Helper(const Helper&) = delete;
  Helper& operator=(const Helper&) = delete;
  ~Helper() {
    stop_watchdog();
    if (fd_ >= 0) ::close(fd_);
    if (!reaped_) {
      ::kill(pid_, SIGKILL);
      (void)wait();
    }
  }

  int fd() const { return fd_; }
  /// Whether the watchdog killed the helper (valid once reap() returned).
  bool timed_out() const { return timed_out_; }

  /// Closes the pipe and waits for the helper to end; its wait status. With `kill`, ends it
  /// first (after a reply that cannot be read, it may still be running).
  int reap(bool kill) {
    stop_watchdog();
    ::close(fd_);
    fd_ = -1;
    if (kill) ::kill(pid_, SIGKILL);
    reaped_ = true;
    return wait();
  }

 private:
  /// Before the helper is reaped (its pid may then be reused), so it is never killed after.
  void stop_watchdog() {
    if (watchdog_.joinable()) {
      watchdog_.request_stop();
      watchdog_.join();
    }
  }
  int wait() const {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
  }

  pid_t pid_ = -1;
  int fd_ = -1;
  bool reaped_ = false;
  std::atomic<bool> timed_out_ = false;
  std::jthread watchdog_;  // last: stopped (destructor) before the members it reads go
};

/// ImportConfig::timeout_seconds, else AMALGAM_IMPORT_TIMEOUT, else 300 s + 1 s per MiB.
double timeout_seconds(const std::string& path, const ImportConfig& config) {
  if (config.timeout_seconds > 0) return config.timeout_seconds;
  if (const char* env = std::getenv("AMALGAM_IMPORT_TIMEOUT"); env != nullptr && *env != '\0') {
    char* end = nullptr;
    const double s = std::strtod(env, &end);
    if (*end != '\0' || !(s > 0) || !(s <= 1e7))
      throw InputError(std::string("AMALGAM_IMPORT_TIMEOUT=") + one_line(env) +
                       ": expected seconds, a number in (0, 1e7]");
    return s;
  }
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  return 300.0 + (ec ? 0.0 : static_cast<double>(size) / (1 << 20));
}

std::string seconds_text(double s) {
  std::ostringstream out;
  out << s << " s";
  return out.str();
}

[[noreturn]] void crashed(const std::string& path, int status) {
  const std::string why = WIFSIGNALED(status)
                              ? "signal " + std::to_string(WTERMSIG(status))
                              : "exit status " + std::to_string(WEXITSTATUS(status));
  fail_input(path, "the importer crashed on this file (" + why + "); is it corrupt?");
}

}  // namespace

ImportedMesh import_mesh(const std::string& path, const ImportConfig& config) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail_input(path, "no such file");
  if (!fs::is_regular_file(path, ec)) fail_input(path, "not a regular file");
  check_mesh_file(path);

  const std::string helper_path = find_helper(config);
  const double timeout = timeout_seconds(path, config);
  Helper helper(helper_path, path, config, std::chrono::duration<double>(timeout));
  import_protocol::Reply reply = import_protocol::receive(helper.fd(), config.max_triangles);
  using Kind = import_protocol::Reply::Kind;
  const int status =
      helper.reap(/*kill=*/reply.kind == Kind::kBroken || reply.kind == Kind::kIncompatible);
  if (helper.timed_out())
    fail_input(path, "the importer did not finish within " + seconds_text(timeout) +
                         " (is the file corrupt? AMALGAM_IMPORT_TIMEOUT sets the limit)");
  switch (reply.kind) {
    case Kind::kError:
      throw InputError(reply.error);
    case Kind::kIncompatible:
      throw RuntimeError(helper_path + ": not the mesh importer of this build (it says '" +
                         one_line(reply.error) + "')");
    case Kind::kMesh:
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return std::move(reply.mesh);
      break;
    case Kind::kBroken:
      break;
  }
  crashed(path, status);
}

}  // namespace amalgam
