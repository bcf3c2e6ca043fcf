// glTF checks of check_mesh_file (io/mesh_check.h): the GLB container's declared sizes and
// the JSON members Assimp 5.2 reads leniently.

#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "amalgam/io/mesh_check.h"
#include "amalgam/util/error.h"

namespace amalgam::detail {
namespace {

/// Walks glTF JSON without building it (an embedded buffer can be hundreds of MB of base64)
/// and refuses a `byteOffset` or `byteStride` that is not a non-negative integer, naming its
/// JSON pointer. Syntax errors are left to Assimp, which reports them.
class MemberCheck : public nlohmann::json_sax<nlohmann::json> {
 public:
  explicit MemberCheck(std::string where) : where_(std::move(where)) {}

  bool null() override { return value("null"); }
  bool boolean(bool b) override { return value(b ? "true" : "false"); }
  bool number_integer(number_integer_t v) override { return value(std::to_string(v)); }
  bool number_unsigned(number_unsigned_t) override { return scalar(); }
  bool number_float(number_float_t, const string_t& s) override { return value(s); }
  bool string(string_t&) override { return value("a string"); }
  bool binary(binary_t&) override { return value("binary data"); }
  bool start_object(std::size_t) override {
    open(false);
    return true;
  }
  bool key(string_t& k) override {
    path_.back().key = k;
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override {
    open(true);
    return true;
  }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  struct Level {
    bool array = false;
    std::uint64_t index = 0;
    std::string key;
  };

  /// A container starts: it is a value of its parent, then the innermost level of the path.
  void open(bool array) {
    before_value();
    path_.push_back(Level{array, 0, {}});
  }
  bool close() {
    path_.pop_back();
    return true;
  }
  /// Before a value in the current container: nothing to do for an object (its key is set);
  /// an array counts its elements.
  void before_value() {
    if (!path_.empty() && path_.back().array) ++path_.back().index;
  }
  bool scalar() {
    before_value();
    return true;
  }
  /// A value that is not a non-negative integer: refused where the member must be one.
  bool value(const std::string& shown) {
    before_value();
    if (path_.empty() || path_.back().array) return true;
    const std::string& k = path_.back().key;
    if (k != "byteOffset" && k != "byteStride") return true;
    std::string pointer;
    for (const Level& l : path_) pointer += "/" + (l.array ? std::to_string(l.index - 1) : l.key);
    fail_input(where_, pointer.substr(1) + " is " + shown + ", not a non-negative integer");
  }

  std::string where_;
  std::vector<Level> path_;
};

template <class Input>
void check_json(const std::string& where, Input&& input) {
  MemberCheck check(where);
  try {
    nlohmann::json::sax_parse(std::forward<Input>(input), &check);
  } catch (const nlohmann::json::exception&) {
    // Left to Assimp, which names the problem in its own words.
  }
}

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

[[noreturn]] void beyond(const std::string& path, const std::string& what, std::uint64_t end,
                         std::uint64_t size) {
  fail_input(path, "binary glTF: " + what + " ends at byte " + std::to_string(end) +
                       ", beyond the end of the file (" + std::to_string(size) + " bytes)");
}

}  // namespace

void check_gltf(const std::string& path, const std::string& ext, const char (&magic)[4],
                std::uint64_t size) {
  std::ifstream in(path, std::ios::binary);
  if (std::memcmp(magic, "glTF", 4) == 0) {
    // GLB: magic, version, total length; glTF 2: chunks (length, type, data), the first JSON;
    // glTF 1 (KHR_binary_glTF): content length and format, then the JSON.
    unsigned char h[20] = {};
    if (!in.read(reinterpret_cast<char*>(h), 12)) return;  // Assimp says it is too short
    const std::uint32_t version = le32(h + 4);
    const std::uint64_t length = le32(h + 8);
    if (version != 1 && version != 2) return;  // Assimp refuses other versions
    if (length > size) beyond(path, "the header's total length", length, size);
    std::string json;
    if (version == 1) {
      if (!in.read(reinterpret_cast<char*>(h + 12), 8)) return;
      const std::uint64_t end = 20 + std::uint64_t{le32(h + 12)};
      if (end > length) beyond(path, "the JSON content", end, length);
      json.resize(end - 20);
    } else {
      std::uint64_t at = 12;
      for (int chunk = 0; at + 8 <= length; ++chunk) {
        unsigned char c[8];
        if (!in.seekg(static_cast<std::streamoff>(at)) || !in.read(reinterpret_cast<char*>(c), 8))
          return;
        const std::uint64_t end = at + 8 + le32(c);
        if (end > length)
          beyond(path, "chunk " + std::to_string(chunk) + " (at byte " + std::to_string(at) + ")",
                 end, length);
        if (chunk == 0 && std::memcmp(c + 4, "JSON", 4) == 0) json.resize(le32(c));
        at = end;
      }
      if (!in.seekg(20)) return;
    }
    if (!in.read(json.data(), static_cast<std::streamsize>(json.size()))) return;
    check_json(path, json);
  } else if (ext == ".gltf") {
    check_json(path, in);
  }
}

}  // namespace amalgam::detail
