#pragma once
// JSON text from outside made a document safely, before anything reads its meaning: a scene
// file's bytes (a regular file of bounded size), UTF-8 without NUL bytes, no key twice in an
// object, bounded nesting, numbers within a double, and the `--set KEY=VALUE` overrides. The
// scene loader (scene/load.h), the checkpoint reader and the viewer's camera body read JSON
// through it; scene/json_reader.h then reads the document's values.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "nimbus/scene/json_reader.h"

namespace nimbus {

// How deeply arrays and objects may nest in a scene file's JSON (or a --set value), checked while
// parsing: room for kMaxShapeDepth (scene/load.h) levels of shapes (two JSON levels each: a node
// and its list of children) and the sections around them. Deeper documents are refused before
// they cost memory in proportion to the square of their depth (issue 29: 200 000 nested arrays
// took 24 GB).
inline constexpr int kMaxJsonDepth = 1024;

// The largest scene file read: far above any scene written by hand or exported, far below
// what would exhaust memory.
inline constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t{64} << 20;

// JSON text parsed as a scene file is, with its limits (comments allowed; UTF-8 without NUL bytes;
// no key twice in an object; at most `max_depth` levels; numbers within a double): every problem
// is one SceneError, "SOURCE: problem" or "SOURCE: /json/pointer: problem". For any JSON nimbus
// reads from outside (a checkpoint's fingerprint, the viewer's requests).
nlohmann::json parse_json_text(const std::string& text, const std::string& source,
                               int max_depth = kMaxJsonDepth);

// A scene file's JSON: its text, a regular file of at most kMaxSceneFileBytes (a directory, a
// FIFO, /dev/zero are one SceneError line), parsed by parse_json_text with `path` as its source.
nlohmann::json parse_json_file(const std::string& path);

// Applies one `--set KEY=VALUE`: KEY is a dotted path into the document (array elements by
// index, as in lights.0.radiance), VALUE is parsed as JSON or else taken as a string. Missing
// object keys along the path are created; a path through a value that is neither an object nor
// an array, or past the end of an array, is an error "--set KEY=VALUE: problem" (a long value
// cut short). Returns the JSON pointer of what the override owns, which later messages blame on
// it: the outermost key it created, or else the value it set.
std::string apply_override(nlohmann::json& j, const std::string& key_equals_value);

// "--set KEY=VALUE" as messages show it (apply_override's, and those blamed on an override): a
// long value is cut after 60 characters and its length said.
std::string set_flag(const std::string& key_equals_value);

}  // namespace nimbus
