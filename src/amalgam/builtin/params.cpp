#include "amalgam/builtin/params.h"

#include <charconv>
#include <cmath>
#include <sstream>

namespace amalgam {

void Params::set(const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == key_value.size())
    throw InputError("--set '" + key_value + "': expected key=value");
  values_[key_value.substr(0, eq)] = key_value.substr(eq + 1);
}

std::int64_t Params::get_int(const std::string& key, std::int64_t def, std::int64_t lo,
                             std::int64_t hi) const {
  used_.insert(key);
  auto it = values_.find(key);
  if (it == values_.end()) return def;
  const std::string& s = it->second;
  std::int64_t v = 0;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size())
    throw InputError(where(key, s) + ": expected an integer");
  if (v < lo || v > hi) {
    std::ostringstream m;
    m << where(key, s) << ": expected an integer in [" << lo << ", " << hi << "]";
    throw InputError(m.str());
  }
  return v;
}

double Params::get_double(const std::string& key, double def, double lo, double hi) const {
  used_.insert(key);
  auto it = values_.find(key);
  if (it == values_.end()) return def;
  const std::string& s = it->second;
  std::size_t pos = 0;
  double v = 0;
  try {
    v = std::stod(s, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != s.size() || !std::isfinite(v)) throw InputError(where(key, s) + ": expected a number");
  if (v < lo || v > hi) {
    std::ostringstream m;
    m << where(key, s) << ": expected a number in [" << lo << ", " << hi << "]";
    throw InputError(m.str());
  }
  return v;
}

std::string Params::get_choice(const std::string& key, const std::string& def,
                               const std::set<std::string>& allowed) const {
  used_.insert(key);
  auto it = values_.find(key);
  if (it == values_.end()) return def;
  if (!allowed.count(it->second)) {
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    throw InputError(where(key, it->second) + ": expected one of " + list);
  }
  return it->second;
}

std::string Params::where(const std::string& key, const std::string& value) const {
  return scene_ + (spelling_ == ParamSpelling::kSet ? ": --set " : ": ") + key + "=" + value;
}

void Params::check_all_used() const {
  for (const auto& [k, v] : values_) {
    if (used_.count(k)) continue;
    if (spelling_ == ParamSpelling::kSet)
      throw UnknownParameter(scene_ + ": unknown parameter '" + k + "' in --set");
    std::string known;
    for (const auto& u : used_) known += (known.empty() ? "" : ", ") + u;
    throw UnknownParameter("load() got an unexpected keyword argument '" + k + "' (" + scene_ +
                           (known.empty() ? " takes no parameters" : "'s parameters: " + known) +
                           ")");
  }
}

std::string Params::applied() const {
  std::string out;
  for (const auto& [k, v] : values_) out += (out.empty() ? "" : " ") + k + "=" + v;
  return out;
}

}  // namespace amalgam
