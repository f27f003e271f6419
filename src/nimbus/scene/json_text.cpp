#include "nimbus/scene/json_text.h"

#include <fmt/format.h>

#include <optional>
#include <set>
#include <vector>

#include "nimbus/os/regular_file.h"

namespace nimbus {
namespace {

// The scene file's text: a regular file of at most kMaxSceneFileBytes, in UTF-8. Anything else
// (a directory, a FIFO that would block, /dev/zero that never ends, a binary file) is one line.
std::string read_file(const std::string& path) {
  try {
    RegularFile file(path);
    if (file.size() > kMaxSceneFileBytes)
      throw SceneError(fmt::format("{}: the file has {} bytes; a scene file may have at most {}",
                                   path, file.size(), kMaxSceneFileBytes));
    std::string text(file.size(), '\0');
    file.stream().read(text.data(), std::streamsize(text.size()));
    if (uint64_t(file.stream().gcount()) != file.size())
      throw SceneError(fmt::format("{}: cannot read file (read {} of its {} bytes)", path,
                                   file.stream().gcount(), file.size()));
    return text;
  } catch (const FileOpenError& e) {
    throw SceneError(e.what());
  }
}

// A scan of a JSON text that refuses a key given twice in one object (the JSON standard leaves it
// open; nlohmann's parser keeps one of them silently) and nesting deeper than kMaxJsonDepth,
// naming the JSON path; run before the text is parsed (parse_checked).
class DuplicateKeys {
 public:
  DuplicateKeys(const std::string& source, int max_depth = kMaxJsonDepth)
      : source_(source), max_depth_(max_depth) {}
  // The pointer of the value the parser reads next (a number it could not hold, say).
  std::string next_value_pointer() const {
    if (frames_.empty()) return "/";
    const Frame& f = frames_.back();
    return child_pointer(f.pointer, f.array ? std::to_string(f.index + 1) : f.key);
  }
  // next_value_pointer, its middle cut out past a few hundred characters (a deep document's).
  std::string next_value_pointer_cut() const {
    const std::string p = next_value_pointer();
    if (p.size() <= 200) return p;
    return fmt::format("{}/.../{}", p.substr(0, p.find('/', 80)),
                       p.substr(p.rfind('/', p.size() - 60) + 1));
  }
  // nlohmann's SAX interface: a scan that builds nothing, so that it stays linear in the text
  // (its DOM parser with a callback scans a whole object again at the end of each object inside
  // it: 16 000 named shapes took 1.5 s, 100 000 over a minute).
  using json = nlohmann::json;
  bool null() { return value(); }
  bool boolean(bool) { return value(); }
  bool number_integer(json::number_integer_t) { return value(); }
  bool number_unsigned(json::number_unsigned_t) { return value(); }
  bool number_float(json::number_float_t, const json::string_t&) { return value(); }
  bool string(json::string_t&) { return value(); }
  bool binary(json::binary_t&) { return value(); }
  bool start_object(std::size_t) { return open(false); }
  bool start_array(std::size_t) { return open(true); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(json::string_t& k) {
    Frame& f = frames_.back();
    f.key = k;
    if (!f.keys.insert(f.key).second)
      throw SceneError(fmt::format("{}: {}: duplicate key \"{}\"", source_,
                                   child_pointer(f.pointer, f.key), f.key));
    return true;
  }
  // A syntax error or a number beyond a double: the scan stops here, and the parse that follows
  // reports it (next_value_pointer still names the place).
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) {
    return false;
  }

 private:
  struct Frame {
    bool array;
    long index;  // arrays: the element being read
    std::set<std::string> keys;
    std::string pointer;  // of this container
    std::string key;      // objects: the key being read
  };
  void enter_element() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }
  bool value() {
    enter_element();
    return true;
  }
  bool open(bool array) {
    if (frames_.size() >= size_t(max_depth_))
      throw SceneError(fmt::format("{}: {}: arrays and objects nest deeper than {} levels", source_,
                                   next_value_pointer_cut(), max_depth_));
    enter_element();
    frames_.push_back(
        {array, -1, {}, frames_.empty() ? "" : child_pointer(here(), key_or_index()), {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return true;
  }
  // The parent's pointer and the token under which the container now opening sits.
  std::string here() const { return frames_.empty() ? "" : frames_.back().pointer; }
  std::string key_or_index() const {
    if (frames_.empty()) return "";
    const Frame& f = frames_.back();
    return f.array ? std::to_string(f.index) : f.key;
  }
  const std::string& source_;
  int max_depth_;
  std::vector<Frame> frames_;
};

// The text scanned by `keys` (which throws for a duplicate key or nesting too deep), then parsed;
// a syntax error or a number beyond a double stops the scan where it is, and the parse throws it.
nlohmann::json parse_checked(const std::string& text, DuplicateKeys& keys, bool ignore_comments) {
  nlohmann::json::sax_parse(text, &keys, nlohmann::json::input_format_t::json, true,
                            ignore_comments);
  return nlohmann::json::parse(text, nullptr, true, ignore_comments);
}

}  // namespace

// "--set KEY=VALUE" as messages show it: a value of any length (up to 240 kB were echoed) is
// cut after 60 characters.
std::string set_flag(const std::string& key_equals_value) {
  constexpr size_t kShown = 60;
  if (key_equals_value.size() <= kShown + 20) return "--set " + key_equals_value;
  return fmt::format("--set {}... ({} characters)", key_equals_value.substr(0, kShown),
                     key_equals_value.size());
}

std::string apply_override(nlohmann::json& j, const std::string& key_equals_value) {
  const auto fail = [&](const std::string& problem) {
    throw SceneError(fmt::format("{}: {}", set_flag(key_equals_value), problem));
  };
  const size_t eq = key_equals_value.find('=');
  if (eq == std::string::npos) fail("expected KEY=VALUE");
  const std::string key = key_equals_value.substr(0, eq);
  const std::string text = key_equals_value.substr(eq + 1);

  std::vector<std::string> parts;
  for (size_t start = 0;;) {
    const size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot - start));
    if (parts.back().empty()) fail("empty name in key \"" + key + "\"");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }

