#pragma once
// Files made to harm their reader (issue 44), written byte by byte as the formats lay them out
// (io/film_file.h, job/checkpoint.h): the tests refuse them, and the files fuzzer's seed corpus
// (fuzz/files_corpus/) is written from them.

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <string>

namespace nimbus::test {

template <class T>
void append(std::string& bytes, T v) {
  char raw[sizeof v];
  std::memcpy(raw, &v, sizeof v);
  bytes.append(raw, sizeof v);
}

// A film file's header (version 4, no AOV layers) claiming width × height pixels, followed by
// `pixels` pixels of zeros (a pixel is 76 bytes: a count, three exact sums, three squares).
inline std::string film_bytes(int32_t width, int32_t height, uint64_t pixels) {
  std::string b("NIMFILM\0", 8);
  append(b, uint32_t{4});
  append(b, width);
  append(b, height);
  append(b, int32_t{0});  // exponent
  append(b, uint8_t{0});  // AOV layers
  append(b, int32_t{0});  // depth exponent
  b.append(pixels * 76, '\0');
  return b;
}

// A checkpoint (version 2) of `spp` holding `fingerprint` and the film's bytes, with the
// checksum that makes it pass as undamaged; `claimed` in place of the fingerprint's size if not 0.
inline std::string checkpoint_bytes(const std::string& fingerprint, const std::string& film,
                                    int32_t spp = 4, uint32_t claimed = 0) {
  std::string b("NIMCKPT\0", 8);
  append(b, uint32_t{2});
  append(b, spp);
  append(b, uint64_t{0});  // majorants
  append(b, claimed != 0 ? claimed : uint32_t(fingerprint.size()));
  b += fingerprint;
  b += film;
  append(b, uint32_t(crc32_z(0, reinterpret_cast<const Bytef*>(b.data()), b.size())));
  return b;
}

// A .npy file (version 1) whose header is the dictionary `header` as written, padded with spaces
// and a newline as numpy pads it, followed by `data`.
inline std::string npy_bytes(const std::string& header, const std::string& data) {
  std::string text = header;
  while ((10 + text.size() + 1) % 64 != 0) text += ' ';
  text += '\n';
  std::string b("\x93NUMPY\x01\x00", 8);
  append(b, uint16_t(text.size()));
  return b + text + data;
}

// JSON arrays nested `depth` deep.
inline std::string nested_arrays(int depth) {
  return std::string(size_t(depth), '[') + std::string(size_t(depth), ']');
}

}  // namespace nimbus::test
