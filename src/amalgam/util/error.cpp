#include "amalgam/util/error.h"

#include "amalgam/util/check.h"

namespace amalgam {

void fail_input(const std::string& file, const std::string& problem) {
  throw InputError(file + ": " + problem);
}

std::string one_line(const std::string& text, std::size_t max) {
  std::string s;
  for (char c : text) s += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.size() > max) s = s.substr(0, max > 3 ? max - 3 : 0) + "...";
  return s;
}

namespace detail {
void check_failed(const char* cond, const char* file, int line, const std::string& what) {
  throw InternalError(std::string("internal error: ") + what + " (" + cond + " failed at " + file +
                      ":" + std::to_string(line) + ")");
}
}  // namespace detail

}  // namespace amalgam
