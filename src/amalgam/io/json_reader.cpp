#include "amalgam/io/json_reader.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <set>
#include <sstream>
#include <vector>

#include "amalgam/io/scene_json.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

using nlohmann::json;

/// "line L, column C: " of the byte at `offset` of `text` (both counted from 1).
std::string line_column(const std::string& text, std::size_t offset) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
}

/// Turns nlohmann's parse error into "line L, column C: invalid JSON: what".
std::string describe_parse_error(const json::parse_error& e, const std::string& text) {
  const std::size_t byte = std::min<std::size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
  std::string what = e.what();
  // "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..."
  const auto col = what.find("column ");
  const auto colon = what.find(": ", col == std::string::npos ? 0 : col);
  if (colon != std::string::npos) what = what.substr(colon + 2);
  for (char& c : what)
    if (c == '\n' || c == '\r') c = ' ';
  return line_column(text, byte) + "invalid JSON: " + what;
}

/// Turns nlohmann's "number overflow parsing '1e400'" into "line L, column C: ..." by finding
/// the quoted token in the text (found by the fuzzer, see tests/fuzz_regressions_test.cpp).
std::string describe_overflow(const json::out_of_range& e, const std::string& text) {
  const std::string what = e.what();
  const auto open = what.find('\''), close = what.rfind('\'');
  const std::string token =
      open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : "";
  const std::size_t at = token.empty() ? std::string::npos : text.find(token);
  return (at != std::string::npos ? line_column(text, at) : std::string()) +
         "invalid JSON: number " + (token.empty() ? "" : token + " ") +
         "is out of the range of a double";
}

/// A first pass over the text (SAX: nothing is built) that refuses a key given twice in one
/// object (nlohmann keeps the last silently, so a scene file with two "camera" objects rendered
/// the second) and sizes the document before it is built. It follows the parse as a stack of
/// open objects and arrays, to name the object by its JSON pointer. (nlohmann's callback
/// parser did the same check in time quadratic in an array's length: it rescans the array for
/// discarded values at the end of every object in it.)
class FirstPass : public nlohmann::json_sax<json> {
 public:
  explicit FirstPass(const std::string& file) : file_(file) {}

  /// Bytes the document takes once built (libstdc++'s node and vector sizes, malloc's
  /// rounding): a 16-byte value each, a map and its nodes for an object, a vector grown by
  /// doubling for an array, a heap buffer for a string or key beyond the short-string buffer.
  std::uint64_t bytes() const { return bytes_ + 16; }

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t& s) override {
    bytes_ += 48 + heap(s.size());
    return value();
  }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override {
    bytes_ += 64;
    open_.push_back({true, {}, {}, 0});
    return true;
  }
  bool key(string_t& k) override {
    bytes_ += 96 + heap(k.size());
    Open& o = open_.back();
    o.key = k;
    if (!o.keys.insert(o.key).second)
      throw InputError(file_ + ": " + (pointer().empty() ? "top level" : pointer()) + ": key \"" +
                       one_line(o.key, 80) + "\" given twice");
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override {
    bytes_ += 32;
    open_.push_back({false, {}, {}, 0});
    return true;
  }
  bool end_array() override {
    bytes_ += 32 * open_.back().index;  // 16 per element, and the spare capacity of doubling
    return close();
  }
  /// Rethrows nlohmann's own exception: parse_json turns it into one line.
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    if (const auto* p = dynamic_cast<const json::parse_error*>(&e)) throw *p;
    if (const auto* o = dynamic_cast<const json::out_of_range*>(&e)) throw *o;
    throw InputError(file_ + ": invalid JSON: " + std::string(e.what()));
  }

 private:
  struct Open {
    bool object;
    std::set<std::string> keys;  ///< an object's keys so far
    std::string key;             ///< an object's current key
    std::size_t index;           ///< an array's current element
  };

  static std::uint64_t heap(std::size_t n) { return n > 15 ? (n + 1 + 15) / 16 * 16 : 0; }

  bool value() {
    if (!open_.empty() && !open_.back().object) ++open_.back().index;
    return true;
  }
  bool close() {
    open_.pop_back();
    return value();
  }

  /// The JSON pointer of the innermost open object or array.
  std::string pointer() const {
    std::string p;
    for (std::size_t i = 0; i + 1 < open_.size(); ++i)
      p += "/" +
           (open_[i].object ? JsonReader::escape(open_[i].key) : std::to_string(open_[i].index));
    return p;
  }

  const std::string& file_;
  std::vector<Open> open_;
  std::uint64_t bytes_ = 0;
};

}  // namespace

json parse_json(const std::string& text, const std::string& file, const JsonLimit& limit) {
  try {
    FirstPass first(file);
    json::sax_parse(text, &first, json::input_format_t::json, /*strict=*/true,
                    /*ignore_comments=*/true);
    const std::uint64_t need = first.bytes() + text.size();  // the text lives on meanwhile
    if (limit.max_bytes != 0 && need > limit.max_bytes)
      throw InputError(file + ": its JSON needs about " + format_bytes(static_cast<double>(need)) +
                       " once read (estimated before reading it), more than " + limit.name);
    return json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    throw InputError(file + ": " + describe_parse_error(e, text));
  } catch (const json::out_of_range& e) {
    // A number beyond double's range ("1e400"): the exception names the token, not its place.
    throw InputError(file + ": " + describe_overflow(e, text));
  }
}

