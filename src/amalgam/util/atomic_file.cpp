#include "amalgam/util/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <system_error>

#include "amalgam/util/fd_io.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int err) {
  return std::error_code(err, std::generic_category()).message();
}

std::atomic<unsigned long> g_counter{0};  ///< tells apart the temporaries of one process

/// The temporary being written (for remove_temporary_from_signal_handler): a fixed buffer,
/// published by `g_temp_active` after it is filled.
char g_temp_path[PATH_MAX];
std::atomic<int> g_temp_active{0};

/// Makes a completed rename durable (best effort: a directory that cannot be opened or synced
/// does not fail a write whose data is already safely on disk).
void sync_directory_of(const std::string& path) {
  const fs::path dir = fs::path(path).parent_path();
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  (void)::fsync(fd);
  ::close(fd);
}

/// Descriptors of special outputs opened by check_writable, by resolved path, kept open until
/// the output is written: opened again only then, a FIFO's reader would already have seen the
/// end of file when the check's descriptor closed.
std::mutex g_opened_mutex;
std::multimap<std::string, int> g_opened;

/// Opens a special target for writing without waiting (O_NONBLOCK: a FIFO with no reader gives
/// ENXIO at once instead of blocking until one comes), then makes its writes blocking again.
/// Returns the descriptor, or -1 with `why` set to the reason.
int open_special(const std::string& path, std::string& why) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode)) {
    why = "is a socket, which cannot be opened as a file (write to a file, a FIFO or a device)";
    return -1;
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    if (err == ENXIO && S_ISFIFO(st.st_mode))
      why = "is a FIFO that no process is reading (start its reader first)";
    else
      why = "cannot be opened for writing: " + errno_text(err);
    return -1;
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) (void)::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  return fd;
}

/// A descriptor of the special target `path` for writing: the one check_writable opened, if
/// any (taken, so each output uses one), else a new one. -1 with `why` set on failure.
int take_special(const std::string& path, std::string& why) {
  {
    const std::lock_guard<std::mutex> lock(g_opened_mutex);
    if (const auto it = g_opened.find(path); it != g_opened.end()) {
      const int fd = it->second;
      g_opened.erase(it);
      return fd;
    }
  }
  return open_special(path, why);
}

}  // namespace

OutputTarget resolve_output(const std::string& path) {
  OutputTarget t;
  if (path == "-") {
    t.kind = OutputTarget::Kind::kStdout;
    t.path = path;
    return t;
  }
  if (path.empty()) throw InputError("an output path is empty");
  // A device, FIFO or socket is written through this very path, resolved by the kernel: also
  // /dev/stdout, whose link /proc/self/fd/1 names a pipe as "pipe:[N]", which is no path.
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISDIR(info.st_mode)) {
    t.kind = OutputTarget::Kind::kSpecial;
    t.path = path;
    return t;
  }
  fs::path p(path);
  std::error_code ec;
  for (int hops = 0; fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    if (hops == 40) throw InputError(path + ": too many levels of symbolic links");
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) throw InputError(path + ": cannot read the symbolic link: " + ec.message());
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  const fs::file_status st = fs::status(p, ec);
  t.path = p.string();
  if (fs::exists(st)) {
    if (fs::is_directory(st)) throw InputError(path + ": is a directory");
    t.kind = fs::is_regular_file(st) ? OutputTarget::Kind::kFile : OutputTarget::Kind::kSpecial;
    return t;
  }
  const fs::path parent = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const fs::file_status ps = fs::status(parent, ec);
  if (!fs::exists(ps))
    throw InputError(path + ": the directory " + parent.string() + " does not exist");
  if (!fs::is_directory(ps))
    throw InputError(path + ": " + parent.string() + " is not a directory");
  t.kind = OutputTarget::Kind::kFile;
  return t;
}

std::string file_identity(const std::string& path) {
  if (path == "-" || path.empty()) return {};
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0)
    return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  const OutputTarget t = resolve_output(path);  // links followed; its directory exists
  const fs::path p(t.path);
  std::error_code ec;
  const fs::path dir = fs::canonical(p.parent_path().empty() ? fs::path(".") : p.parent_path(), ec);
  return "path " + (ec ? fs::absolute(p).lexically_normal() : dir / p.filename()).string();
}

