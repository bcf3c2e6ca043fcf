#pragma once
/// \file Atomic file output: every file amalgam writes (images, stats JSON, checkpoints,
/// experiment reports) goes through `write_atomically`, so a destination is either left
/// untouched or holds the complete new contents, never a half-written file.
///
/// What is replaced is only ever a regular file or a new path: a symbolic link is followed and
/// its final target replaced (the link stays); a character or block device or a FIFO
/// (`/dev/null`, `/dev/stdout`, a pipe) is written through, never renamed over (a socket cannot
/// be opened: check_writable refuses it); "-" is standard output. Those are written from memory
/// once the whole contents are made, so a failure while making them writes nothing.

#include <cstddef>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include "amalgam/util/error.h"

namespace amalgam {

class AtomicFile;

/// Where an output path leads.
struct OutputTarget {
  enum class Kind : unsigned char {
    kFile,     ///< a regular file or a new path: written to a temporary, renamed onto `path`
    kSpecial,  ///< a device, FIFO or socket: written through
    kStdout,   ///< "-"
  };
  Kind kind = Kind::kFile;
  std::string path;  ///< symbolic links resolved (kFile); as given (kSpecial, kStdout)
};

/// Resolves `path` (following symbolic links, at most 40) and classifies it. Throws InputError
/// naming the path when it can never be written: a directory, a parent that is missing or not
/// a directory, a symbolic link loop.
OutputTarget resolve_output(const std::string& path);

/// A key equal for two paths that name the same file, however spelled (`x.png`, `./x.png`,
/// `$PWD/x.png`, `sub/../x.png`, a symbolic link to it): "inode DEV:INO" where the file exists,
/// else "path P" with P the resolved directory and the name (links followed). Empty for "-".
std::string file_identity(const std::string& path);

/// Checks before any work that `path` can be written: resolve_output, then, for a regular file
/// or a new path, write permission on its directory; a device or FIFO is opened for writing
/// (without waiting: a FIFO no process is reading is refused at once, as are a socket and a
/// device that cannot be opened) and kept open until write_atomically writes it. Throws
/// InputError naming the path.
void check_writable(const std::string& path);

/// Removes the temporary file being written, if any, with async-signal-safe calls only: for a
/// signal handler that ends the process during a write (no temporary may be left behind).
void remove_temporary_from_signal_handler() noexcept;

namespace detail {
/// write_atomically without the throw: nullopt on success, else the one-line reason of the
/// failure (the temporary file removed).
std::optional<std::string> write_atomically_or_reason(const std::string& path,
                                                      const std::function<void(AtomicFile&)>& body);
}  // namespace detail

/// The temporary file that the body of `write_atomically` writes. Its functions throw a
/// RuntimeError carrying the reason only ("write failed: No space left on device");
/// write_atomically names the destination.
class AtomicFile {
 public:
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends `n` bytes.
  void write(const void* data, std::size_t n);
  void write(std::string_view text) { write(text.data(), text.size()); }
  /// The open C stream, for libraries that write through one (libpng, OpenEXR). Errors on it
  /// are caught when write_atomically flushes it.
  std::FILE* stream() const { return fp_; }
  /// The temporary's path: `<destination>.tmp-<pid>-<n>`, in the destination's directory
  /// (empty when the destination is written through from memory: a device, FIFO or "-").
  const std::string& temp_path() const { return temp_; }

 private:
  friend std::optional<std::string> detail::write_atomically_or_reason(
      const std::string& path, const std::function<void(AtomicFile&)>& body);
  /// Creates the temporary next to `destination`.
  explicit AtomicFile(const std::string& destination);
  /// Closes the temporary and, unless commit() succeeded, removes it.
  ~AtomicFile();
  /// Flushes, fsyncs and closes the temporary, then renames it onto the destination.
  void commit();

  OutputTarget target_;
  std::string temp_;
  std::FILE* fp_ = nullptr;
  char* memory_ = nullptr;  ///< open_memstream's buffer (special targets)
  std::size_t memory_size_ = 0;
  bool committed_ = false;
};

/// Writes `path` atomically: `body` writes a temporary file in the same directory (so the
/// rename never crosses file systems), which is then flushed, fsynced and renamed onto `path`
/// (replacing an existing regular file, keeping its permission bits); a special target is
/// written through (see the file comment). On any failure, of the body or of the file, the
/// temporary is removed and an `Error` (RuntimeError or a kind derived from it) is thrown whose
/// what() is one line, "<path>: <reason>"; exceptions thrown by `body` give their what() as the
/// reason.
template <class Error = RuntimeError>
void write_atomically(const std::string& path, const std::function<void(AtomicFile&)>& body) {
  static_assert(std::is_base_of_v<RuntimeError, Error>, "a failed write is a RuntimeError");
  if (std::optional<std::string> why = detail::write_atomically_or_reason(path, body))
    throw Error(path + ": " + *why);
}

/// Writes `contents` as the whole of `path` with write_atomically (throws RuntimeError).
void write_file_atomic(const std::string& path, std::string_view contents);

}  // namespace amalgam