void JsonReader::fail(const std::string& ptr, const std::string& what) const {
  // Keys and values quoted from the file are cut: one readable line, however long the input.
  throw InputError(file_ + ": " + (ptr.empty() ? std::string("top level") : one_line(ptr, 160)) +
                   ": " + one_line(what, 300));
}

std::string JsonReader::escape(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

JsonValue JsonReader::child(const JsonValue& v, const std::string& key) {
  return {v.j.at(key), v.ptr + "/" + escape(key)};
}

JsonValue JsonReader::element(const JsonValue& v, std::size_t i) {
  return {v.j.at(i), v.ptr + "/" + std::to_string(i)};
}

std::string JsonReader::type(const json& j) {
  if (j.is_number()) return "a number";
  if (j.is_string()) return "a string";
  if (j.is_boolean()) return "a boolean";
  if (j.is_null()) return "null";
  if (j.is_array()) return "an array";
  return "an object";
}

std::string JsonReader::format(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

void JsonReader::object(const JsonValue& v, std::initializer_list<const char*> allowed) const {
  if (!v.j.is_object()) fail(v.ptr, "expected an object, found " + type(v.j));
  for (const auto& [key, value] : v.j.items()) {
    if (key == "comment") continue;
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(v.ptr + "/" + escape(key), "unknown key (expected one of: " + list + ")");
    }
  }
}

std::optional<JsonValue> JsonReader::find(const JsonValue& v, const std::string& key,
                                          const std::string& alias) const {
  const bool has_key = v.j.contains(key), has_alias = !alias.empty() && v.j.contains(alias);
  if (has_key && has_alias)
    fail(v.ptr, "both '" + key + "' and '" + alias + "' given (they mean the same)");
  if (has_key) return child(v, key);
  if (has_alias) return child(v, alias);
  return std::nullopt;
}

JsonValue JsonReader::require(const JsonValue& v, const std::string& key,
                              const std::string& alias) const {
  if (auto c = find(v, key, alias)) return *c;
  fail(v.ptr, "missing key '" + key + "'");
}

std::vector<JsonValue> JsonReader::items(const JsonValue& v) const {
  array(v);
  std::vector<JsonValue> out;
  for (std::size_t i = 0; i < v.j.size(); ++i) out.push_back(element(v, i));
  return out;
}

double JsonReader::number(const JsonValue& v, double lo, double hi, const char* range) const {
  if (!v.j.is_number()) fail(v.ptr, "expected a number, found " + type(v.j));
  const double x = v.j.get<double>();
  if (!std::isfinite(x) || x < lo || x > hi)
    fail(v.ptr, std::string("expected a number ") +
                    (range ? range : "in [" + format(lo) + ", " + format(hi) + "]") + ", found " +
                    format(x));
  return x;
}

double JsonReader::positive(const JsonValue& v) const {
  const bool huge = v.j.is_number() && v.j.get<double>() > kMaxCoordinate;
  return number(v, 1e-30, kMaxCoordinate, huge ? "<= 1e12" : "> 0");
}

std::int64_t JsonReader::integer(const JsonValue& v, std::int64_t lo, std::int64_t hi) const {
  const std::string expected =
      "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v.j.is_number_integer()) {
    if (v.j.is_number_float()) {
      const double x = v.j.get<double>();
      if (x == std::floor(x) && x >= static_cast<double>(lo) && x <= static_cast<double>(hi))
        return static_cast<std::int64_t>(x);
    }
    fail(v.ptr, expected + ", found " + (v.j.is_number() ? v.j.dump() : type(v.j)));
  }
  const bool neg = v.j.is_number_unsigned() ? false : v.j.get<std::int64_t>() < 0;
  if (!neg && v.j.is_number_unsigned() &&
      v.j.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
    fail(v.ptr, expected + ", found " + v.j.dump());
  const std::int64_t x = v.j.get<std::int64_t>();
  if (x < lo || x > hi) fail(v.ptr, expected + ", found " + v.j.dump());
  return x;
}

bool JsonReader::boolean(const JsonValue& v) const {
  if (!v.j.is_boolean()) fail(v.ptr, "expected true or false, found " + type(v.j));
  return v.j.get<bool>();
}

std::string JsonReader::string(const JsonValue& v) const {
  if (!v.j.is_string()) fail(v.ptr, "expected a string, found " + type(v.j));
  return v.j.get<std::string>();
}

void JsonReader::array(const JsonValue& v) const {
  if (!v.j.is_array()) fail(v.ptr, "expected an array, found " + type(v.j));
}

Vec3 JsonReader::vec3(const JsonValue& v) const {
  if (!v.j.is_array() || v.j.size() != 3)
    fail(v.ptr, "expected an array of 3 numbers, found " +
                    (v.j.is_array() ? "an array of " + std::to_string(v.j.size()) : type(v.j)));
  Vec3 r;
  for (int i = 0; i < 3; ++i) {
    const JsonValue e = element(v, static_cast<std::size_t>(i));
    if (!e.j.is_number()) fail(v.ptr, "expected an array of 3 numbers, found " + v.j.dump());
    r[i] = static_cast<float>(number(e));
  }
  return r;
}

Vec3 JsonReader::colour(const JsonValue& v) const {
  const Vec3 c = vec3(v);
  if (c.x < 0 || c.y < 0 || c.z < 0) fail(v.ptr, "expected non-negative colour components");
  return c;
}

Vec3 JsonReader::direction(const JsonValue& v) const {
  const Vec3 d = vec3(v);
  if (!(length(d) > 0.0f)) fail(v.ptr, "expected a non-zero direction");
  return d;
}

}  // namespace amalgam