void check_writable(const std::string& path) {
  const OutputTarget t = resolve_output(path);
  if (t.kind == OutputTarget::Kind::kStdout) return;
  if (t.kind == OutputTarget::Kind::kSpecial) {
    // Opened now, for real (a socket, a FIFO without a reader, a device without its hardware
    // fail here, not after the work), and kept open for the write.
    std::string why;
    const int fd = open_special(t.path, why);
    if (fd < 0) throw InputError(path + ": " + why);
    const std::lock_guard<std::mutex> lock(g_opened_mutex);
    g_opened.emplace(t.path, fd);
    return;
  }
  // A regular file is replaced through its directory.
  const fs::path parent = fs::path(t.path).parent_path();
  const std::string dir = parent.empty() ? std::string(".") : parent.string();
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(path + ": cannot be written: " + errno_text(errno));
}

void remove_temporary_from_signal_handler() noexcept {
  if (g_temp_active.load()) ::unlink(g_temp_path);
}

AtomicFile::AtomicFile(const std::string& destination) {
  try {
    target_ = resolve_output(destination);
  } catch (const InputError& e) {  // as a write failure: the caller names the path
    const std::string what = e.what();
    throw RuntimeError(what.substr(what.find(": ") == std::string::npos ? 0 : what.find(": ") + 2));
  }
  if (target_.kind != OutputTarget::Kind::kFile) {
    fp_ = ::open_memstream(&memory_, &memory_size_);
    if (!fp_) throw RuntimeError("cannot allocate the output buffer: " + errno_text(errno));
    return;
  }
  temp_ = target_.path + ".tmp-" + std::to_string(::getpid()) + "-" +
          std::to_string(g_counter.fetch_add(1));
  if (temp_.size() < sizeof g_temp_path) {
    std::memcpy(g_temp_path, temp_.c_str(), temp_.size() + 1);
    g_temp_active.store(1);
  }
  fp_ = std::fopen(temp_.c_str(), "wb");
  if (!fp_) {
    g_temp_active.store(0);
    throw RuntimeError("cannot open for writing: " + errno_text(errno));
  }
  // A replaced file keeps its permission bits.
  struct stat old;
  if (::stat(target_.path.c_str(), &old) == 0) (void)::fchmod(::fileno(fp_), old.st_mode & 07777);
}

AtomicFile::~AtomicFile() {
  if (fp_) std::fclose(fp_);
  std::free(memory_);
  if (!committed_ && !temp_.empty()) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
  if (!temp_.empty()) g_temp_active.store(0);
}

void AtomicFile::write(const void* data, std::size_t n) {
  if (n != 0 && std::fwrite(data, 1, n, fp_) != n)
    throw RuntimeError("write failed: " + errno_text(errno));
}

void AtomicFile::commit() {
  if (std::fflush(fp_) != 0) throw RuntimeError("write failed: " + errno_text(errno));
  if (target_.kind != OutputTarget::Kind::kFile) {  // the whole contents made: write through
    if (std::ferror(fp_)) throw RuntimeError("write failed");
    std::FILE* fp = fp_;
    fp_ = nullptr;
    std::fclose(fp);  // memory_ and memory_size_ now hold the contents
    if (target_.kind == OutputTarget::Kind::kStdout) {
      std::fflush(stdout);
      if (!write_all(1, memory_, memory_size_))
        throw RuntimeError("write to standard output failed: " + errno_text(errno));
    } else {
      std::string why;
      const int fd = take_special(target_.path, why);
      if (fd < 0) throw RuntimeError(why);
      const bool ok = write_all(fd, memory_, memory_size_);
      const int err = errno;
      ::close(fd);
      if (!ok) throw RuntimeError("write failed: " + errno_text(err));
    }
    committed_ = true;
    return;
  }
  if (std::ferror(fp_)) throw RuntimeError("write failed");
  if (::fsync(::fileno(fp_)) != 0) throw RuntimeError("cannot sync to disk: " + errno_text(errno));
  std::FILE* fp = fp_;
  fp_ = nullptr;
  if (std::fclose(fp) != 0) throw RuntimeError("write failed on close: " + errno_text(errno));
  std::error_code ec;
  fs::rename(temp_, target_.path, ec);
  if (ec) throw RuntimeError("cannot rename temporary file into place: " + ec.message());
  committed_ = true;
  sync_directory_of(target_.path);
}

namespace detail {

std::optional<std::string> write_atomically_or_reason(
    const std::string& path, const std::function<void(AtomicFile&)>& body) {
  try {
    AtomicFile file(path);
    body(file);
    file.commit();
    return std::nullopt;
  } catch (const std::exception& e) {
    return one_line(e.what(), std::string::npos);
  } catch (...) {
    return std::string("unknown error");
  }
}

}  // namespace detail

void write_file_atomic(const std::string& path, std::string_view contents) {
  write_atomically(path, [&](AtomicFile& f) { f.write(contents); });
}

}  // namespace amalgam
