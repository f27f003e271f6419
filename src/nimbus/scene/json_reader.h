#pragma once
// Typed, strict reading of a JSON document whose every error is one line naming the JSON pointer
// of the offending value: "scene.json: /media/cloud/sigma_s/1: must be >= 0". The scene loader
// is written against these helpers so that validation reads as a list of rules.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nimbus/math/range.h"
#include "nimbus/math/vec3.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// `text` as one printable line of bounded length, for messages that quote what a file or a flag
// said: control characters (C0, DEL, C1) and bytes that are not UTF-8 (overlong forms and
// surrogates included) are written as escapes (\n, \t, \xNN), so that a name cannot split a
// message or send a terminal an escape sequence; past kMaxMessageBytes the middle is cut and
// the length said.
inline constexpr size_t kMaxMessageBytes = 1000;
std::string printable_line(std::string_view text);

// The first byte offset at which `text` is not well-formed UTF-8 (a stray continuation byte, an
// overlong form, a surrogate, past U+10FFFF, a sequence cut short), or npos.
size_t invalid_utf8_at(std::string_view text);

// A scene error; the message is the complete one-line report (printable_line).
struct SceneError : std::runtime_error {
  explicit SceneError(std::string_view message) : std::runtime_error(printable_line(message)) {}
};

// Where a document came from, for messages and relative file names. A value that a --set
// override put in place is reported against that flag rather than against the file, which never
// contained it.
struct JsonOrigin {
  std::string source;
  struct Override {
    std::string pointer;  // JSON pointer of the replaced value
    std::string flag;     // "--set KEY=VALUE" as given
  };
  std::vector<Override> overrides;
  // The folder that relative file names in the document resolve against: the scene file's own;
  // "" (the current directory) for a document that is not a file.
  std::string folder = "";
};

// What a value that holds a solid texture ({"texture": ...}) is told where its key takes none.
inline constexpr std::string_view kTakesNoTexture =
    "takes no texture (textures drive a diffuse albedo, a roughness, and a medium's sigma_a and "
    "sigma_s)";

// One JSON value and its JSON pointer ("" for the document itself).
class JsonValue {
 public:
  JsonValue(const nlohmann::json& json, std::string pointer, const JsonOrigin& origin)
      : json_(&json), pointer_(std::move(pointer)), origin_(&origin) {}

  const nlohmann::json& json() const { return *json_; }
  const std::string& pointer() const { return pointer_; }
  const JsonOrigin& origin() const { return *origin_; }
  // "ORIGIN: POINTER", the start of fail()'s message: for a problem found once the document is
  // gone (a file read when the scene is compiled, scene/input_file.h).
  std::string blame() const;

  // Throws SceneError("ORIGIN: POINTER: problem").
  [[noreturn]] void fail(std::string_view problem) const;

  // Each getter fails with "expected ..." on a wrong JSON type and with "must be ..." outside
  // its range. Numbers are always finite.
  double number(const Range& range = {}) const;
  int integer(const Range& range = {}) const;
  uint64_t unsigned_integer() const;
  bool boolean() const;
  std::string string() const;
  // A file named here: a non-empty string without a NUL byte (at which the C library would cut
  // the name: issue 44, "fire.vdb\u0000junk" read fire.vdb), joined to the origin's folder.
  std::string file() const;
  // [x, y, z]; a component outside the range is reported at its own pointer (".../1").
  Vec3 vec3(const Range& range = {}) const;
  // A nonzero [x, y, z].
  Vec3 direction() const;
  // [r, g, b] or one number for all three.
  Rgb rgb(const Range& range = {}) const;
  std::vector<JsonValue> array() const;
  // The index of the string's value in `names`; otherwise fails with
  // `unknown NOUN "value" (expected one of: a, b, c)`.
  size_t choice(std::string_view noun, const std::vector<std::string_view>& names) const;

 private:
  void check(double x, const Range& range) const;

  const nlohmann::json* json_;
  std::string pointer_;
  const JsonOrigin* origin_;
};

// A JSON object read strictly: finish() rejects every key that was never asked for, which
// catches misspelt keys that would otherwise silently fall back to defaults.
class JsonObject {
 public:
  explicit JsonObject(const JsonValue& value);  // fails "expected an object"

  const JsonValue& value() const { return value_; }
  [[noreturn]] void fail(std::string_view problem) const { value_.fail(problem); }

  bool has(const std::string& key) const { return value_.json().contains(key); }
  std::optional<JsonValue> optional(const std::string& key);
  // Fails at the missing key's pointer with "required key is missing".
  JsonValue required(const std::string& key);
  // All entries in key order (nlohmann::json keeps objects sorted), each key counted as known.
  std::vector<std::pair<std::string, JsonValue>> entries();

  // Fails at the first key that was never asked for with `unknown key` (plus `context`, e.g.
  // `for light type "point"`), adding `(did you mean "x"?)` when an asked-for key is a likely
  // intended spelling.
  void finish(std::string_view context = {}) const;

 private:
  JsonValue value_;
  std::set<std::string, std::less<>> known_;
};

// The pointer of `key` inside the value at `pointer`, escaped as RFC 6901 asks.
std::string child_pointer(const std::string& pointer, std::string_view key);

}  // namespace nimbus
