#pragma once
// The header of a NumPy .npy file: the text after the magic string, the version and the length
// (docs/scene-format.md, "instances"). numpy reads it as a Python dict literal (ast.literal_eval)
// and checks its keys and values; a looser reading than numpy's would render a file that numpy
// itself refuses or reads otherwise (issue 44: a shape of (-1, 3) read as (1, 3), (2.3, 4) as
// (2, 3, 4)). This parser takes a strict subset of what numpy accepts, as numpy.save writes it,
// and refuses the rest.

#include <cstddef>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace nimbus {

// numpy's own limit on a header's length (numpy.lib.format._MAX_HEADER_SIZE): np.load refuses
// a longer one unless allow_pickle=True.
inline constexpr std::size_t kMaxNpyHeaderBytes = 10000;

// A problem with a header, in words without the file's name ("the .npy header has no 'shape'").
struct NpyHeaderError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct NpyHeader {
  int item_bytes = 8;  // 8: float64 ('<f8'), 4: float32 ('<f4')
  std::vector<std::size_t> shape;
};

// Parses `text`, e.g. "{'descr': '<f8', 'fortran_order': False, 'shape': (1000, 3, 4), }" and
// its padding of spaces and a newline. Accepted: at most kMaxNpyHeaderBytes bytes; leading
// spaces or tabs; one dict whose keys are exactly 'descr', 'fortran_order' and 'shape', each
// once, in any order, as strings in single or double quotes without escapes, with or without a
// trailing comma; 'descr' '<f8' or '<f4', 'fortran_order' False, 'shape' a tuple of decimal
// whole numbers below 10^18 (a one-element tuple with its comma); spaces, tabs and newlines
// between the tokens and after the dict. Throws NpyHeaderError otherwise: for anything numpy
// refuses or would read differently (negative or fractional dimensions, a duplicate key, which
// numpy would take the last of, a missing brace), and for the rarer forms numpy also accepts
// (comments, escapes, concatenated strings, Python 2's 3L, other spellings of the dtype).
NpyHeader parse_npy_header(std::string_view text);

}  // namespace nimbus
