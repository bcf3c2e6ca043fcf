#pragma once
/// \file The two kinds of failure, and the one rule that maps them to exit statuses.
///
/// - `InputError`: the user's input is wrong (a scene file, a mesh, an option, a checkpoint):
///   one line naming the file and the place; the CLI exits 2.
/// - `RuntimeError`: the input was fine but the work failed (a disk full, a write refused, a
///   helper process killed); the CLI exits 1.
/// - `InternalError` (thrown by AMALGAM_CHECK, check.h, and by a library function called
///   outside its preconditions): a broken invariant of our own, a bug; exit 1. Every
///   std::logic_error (std::invalid_argument, ...) counts as one.
/// Any other std::exception is a runtime failure. `error_kind` is the one classification: the
/// CLI's exit status and the Python module's exception both follow from it.

#include <exception>
#include <stdexcept>
#include <string>

namespace amalgam {

/// Bad user input. The message is one line: "<file or option>: <what is wrong>".
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws InputError("<file>: <problem>").
[[noreturn]] void fail_input(const std::string& file, const std::string& problem);

/// A failure of the work itself, not of its input (I/O, resources, a helper process).
struct RuntimeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A violated internal invariant (a bug): see AMALGAM_CHECK in check.h.
struct InternalError : std::logic_error {
  using std::logic_error::logic_error;
};

/// Which kind of failure `e` is.
enum class ErrorKind : unsigned char { kInput, kRuntime, kInternal };
inline ErrorKind error_kind(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e) != nullptr) return ErrorKind::kInput;
  if (dynamic_cast<const std::logic_error*>(&e) != nullptr) return ErrorKind::kInternal;
  return ErrorKind::kRuntime;
}

/// Exit status for a failure: 2 for bad input, 1 for everything else.
inline int exit_status(const std::exception& e) {
  return error_kind(e) == ErrorKind::kInput ? 2 : 1;
}

/// `text` on one line: newlines, carriage returns and tabs shown as spaces, trailing spaces
/// dropped, then cut to at most `max` characters (ending in an ellipsis where it was cut). For
/// quoting user input (default 120) or a library's message (`std::string::npos`: no cut)
/// inside an error message.
std::string one_line(const std::string& text, std::size_t max = 120);

}  // namespace amalgam
