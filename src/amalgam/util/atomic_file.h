#pragma once
/// \file Atomic file output: every file amalgam writes (images, stats JSON, checkpoints,
/// experiment reports) goes through `write_atomically`, so a destination is either left
/// untouched or holds the complete new contents, never a half-written file.

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
  /// The temporary's path: `<destination>.tmp-<pid>-<n>`, in the destination's directory.
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

  std::string destination_, temp_;
  std::FILE* fp_ = nullptr;
  bool committed_ = false;
};

/// Writes `path` atomically: `body` writes a temporary file in the same directory (so the
/// rename never crosses file systems), which is then flushed, fsynced and renamed onto `path`
/// (replacing any existing file). On any failure, of the body or of the file, the temporary is
/// removed and an `Error` (RuntimeError or a kind derived from it) is thrown whose what() is
/// one line, "<path>: <reason>"; exceptions thrown by `body` give their what() as the reason.
template <class Error = RuntimeError>
void write_atomically(const std::string& path, const std::function<void(AtomicFile&)>& body) {
  static_assert(std::is_base_of_v<RuntimeError, Error>, "a failed write is a RuntimeError");
  if (std::optional<std::string> why = detail::write_atomically_or_reason(path, body))
    throw Error(path + ": " + *why);
}

/// Writes `contents` as the whole of `path` with write_atomically (throws RuntimeError).
void write_file_atomic(const std::string& path, std::string_view contents);

}  // namespace amalgam
