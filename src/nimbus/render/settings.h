#pragma once
// Every render setting of the scene format, declared once: its key (the dotted path in the scene
// file, and for --set), its type and range, its default (RenderSettings' own) and one line of
// documentation. The declaration drives the loader (scene/load.cpp reads the "film",
// "integrator" and "spectrum" sections through it), the "settings" object of --stats, the table
// of docs/scene-format.md (`nimbus settings --markdown`, checked by a test) and, through the
// scene document, the fingerprint of checkpoints (job/fingerprint.h).
//
// A new setting: a member of RenderSettings (render/scene.h), its entry in render/settings.cpp,
// and the code that acts on it.

#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "nimbus/math/range.h"
#include "nimbus/render/scene.h"

namespace nimbus {

struct SettingType {
  // ChoiceList: an array of distinct names, each a Choice's.
  enum class Kind { Integer, Unsigned, Number, Boolean, Choice, ChoiceList };
  Kind kind = Kind::Integer;
  Range range;                          // Integer, Number
  std::vector<std::string_view> names;  // Choice, ChoiceList: the names a file may give
  std::string_view noun;                // Choice, ChoiceList: what messages call one ("tracking")
};

struct Setting {
  std::string_view key;  // "integrator.max_depth"
  SettingType type;
  std::string_view doc;  // one line
  // The setting's value as the scene file writes it, and its assignment from such a value once
  // the loader has checked it against `type` (and `check`).
  std::function<nlohmann::json(const RenderSettings&)> get;
  std::function<void(RenderSettings&, const nlohmann::json&)> set;
  // A check beyond the type: the problem with a value ("must be one of ..."), or "".
  std::function<std::string(const nlohmann::json&)> check;
  // The type as the docs' table says it, when `type` does not say it all.
  std::string_view type_text;
};

// All of them, in the order of the docs.
std::span<const Setting> render_settings();

// The settings' values as the scene file writes them, one object per section:
// {"film": {"width": 640, ...}, "integrator": {..., "majorant": {...}}, "spectrum": {...}}.
nlohmann::json settings_json(const RenderSettings& settings);

// The docs' table of the settings of `section` ("film", "integrator", "spectrum"): Markdown
// rows of key, type, default and meaning.
std::string settings_markdown(std::string_view section);

}  // namespace nimbus
