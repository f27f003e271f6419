#include "nimbus/scene/json_reader.h"

#include <fmt/format.h>
#include <fmt/ranges.h>  // fmt::join (moved here in fmt 11)

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

namespace nimbus {
namespace {

std::string describe(const Range& r) {
  return "must be " + range_text(r);
}

// Levenshtein distance, for suggesting the key a typo was meant to be.
size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// A suggestion only when the typo is small compared with the words.
bool is_likely_typo(std::string_view typed, std::string_view meant) {
  const size_t d = edit_distance(typed, meant);
  return d <= 2 && d < typed.size() && d < meant.size();
}

const char* type_name(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::object:
      return "an object";
    case nlohmann::json::value_t::array:
      return "an array";
    case nlohmann::json::value_t::string:
      return "a string";
    case nlohmann::json::value_t::boolean:
      return "a boolean";
    default:
      return "a number";
  }
}

}  // namespace

std::string child_pointer(const std::string& pointer, std::string_view key) {
  std::string out = pointer + "/";
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

std::string JsonValue::blame() const {
  std::string origin = origin_->source;
  for (const auto& o : origin_->overrides) {
    const bool inside = pointer_ == o.pointer || (pointer_.rfind(o.pointer + "/", 0) == 0);
    if (inside) origin = o.flag;  // the last override of a value is the one in effect
  }
  return fmt::format("{}: {}", origin, pointer_.empty() ? "/" : pointer_);
}

void JsonValue::fail(std::string_view problem) const {
  throw SceneError(fmt::format("{}: {}", blame(), problem));
}

namespace {

// The length of the well-formed UTF-8 sequence at text[i] (1 to 4), or 0 if there is none there
// (a stray continuation byte, an overlong form, a surrogate, past U+10FFFF, cut short).
size_t utf8_sequence_at(std::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b = byte(i);
  if (b < 0x80) return 1;
  const size_t n = (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xe ? 3 : (b >> 3) == 0x1e ? 4 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  uint32_t cp = b & (0x7f >> n);
  for (size_t k = 1; k < n; ++k) {
    if ((byte(i + k) >> 6) != 0x2) return 0;
    cp = (cp << 6) | (byte(i + k) & 0x3f);
  }
  constexpr uint32_t kLeast[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < kLeast[n] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
  return n;
}

}  // namespace

size_t invalid_utf8_at(std::string_view text) {
  for (size_t i = 0; i < text.size();) {
    const size_t n = utf8_sequence_at(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string_view::npos;
}

std::string printable_line(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const auto b = static_cast<unsigned char>(text[i]);
    const size_t n = utf8_sequence_at(text, i);
    // U+0080-U+009F (C1 controls) are two bytes, 0xc2 0x80-0x9f.
    const bool c1 = n == 2 && b == 0xc2 && static_cast<unsigned char>(text[i + 1]) < 0xa0;
    if (b == '\n') {
      out += "\\n";
    } else if (b == '\t') {
      out += "\\t";
    } else if (n == 0 || b < 0x20 || b == 0x7f || c1) {
      for (size_t k = 0; k < std::max<size_t>(n, 1); ++k)
        out += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[i + k]));
    } else {
      out.append(text.substr(i, n));
    }
    i += std::max<size_t>(n, 1);
  }
  if (out.size() <= kMaxMessageBytes) return out;
  // Cut on a character boundary: continuation bytes are 10xxxxxx.
  size_t head = kMaxMessageBytes / 2, tail = out.size() - kMaxMessageBytes / 4;
  while (head > 0 && (static_cast<unsigned char>(out[head]) >> 6) == 0x2) --head;
  while (tail < out.size() && (static_cast<unsigned char>(out[tail]) >> 6) == 0x2) ++tail;
  return fmt::format("{} ... ({} bytes in all) ... {}", out.substr(0, head), text.size(),
                     out.substr(tail));
}

void JsonValue::check(double x, const Range& range) const {
  if (!contains(range, x)) fail(describe(range));
}

double JsonValue::number(const Range& range) const {
  if (json_->is_object() && json_->contains("texture")) fail(kTakesNoTexture);
  if (!json_->is_number()) fail(fmt::format("expected a number, not {}", type_name(*json_)));
  const double x = json_->get<double>();
  if (!std::isfinite(x)) fail("must be finite");
  check(x, range);
  return x;
}

int JsonValue::integer(const Range& range) const {
  if (!json_->is_number_integer())
    fail(fmt::format("expected an integer, not {}",
                     json_->is_number() ? "a fraction" : type_name(*json_)));
  // Unsigned values above INT64_MAX compare correctly as doubles against the int range below.
  const double x = json_->is_number_unsigned() ? static_cast<double>(json_->get<uint64_t>())
                                               : static_cast<double>(json_->get<int64_t>());
  check(x, range);
  // Beyond int's range, the message gives the range that is really accepted: the caller's
  // within int's.
  Range r = range;
  constexpr double kMin = std::numeric_limits<int>::min(), kMax = std::numeric_limits<int>::max();
  if (!r.lo || *r.lo < kMin) r.lo = kMin, r.lo_open = false;
  if (!r.hi || *r.hi > kMax) r.hi = kMax, r.hi_open = false;
  check(x, r);
  return static_cast<int>(x);
}

uint64_t JsonValue::unsigned_integer() const {
  // A whole number past 2^64 - 1 is read as a double (issue 29: it was called "a fraction").
  if (json_->is_number_float()) {
    const double x = json_->get<double>();
    if (x == std::floor(x) && std::abs(x) >= 0x1p63)
      fail(x < 0 ? "must be >= 0"
                 : fmt::format("must be <= {}", std::numeric_limits<uint64_t>::max()));
  }
  if (!json_->is_number_integer())
    fail(fmt::format("expected an integer, not {}",
                     json_->is_number() ? "a fraction" : type_name(*json_)));
  if (!json_->is_number_unsigned()) fail("must be >= 0");
  return json_->get<uint64_t>();
}

bool JsonValue::boolean() const {
  if (!json_->is_boolean()) fail(fmt::format("expected true or false, not {}", type_name(*json_)));
  return json_->get<bool>();
}

std::string JsonValue::string() const {
  if (!json_->is_string()) fail(fmt::format("expected a string, not {}", type_name(*json_)));
  return json_->get<std::string>();
}

std::string JsonValue::file() const {
  const std::string name = string();
  if (name.empty()) fail("must name a file");
  if (name.find('\0') != std::string::npos) fail("a file name cannot hold a NUL byte");
  return (std::filesystem::path(origin_->folder) / name).string();
}

Vec3 JsonValue::vec3(const Range& range) const {
  if (!json_->is_array() || json_->size() != 3) fail("expected an array of 3 numbers");
  Vec3 v;
  for (int i = 0; i < 3; ++i)
    v[i] = JsonValue((*json_)[i], pointer_ + "/" + std::to_string(i), *origin_).number(range);
  return v;
}

Vec3 JsonValue::direction() const {
  const Vec3 v = vec3();
  if (dot(v, v) == 0) fail("must be a nonzero vector");
  return v;
}

Rgb JsonValue::rgb(const Range& range) const {
  if (json_->is_number()) return Rgb(number(range));
  if (!json_->is_array() || json_->size() != 3) fail("expected a number or an array of 3 numbers");
  const Vec3 v = vec3(range);
  return Rgb({v.x, v.y, v.z});
}

std::vector<JsonValue> JsonValue::array() const {
  if (!json_->is_array()) fail(fmt::format("expected an array, not {}", type_name(*json_)));
  std::vector<JsonValue> out;
  for (size_t i = 0; i < json_->size(); ++i)
    out.emplace_back((*json_)[i], pointer_ + "/" + std::to_string(i), *origin_);
  return out;
}

size_t JsonValue::choice(std::string_view noun, const std::vector<std::string_view>& names) const {
  const std::string s = string();
  size_t i = 0;
  for (std::string_view name : names) {
    if (s == name) return i;
    ++i;
  }
  fail(fmt::format("unknown {} \"{}\" (expected one of: {})", noun, s, fmt::join(names, ", ")));
}

JsonObject::JsonObject(const JsonValue& value) : value_(value) {
  if (!value.json().is_object())
    value.fail(fmt::format("expected an object, not {}", type_name(value.json())));
}

std::optional<JsonValue> JsonObject::optional(const std::string& key) {
  known_.insert(key);
  const auto it = value_.json().find(key);
  if (it == value_.json().end()) return std::nullopt;
  return JsonValue(*it, child_pointer(value_.pointer(), key), value_.origin());
}

JsonValue JsonObject::required(const std::string& key) {
  if (auto v = optional(key)) return *v;
  // A present, unasked-for key spelt almost like the missing one is most likely a typo of it.
  for (const auto& [present, json] : value_.json().items())
    if (!known_.count(present) && is_likely_typo(present, key))
      JsonValue(json, child_pointer(value_.pointer(), present), value_.origin())
          .fail(fmt::format("unknown key (did you mean \"{}\"?)", key));
  JsonValue(value_.json(), child_pointer(value_.pointer(), key), value_.origin())
      .fail("required key is missing");
}

std::vector<std::pair<std::string, JsonValue>> JsonObject::entries() {
  std::vector<std::pair<std::string, JsonValue>> out;
  for (const auto& [key, json] : value_.json().items()) {
    known_.insert(key);
    out.emplace_back(key, JsonValue(json, child_pointer(value_.pointer(), key), value_.origin()));
  }
  return out;
}

void JsonObject::finish(std::string_view context) const {
  for (const auto& [key, json] : value_.json().items()) {
    if (known_.count(key)) continue;
    std::string problem = "unknown key";
    if (!context.empty()) problem += fmt::format(" {}", context);
    size_t best = std::numeric_limits<size_t>::max();
    std::string_view suggestion;
    for (const std::string& k : known_) {
      const size_t d = edit_distance(key, k);
      if (d < best) best = d, suggestion = k;
    }
    if (is_likely_typo(key, suggestion))
      problem += fmt::format(" (did you mean \"{}\"?)", suggestion);
    JsonValue(json, child_pointer(value_.pointer(), key), value_.origin()).fail(problem);
  }
}

}  // namespace nimbus