  nlohmann::json* cur = &j;
  std::string pointer, dotted;
  // The outermost key this override creates: what lies below it is the override's, not the
  // file's, and messages about it name the flag.
  std::optional<std::string> created;
  for (const std::string& part : parts) {
    const bool missing = cur->is_null() || (cur->is_object() && !cur->contains(part));
    if (missing && !created) created = child_pointer(pointer, part);
    if (cur->is_array()) {
      const bool digits =
          part.find_first_not_of("0123456789") == std::string::npos && part.size() < 10;
      if (!digits) fail(fmt::format("{} is an array; \"{}\" is not an index", dotted, part));
      const size_t index = std::stoul(part);
      if (index >= cur->size())
        fail(fmt::format("index {} is out of range for {} (size {})", index, dotted, cur->size()));
      cur = &(*cur)[index];
    } else if (cur->is_object()) {
      cur = &(*cur)[part];  // creates the key (as null) if missing
    } else if (cur->is_null()) {
      *cur = nlohmann::json::object();  // a key created on the way
      cur = &(*cur)[part];
    } else {
      fail(fmt::format("{} is not an object", dotted));
    }
    pointer = child_pointer(pointer, part);
    dotted += (dotted.empty() ? "" : ".") + part;
  }

  // Parsed as a file is: a duplicate key is an error (DuplicateKeys throws), and so is a number
  // beyond a double (issue 29: camera.fov=1e999 became the string "1e999").
  nlohmann::json value;
  const std::string flag = set_flag(key_equals_value);
  DuplicateKeys keys(flag);
  try {
    value = parse_checked(text, keys, false);
  } catch (const nlohmann::json::out_of_range&) {
    fail("a number beyond a double's range (finite, at most 1.8e308 in magnitude)");
  } catch (const nlohmann::json::exception&) {
    value = text;  // a bare word such as perspective
  }
  *cur = std::move(value);
  return created.value_or(pointer);
}

// The text must be UTF-8 (strictly: an overlong form or a surrogate is not) without NUL bytes,
// which the JSON parser would take for the end of the input (issue 29).
nlohmann::json parse_json_text(const std::string& text, const std::string& source, int max_depth) {
  if (const size_t at = invalid_utf8_at(text); at != std::string_view::npos)
    throw SceneError(fmt::format("{}: not UTF-8 text (byte {})", source, at));
  if (const size_t at = text.find('\0'); at != std::string::npos)
    throw SceneError(fmt::format("{}: a NUL byte at byte {} (a scene file is text)", source, at));
  nlohmann::json j;
  DuplicateKeys keys(source, max_depth);
  try {
    j = parse_checked(text, keys, /*ignore_comments=*/true);
  } catch (const nlohmann::json::out_of_range& e) {
    // "number overflow parsing '1e400'", without a place (issue 29): the path of the value.
    const std::string what = e.what();
    const size_t open = what.find('\''), close = what.rfind('\'');
    const std::string number =
        open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : "";
    throw SceneError(
        fmt::format("{}: {}: the number {} is beyond a double's range (finite, at "
                    "most 1.8e308 in magnitude)",
                    source, keys.next_value_pointer(), number));
  } catch (const nlohmann::json::exception& e) {
    // what() is "[json.exception.parse_error.101] parse error at line 3, column 5: ..." (or an
    // out_of_range error for numbers beyond double).
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    throw SceneError(source + ": " +
                     (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  return j;
}

nlohmann::json parse_json_file(const std::string& path) {
  return parse_json_text(read_file(path), path);
}

}  // namespace nimbus
