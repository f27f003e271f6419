#include "nimbus/scene/npy_header.h"

#include <fmt/format.h>

#include <cctype>
#include <optional>
#include <string>

namespace nimbus {
namespace {

// A cursor over the header's text; every error names the byte where reading stopped.
class NpyTextReader {
 public:
  explicit NpyTextReader(std::string_view text) : text_(text) {}

  [[noreturn]] void fail(std::string_view what) const {
    throw NpyHeaderError(fmt::format("a broken .npy header: {} at byte {}", what, at_));
  }
  bool done() const { return at_ == text_.size(); }
  char peek() const { return done() ? '\0' : text_[at_]; }
  void skip_space() {
    while (!done() && (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r')) ++at_;
  }
  void skip_indent() {
    while (peek() == ' ' || peek() == '\t') ++at_;
  }
  // Takes `c` after any space; false (nothing taken) when another character follows.
  bool take(char c) {
    skip_space();
    if (peek() != c) return false;
    ++at_;
    return true;
  }
  void expect(char c, std::string_view what) {
    if (!take(c)) fail(fmt::format("expected {}", what));
  }
  // A string in single or double quotes, of printable ASCII without escapes; numpy's
  // literal_eval would also join adjacent strings, which the caller's next expect() refuses.
  std::string string(std::string_view what) {
    skip_space();
    const char quote = peek();
    if (quote != '\'' && quote != '"') fail(fmt::format("expected {} in quotes", what));
    const std::size_t start = ++at_;
    while (!done() && peek() != quote) {
      if (peek() == '\\' || peek() < ' ' || peek() > '~')
        fail("a string with an escape or a byte that is not printable ASCII");
      ++at_;
    }
    if (done()) fail("an unterminated string");
    return std::string(text_.substr(start, at_++ - start));
  }
  // A Python name, [A-Za-z_][A-Za-z0-9_]*.
  std::string_view name() {
    skip_space();
    const std::size_t start = at_;
    while (!done() && (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_')) ++at_;
    return text_.substr(start, at_ - start);
  }
  // A whole number as Python writes one in decimal: digits, no leading zero, nothing glued on
  // (2.3, 3L, 1e3, 1_000 and -1 are refused; numpy reads -1 and refuses the others).
  std::size_t dimension() {
    skip_space();
    const std::size_t start = at_;
    while (!done() && peek() >= '0' && peek() <= '9') ++at_;
    const std::string_view digits = text_.substr(start, at_ - start);
    if (digits.empty() || std::isalnum(static_cast<unsigned char>(peek())) || peek() == '.' ||
        peek() == '_')
      fail("a dimension that is not a whole number >= 0");
    if (digits.size() > 1 && digits[0] == '0') fail("a dimension with a leading zero");
    if (digits.size() > 18) throw NpyHeaderError("has a dimension too large to read");
    std::size_t n = 0;
    for (const char d : digits) n = 10 * n + std::size_t(d - '0');
    return n;
  }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
};

// The shape's tuple: "()", "(3,)", "(3, 4)", "(3, 4,)". "(3)" is an int to Python, not a tuple.
std::vector<std::size_t> read_npy_shape(NpyTextReader& r) {
  r.expect('(', "the shape as a tuple, (");
  std::vector<std::size_t> shape;
  while (!r.take(')')) {
    shape.push_back(r.dimension());
    if (r.take(',')) continue;
    if (!r.take(')')) r.fail("expected ',' or ')' in the shape");
    if (shape.size() == 1) r.fail("',' after the one dimension of a tuple, (3,) not (3),");
    break;
  }
  return shape;
}

}  // namespace

NpyHeader parse_npy_header(std::string_view text) {
  if (text.size() > kMaxNpyHeaderBytes)
    throw NpyHeaderError(fmt::format("a .npy header of {} bytes; numpy reads at most {}",
                                     text.size(), kMaxNpyHeaderBytes));
  NpyTextReader r(text);
  // literal_eval strips leading spaces and tabs; a leading line break would make the next
  // line's indent an error.
  r.skip_indent();
  if (r.peek() != '{') r.fail("expected '{'");
  r.expect('{', "'{'");
  std::optional<std::string> descr;
  std::optional<bool> fortran_order;
  std::optional<std::vector<std::size_t>> shape;
  while (!r.take('}')) {
    const std::string key = r.string("a key");
    r.expect(':', "':' after a key");
    if (key == "descr") {
      if (descr) r.fail("'descr' twice (numpy would take the last)");
      descr = r.string("the 'descr'");
    } else if (key == "fortran_order") {
      if (fortran_order) r.fail("'fortran_order' twice (numpy would take the last)");
      const std::string_view value = r.name();
      if (value != "True" && value != "False") r.fail("expected True or False for 'fortran_order'");
      fortran_order = value == "True";
    } else if (key == "shape") {
      if (shape) r.fail("'shape' twice (numpy would take the last)");
      shape = read_npy_shape(r);
    } else {
      r.fail("a key other than 'descr', 'fortran_order' and 'shape'");
    }
    if (r.take(',')) continue;
    r.expect('}', "',' or '}' after a value");
    break;
  }
  r.skip_space();
  if (!r.done()) r.fail("expected the end after the '}'");
  for (const auto& [has, key] :
       {std::pair{bool(descr), "descr"}, std::pair{bool(fortran_order), "fortran_order"},
        std::pair{bool(shape), "shape"}})
    if (!has) throw NpyHeaderError(fmt::format("the .npy header has no '{}'", key));

  NpyHeader h;
  if (*descr == "<f8")
    h.item_bytes = 8;
  else if (*descr == "<f4")
    h.item_bytes = 4;
  else
    throw NpyHeaderError(
        fmt::format("holds '{}' values; expected little-endian float64 ('<f8') or float32 ('<f4')",
                    descr->substr(0, 32)));
  if (*fortran_order) throw NpyHeaderError("is in Fortran order; save a C-ordered array");
  h.shape = std::move(*shape);
  return h;
}

}  // namespace nimbus
