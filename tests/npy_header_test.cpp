// .npy headers read as strictly as numpy reads them, or more (issue 44): a header is accepted
// only where numpy reads the same shape and dtype. Each case records what numpy 1.24 makes of
// the header; tools/check_npy_headers.py checks that column against the numpy installed (the
// ctest NpyHeadersAsNumpyReadsThem), so the table cannot drift from numpy.

#include "nimbus/scene/npy_header.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "nimbus/scene/instances_file.h"
#include "support/process.h"

namespace npy_header_test {

using nimbus::NpyHeaderError;
using nimbus::parse_npy_header;

struct Case {
  const char* text;
  const char* numpy;  // "SHAPE DESCR" as numpy reads the file, or "refused"
  const char* ours;   // "" when accepted (then as numpy reads it), else part of the error
};

// One case a line: tools/check_npy_headers.py reads these lines.
const Case kCases[] = {
    // As numpy.save writes them, and other forms numpy reads alike.
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }          \n", "(2, 3) <f8", ""},
    {"{\"descr\": \"<f4\", \"shape\": (1, 3, 4), \"fortran_order\": False}", "(1, 3, 4) <f4", ""},
    {"\t {'descr':'<f8','fortran_order':False,'shape':(5,3,)}\r\n", "(5, 3) <f8", ""},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (7,), }", "(7,) <f8", ""},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (), }", "() <f8", ""},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (0, 3), }", "(0, 3) <f8", ""},
    {"{'descr': '<f8',\n 'fortran_order': False,\n 'shape': (\n1,\n 3)\n}", "(1, 3) <f8", ""},
    // What numpy refuses.
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (-1, 3), }", "refused",
     "a dimension that is not a whole number >= 0 at byte 51"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (2.3, 4), }", "refused",
     "a dimension that is not a whole number >= 0 at byte 52"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1e3, 4), }", "refused",
     "a dimension that is not a whole number >= 0"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (True, 3), }", "refused",
     "a dimension that is not a whole number >= 0"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1), }", "refused",
     "',' after the one dimension of a tuple"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': [1, 3], }", "refused",
     "expected the shape as a tuple"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1 3), }", "refused",
     "expected ',' or ')' in the shape"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3,,), }", "refused",
     "a dimension that is not a whole number"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), ", "refused",
     "expected a key in quotes"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3)", "refused",
     "expected ',' or '}' after a value"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3)}}", "refused",
     "expected the end after the '}'"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3)} x", "refused",
     "expected the end after the '}'"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3),, }", "refused",
     "expected a key in quotes"},
    {"{'descr': '<f8' 'fortran_order': False, 'shape': (1, 3)}", "refused",
     "expected ',' or '}' after a value"},
    {"{'descr': '<f8, 'fortran_order': False, 'shape': (1, 3)}", "refused",
     "expected ',' or '}' after a value"},
    {"{'descr': '<f8', 'fortran_order': 0, 'shape': (1, 3)}", "refused",
     "expected True or False for 'fortran_order'"},
    {"{'descr': '<f8', 'fortran_order': false, 'shape': (1, 3)}", "refused",
     "expected True or False for 'fortran_order'"},
    {"{'descr': '<f8', 'fortran_order': Falsey, 'shape': (1, 3)}", "refused",
     "expected True or False for 'fortran_order'"},
    {"{'descr': '<f8', 'fortran_order': False}", "refused", "the .npy header has no 'shape'"},
    {"{'fortran_order': False, 'shape': (1, 3)}", "refused", "the .npy header has no 'descr'"},
    {"{'descr': '<f8', 'shape': (1, 3)}", "refused", "the .npy header has no 'fortran_order'"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), 'x': 1}", "refused",
     "a key other than 'descr', 'fortran_order' and 'shape'"},
    {"{'descr': '<f8\\x00', 'fortran_order': False, 'shape': (1, 3)}", "refused",
     "a string with an escape or a byte that is not printable ASCII"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999, 3)}", "refused",
     "has a dimension too large to read"},
    {"", "refused", "expected '{' at byte 0"},
    {"\n {'descr': '<f8', 'fortran_order': False, 'shape': (1, 3)}", "refused",
     "expected '{' at byte 0"},
    {"[1, 2]", "refused", "expected '{' at byte 0"},
    {"{}", "refused", "the .npy header has no 'descr'"},
    // What numpy reads otherwise than nimbus would: a duplicate key is numpy's last.
    {"{'descr': '<f4', 'fortran_order': False, 'shape': (1, 3), 'descr': '<f8'}", "(1, 3) <f8",
     "'descr' twice (numpy would take the last)"},
    {"{'descr': '<f8', 'fortran_order': True, 'shape': (1, 3), 'fortran_order': False}",
     "(1, 3) <f8", "'fortran_order' twice (numpy would take the last)"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), 'shape': (1, 3)}", "(1, 3) <f8",
     "'shape' twice (numpy would take the last)"},
    // Forms numpy reads that nimbus refuses: numpy.save writes none of them.
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (00, 3)}", "(0, 3) <f8",
     "a dimension with a leading zero"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1_000, 3)}", "(1000, 3) <f8",
     "a dimension that is not a whole number"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (0x10, 3)}", "(16, 3) <f8",
     "a dimension that is not a whole number"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (+1, 3)}", "(1, 3) <f8",
     "a dimension that is not a whole number"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': ((1), 3)}", "(1, 3) <f8",
     "a dimension that is not a whole number"},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (3L, 3)}", "(3, 3) <f8",
     "a dimension that is not a whole number"},
    {"{'descr': '<f8', # a comment\n 'fortran_order': False, 'shape': (1, 3)}", "(1, 3) <f8",
     "expected a key in quotes at byte 17"},
    {"{'descr': '<' 'f8', 'fortran_order': False, 'shape': (1, 3)}", "(1, 3) <f8",
     "expected ',' or '}' after a value"},
    {"{'\\x64escr': '<f8', 'fortran_order': False, 'shape': (1, 3)}", "(1, 3) <f8",
     "a string with an escape"},
    {"{'descr': '=f8', 'fortran_order': False, 'shape': (1, 3)}", "(1, 3) <f8",
     "holds '=f8' values; expected little-endian float64 ('<f8') or float32 ('<f4')"},
    {"{'descr': '>f8', 'fortran_order': False, 'shape': (1, 3)}", "(1, 3) >f8",
     "holds '>f8' values"},
    {"{'descr': '<f8', 'fortran_order': True, 'shape': (1, 3)}", "(1, 3) <f8",
     "is in Fortran order; save a C-ordered array"},
};

