#pragma once
/// \file What kind of file a path is, for messages about inputs that must be regular files:
/// "is a directory", "is a FIFO, not a regular file". Found with stat, never by opening (opening
/// a FIFO waits for a writer; reading a device may never end).

#include <sys/stat.h>

#include <string>

namespace amalgam {

/// The kind of a file that is not a regular file ("a directory", "a FIFO", "a character
/// device", "a block device", "a socket"); empty for a regular file.
inline std::string special_file_kind(mode_t mode) {
  if (S_ISREG(mode)) return {};
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// Why `path` (symbolic links followed) cannot be read as an input file: "is a directory",
/// "is a FIFO, not a regular file", ...; empty when it is a regular file or does not exist
/// (the caller reports that in its own words).
inline std::string not_a_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return {};
  if (S_ISDIR(st.st_mode)) return "is a directory";
  const std::string kind = special_file_kind(st.st_mode);
  return kind == "not a regular file" ? "is not a regular file"
                                      : "is " + kind + ", not a regular file";
}

}  // namespace amalgam
