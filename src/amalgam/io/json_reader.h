#pragma once
/// \file Reading user-written JSON (scene files): parsing with errors that name the line and
/// column, and checked access to the document whose errors name the JSON pointer of the
/// offending value. Every error is one-line InputError, "<file>: <where>: <what>".

#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/scene/coordinate_limit.h"

namespace amalgam {

/// The bytes a parsed document may take (0: no limit), and how messages name the limit.
struct JsonLimit {
  std::uint64_t max_bytes = 0;
  std::string name = "the memory limit";
};

/// Parses `text` (comments allowed), in time linear in its length. Throws InputError "<file>:
/// line L, column C: invalid JSON: <what>" on a syntax error, and likewise for a number beyond
/// the range of a double; "<file>: <pointer of the object>: key "K" given twice" for a
/// duplicate key; "<file>: its JSON needs about ..." when the document, sized in a first pass
/// that builds nothing, would take more than `limit`.
nlohmann::json parse_json(const std::string& text, const std::string& file,
                          const JsonLimit& limit = {});

/// A value of a document with its JSON pointer ("/lights/0/intensity"; "" for the root).
struct JsonValue {
  const nlohmann::json& j;
  std::string ptr;
};

/// Checked access to one file's document. Numbers are finite and within the coordinate range
/// of scenes, +-kMaxCoordinate (scene/coordinate_limit.h), unless a narrower range is asked
/// for.
class JsonReader {
 public:
  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  /// Throws InputError "<file>: <ptr or 'top level'>: <what>".
  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const;

  /// The member `key` / element `i` of `v` (which must have it).
  static JsonValue child(const JsonValue& v, const std::string& key);
  static JsonValue element(const JsonValue& v, std::size_t i);
  /// `key` escaped as a JSON pointer token (~ -> ~0, / -> ~1).
  static std::string escape(const std::string& key);
  /// "a number", "an array", ...: the kind of `j`, for messages.
  static std::string type(const nlohmann::json& j);
  /// A number as messages show it (std::ostream's default format).
  static std::string format(double v);

  /// Checks that `v` is an object whose keys are all in `allowed` ("comment" is always
  /// allowed).
  void object(const JsonValue& v, std::initializer_list<const char*> allowed) const;
  /// The member `key`, or `alias` (an alternative spelling); nullopt when neither is there.
  /// Both present is an error.
  std::optional<JsonValue> find(const JsonValue& v, const std::string& key,
                                const std::string& alias = "") const;
  /// As find, but a missing member is an error.
  JsonValue require(const JsonValue& v, const std::string& key,
                    const std::string& alias = "") const;
  /// The elements of an array.
  std::vector<JsonValue> items(const JsonValue& v) const;

  /// A number in [lo, hi]; `range` replaces "in [lo, hi]" in the message.
  double number(const JsonValue& v, double lo = -kMaxCoordinate, double hi = kMaxCoordinate,
                const char* range = nullptr) const;
  /// A number in (0, kMaxCoordinate].
  double positive(const JsonValue& v) const;
  /// An integer in [lo, hi] (a float with an integral value counts).
  std::int64_t integer(const JsonValue& v, std::int64_t lo, std::int64_t hi) const;
  bool boolean(const JsonValue& v) const;
  std::string string(const JsonValue& v) const;
  /// Checks that `v` is an array.
  void array(const JsonValue& v) const;
  /// An array of 3 numbers.
  Vec3 vec3(const JsonValue& v) const;
  /// A vec3 with non-negative components.
  Vec3 colour(const JsonValue& v) const;
  /// A vec3 of non-zero length (not normalised).
  Vec3 direction(const JsonValue& v) const;

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

}  // namespace amalgam