std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

TEST(NpyHeader, HostileHeadersAreRefusedAndGoodOnesReadAsNumpyReadsThem) {
  for (const Case& c : kCases) {
    const std::string text = c.text;
    try {
      const nimbus::NpyHeader h = parse_npy_header(text);
      EXPECT_STREQ(c.ours, "") << "accepted: " << text;
      EXPECT_EQ(shape_text(h.shape) + (h.item_bytes == 8 ? " <f8" : " <f4"), c.numpy) << text;
    } catch (const NpyHeaderError& e) {
      EXPECT_STRNE(c.ours, "") << "refused: " << text << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.ours), std::string::npos)
          << text << ": expected \"" << c.ours << "\" in: " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(NpyHeader, AHeaderPastNumpysLimitIsRefused) {
  std::string text = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }";
  text.resize(nimbus::kMaxNpyHeaderBytes, ' ');
  EXPECT_EQ(shape_text(parse_npy_header(text).shape), "(1, 3)");
  text += '\n';
  EXPECT_THROW(parse_npy_header(text), NpyHeaderError);
}

// The file around the header: the version and the header's length are checked before the
// header is read (a length past the file allocates nothing).
TEST(NpyHeader, TheFilesVersionAndHeaderLengthAreChecked) {
  const std::filesystem::path dir = nimbus::test::fresh_test_dir("nimbus_npy_header");
  const std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }\n";
  const std::string data(24, '\0');
  const auto npy = [&](const std::string& name, std::string version, std::uint32_t length,
                       const std::string& text) {
    std::string bytes = "\x93NUMPY" + version;
    for (int i = 0; i < (version[0] == 1 ? 2 : 4); ++i) bytes += char(length >> (8 * i) & 0xff);
    std::ofstream((dir / name).string(), std::ios::binary) << bytes << text;
    return (dir / name).string();
  };
  const auto error = [](const std::string& path) -> std::string {
    try {
      nimbus::read_instances_file(path);
    } catch (const nimbus::InstancesFileError& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::uint32_t n = std::uint32_t(header.size());
  EXPECT_EQ(nimbus::read_instances_file(npy("good.npy", {1, 0}, n, header + data)).size(), 1u);
  EXPECT_EQ(nimbus::read_instances_file(npy("v2.npy", {2, 0}, n, header + data)).size(), 1u);
  EXPECT_EQ(error(npy("minor.npy", {1, 1}, n, header + data)),
            ".npy format version 1.1 is not supported (1.0, 2.0 and 3.0 are)");
  EXPECT_EQ(error(npy("v4.npy", {4, 0}, n, header + data)),
            ".npy format version 4.0 is not supported (1.0, 2.0 and 3.0 are)");
  EXPECT_EQ(error(npy("past.npy", {2, 0}, 0xffffffff, header)),
            "a broken .npy header: its length, 4294967295 bytes, is past the end of the file");
  EXPECT_EQ(error(npy("cut.npy", {1, 0}, n, header.substr(0, 20))),
            "a broken .npy header: its length, " + std::to_string(n) +
                " bytes, is past the end of the file");
  const std::string padded = header.substr(0, header.size() - 1) + std::string(10000, ' ') + "\n";
  EXPECT_EQ(
      error(npy("long.npy", {2, 0}, std::uint32_t(padded.size()), padded + data)),
      "a .npy header of " + std::to_string(padded.size()) + " bytes; numpy reads at most 10000");
  std::filesystem::remove_all(dir);
}

}  // namespace npy_header_test
