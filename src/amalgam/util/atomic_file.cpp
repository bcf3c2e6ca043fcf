#include "amalgam/util/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <exception>
#include <filesystem>
#include <system_error>

namespace amalgam {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int err) {
  return std::error_code(err, std::generic_category()).message();
}

std::atomic<unsigned long> g_counter{0};  ///< tells apart the temporaries of one process

/// Makes a completed rename durable (best effort: a directory that cannot be opened or synced
/// does not fail a write whose data is already safely on disk).
void sync_directory_of(const std::string& path) {
  const fs::path dir = fs::path(path).parent_path();
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

AtomicFile::AtomicFile(const std::string& destination)
    : destination_(destination),
      temp_(destination + ".tmp-" + std::to_string(::getpid()) + "-" +
            std::to_string(g_counter.fetch_add(1))) {
  fp_ = std::fopen(temp_.c_str(), "wb");
  if (!fp_) throw RuntimeError("cannot open for writing: " + errno_text(errno));
}

AtomicFile::~AtomicFile() {
  if (fp_) std::fclose(fp_);
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::write(const void* data, std::size_t n) {
  if (n != 0 && std::fwrite(data, 1, n, fp_) != n)
    throw RuntimeError("write failed: " + errno_text(errno));
}

void AtomicFile::commit() {
  if (std::fflush(fp_) != 0) throw RuntimeError("write failed: " + errno_text(errno));
  if (std::ferror(fp_)) throw RuntimeError("write failed");
  if (::fsync(::fileno(fp_)) != 0) throw RuntimeError("cannot sync to disk: " + errno_text(errno));
  std::FILE* fp = fp_;
  fp_ = nullptr;
  if (std::fclose(fp) != 0) throw RuntimeError("write failed on close: " + errno_text(errno));
  std::error_code ec;
  fs::rename(temp_, destination_, ec);
  if (ec) throw RuntimeError("cannot rename temporary file into place: " + ec.message());
  committed_ = true;
  sync_directory_of(destination_);
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
