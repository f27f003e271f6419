// exr_to_pfm IN.exr OUT.pfm: the R, G, B channels of an OpenEXR image as 32-bit floats in a
// PFM file (little-endian, rows bottom to top), for bench/pbrt/side_by_side.py, which reads
// PFM with numpy alone. Both renderers write EXR (nimbus float, pbrt-v4 float with savefp16
// false); channels are read as FLOAT whatever their type in the file (half converts exactly).
// Built by bench/pbrt_side_by_side.sh with g++ against the system's OpenEXR; not part of the
// CMake build (bench/*.cpp are, this folder is not).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImathBox.h>

#include <cstdio>
#include <exception>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: exr_to_pfm IN.exr OUT.pfm\n");
    return 2;
  }
  try {
    Imf::InputFile file(argv[1]);
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    std::vector<float> rgb(size_t(w) * h * 3, 0.0f);
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      if (!file.header().channels().findChannel(names[c])) {
        std::fprintf(stderr, "exr_to_pfm: %s has no channel %s\n", argv[1], names[c]);
        return 1;
      }
      char* base = reinterpret_cast<char*>(rgb.data() + c) -
                   (size_t(dw.min.x) + size_t(dw.min.y) * w) * 3 * sizeof(float);
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base, 3 * sizeof(float), size_t(w) * 3 * sizeof(float)));
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    std::FILE* out = std::fopen(argv[2], "wb");
    if (!out) {
      std::perror(argv[2]);
      return 1;
    }
    std::fprintf(out, "PF\n%d %d\n-1.0\n", w, h);
    for (int y = h - 1; y >= 0; --y)  // PFM stores the bottom row first
      std::fwrite(rgb.data() + size_t(y) * w * 3, sizeof(float), size_t(w) * 3, out);
    if (std::fclose(out) != 0) {
      std::perror(argv[2]);
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exr_to_pfm: %s: %s\n", argv[1], e.what());
    return 1;
  }
  return 0;
}
