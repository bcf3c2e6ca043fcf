#pragma once
/// \file Whole reads and writes on file descriptors, retried on EINTR and short counts.

#include <unistd.h>

#include <cerrno>
#include <cstddef>

namespace amalgam {

/// Writes all `n` bytes; false on an error (errno set) or a descriptor that takes no more.
inline bool write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w, n -= static_cast<std::size_t>(w);
  }
  return true;
}

/// Reads exactly `n` bytes; false on an error or an end of file before them.
inline bool read_all(int fd, void* data, std::size_t n) {
  char* p = static_cast<char*>(data);
  while (n > 0) {
    const ssize_t r = ::read(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r, n -= static_cast<std::size_t>(r);
  }
  return true;
}

}  // namespace amalgam
