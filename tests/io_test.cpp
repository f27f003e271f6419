#include <gtest/gtest.h>
#include <png.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "nimbus/io/atomic_file.h"
#include "nimbus/io/exr.h"
#include "nimbus/io/output.h"
#include "nimbus/io/png.h"

namespace nimbus {
namespace io_test {

namespace fs = std::filesystem;

// Each test writes into a fresh directory of its own, so leftovers are easy to see.
class IoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("nimbus_io_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

Image test_image(int w, int h) {
  Image image{w, h, std::vector<float>(3 * w * h)};
  for (size_t i = 0; i < image.rgb.size(); ++i)
    image.rgb[i] = static_cast<float>(i) * 0.37f - 3.0f + 1e-7f * static_cast<float>(i * i);
  image.rgb[1] = 1e30f;
  image.rgb[2] = 1.17549435e-38f;  // smallest normal: floats, not halves
  return image;
}

// Reads an 8-bit RGB PNG with libpng's simplified interface.
std::vector<uint8_t> read_png_rgb8(const std::string& file, int& width, int& height) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, file.c_str())) throw std::runtime_error(png.message);
  png.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> bytes(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, bytes.data(), 0, nullptr))
    throw std::runtime_error(png.message);
  width = static_cast<int>(png.width);
  height = static_cast<int>(png.height);
  return bytes;
}

TEST_F(IoTest, ExrRoundTripIsExact) {
  const Image image = test_image(7, 5);
  write_exr(path("a.exr"), image);
  const Image back = read_exr(path("a.exr"));
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  ASSERT_EQ(back.rgb.size(), image.rgb.size());
  for (size_t i = 0; i < image.rgb.size(); ++i) EXPECT_EQ(back.rgb[i], image.rgb[i]) << i;
  EXPECT_EQ(listing(), std::vector<std::string>{"a.exr"});
}

TEST_F(IoTest, ExrReadOfMissingFileNamesThePath) {
  EXPECT_EQ(error_of([&] { read_exr(path("none.exr")); }).rfind(path("none.exr") + ": ", 0), 0u);
}

TEST(Srgb, EncodesKnownValues) {
  EXPECT_EQ(encode_srgb8(0.0f), 0);
  EXPECT_EQ(encode_srgb8(0.5f), 188);
  EXPECT_EQ(encode_srgb8(1.0f), 255);
  EXPECT_EQ(encode_srgb8(7.0f), 255);
  EXPECT_EQ(encode_srgb8(-1.0f), 0);
  EXPECT_EQ(encode_srgb8(static_cast<float>(std::nan(""))), 0);
  EXPECT_EQ(encode_srgb8(0.0031308f * 0.5f), 5);  // linear segment: 12.92 * 0.0015654 * 255 = 5.2
  EXPECT_EQ(encode_srgb8(0.18f), 118);            // middle grey
}

TEST_F(IoTest, PngEncodesSrgbAndClamps) {
  Image image{3,
              2,
              {0.5f, 1.0f, 2.0f, 0.0f, -1.0f, 0.18f, 1.0f, 1.0f, 1.0f, 0.25f, 0.75f, 1e9f, 0.0f,
               0.0f, 0.0f, 0.5f, 0.5f, 0.5f}};
  write_png(path("a.png"), image);
  int w = 0, h = 0;
  const std::vector<uint8_t> bytes = read_png_rgb8(path("a.png"), w, h);
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 2);
  const std::vector<uint8_t> expected{188, 255, 255, 0, 0, 118, 255, 255, 255,
                                      137, 225, 255, 0, 0, 0,   188, 188, 188};
  EXPECT_EQ(bytes, expected);
  EXPECT_EQ(listing(), std::vector<std::string>{"a.png"});
}

TEST_F(IoTest, AtomicWriteReplacesAndLeavesNoTemporaryFile) {
  std::ofstream(path("out.txt")) << "old";
  write_atomically(path("out.txt"), [](const std::string& temp) { std::ofstream(temp) << "new"; });
  std::ifstream in(path("out.txt"));
  std::string content;
  in >> content;
  EXPECT_EQ(content, "new");
  EXPECT_EQ(listing(), std::vector<std::string>{"out.txt"});
}

TEST_F(IoTest, FailedAtomicWriteKeepsTheOldFileAndRemovesTheTemporary) {
  std::ofstream(path("out.txt")) << "old";
  const std::string error = error_of([&] {
    write_atomically(path("out.txt"), [](const std::string& temp) {
      std::ofstream(temp) << "half";
      throw std::runtime_error("disk full");
    });
  });
  EXPECT_EQ(error, path("out.txt") + ": disk full");
  std::ifstream in(path("out.txt"));
  std::string content;
  in >> content;
  EXPECT_EQ(content, "old");
  EXPECT_EQ(listing(), std::vector<std::string>{"out.txt"});
}

TEST_F(IoTest, WriteIntoMissingDirectoryFailsAndCreatesNothing) {
  const Image image = test_image(2, 2);
  for (const char* name : {"a.exr", "a.png"}) {
    const std::string target = path(std::string("missing/") + name);
    const std::string error = error_of([&] { write_image(target, image); });
    EXPECT_EQ(error.rfind(target + ": ", 0), 0u) << error;
    EXPECT_FALSE(fs::exists(target));
  }
  EXPECT_TRUE(listing().empty());
}

TEST_F(IoTest, WriteImageChoosesTheFormatByExtension) {
  const Image image = test_image(4, 3);
  write_image(path("a.EXR"), image);
  write_image(path("b.Png"), image);
  EXPECT_EQ(read_exr(path("a.EXR")).rgb, image.rgb);
  int w = 0, h = 0;
  EXPECT_EQ(read_png_rgb8(path("b.Png"), w, h).size(), 36u);
  EXPECT_EQ(listing(), (std::vector<std::string>{"a.EXR", "b.Png"}));
}

TEST_F(IoTest, UnknownExtensionIsAnError) {
  const Image image = test_image(2, 2);
  EXPECT_EQ(error_of([&] { write_image(path("a.jpg"), image); }),
            path("a.jpg") + ": unknown image format (use .exr or .png)");
  EXPECT_EQ(error_of([&] { write_image(path("noext"), image); }),
            path("noext") + ": unknown image format (use .exr or .png)");
  EXPECT_TRUE(listing().empty());
}

TEST_F(IoTest, MalformedImageIsRefused) {
  const Image image{2, 2, std::vector<float>(11)};
  EXPECT_EQ(error_of([&] { write_image(path("a.exr"), image); }),
            path("a.exr") + ": image size does not match its pixel data");
  EXPECT_TRUE(listing().empty());
}

TEST_F(IoTest, OutputPathIsCheckedUpfront) {
  EXPECT_EQ(error_of([&] { check_output_path(path("a.exr")); }), "(no error)");
  EXPECT_EQ(error_of([&] { check_output_path(path("a.tif")); }),
            path("a.tif") + ": unknown image format (use .exr or .png)");
  EXPECT_EQ(error_of([&] { check_output_path(path("no/a.png")); }),
            path("no/a.png") + ": directory " + path("no") + " does not exist");
  fs::create_directory(path("d.png"));
  EXPECT_EQ(error_of([&] { check_output_path(path("d.png")); }),
            path("d.png") + ": is a directory");
  EXPECT_EQ(error_of([] { check_output_path("relative.png"); }), "(no error)");
  // Issue 16: /dev was accepted as an output folder, so /dev/full.exr was written.
  EXPECT_EQ(error_of([] { check_output_path("/dev/full.exr"); }),
            "/dev/full.exr: refusing to write into /dev (a folder of devices and kernel files)");
  EXPECT_EQ(error_of([] { check_output_path("/proc/self/x.png"); }).rfind("/proc/self/x.png: ", 0),
            0u);
  ASSERT_EQ(::mkfifo(path("pipe.png").c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { check_output_path(path("pipe.png")); }),
            path("pipe.png") + ": exists and is not a regular file");
}

// Issue 16: the outputs of one run are renamed into place together, after all are complete; a
// failure or an early end leaves neither new files nor temporaries.
TEST_F(IoTest, OutputTransactionRenamesAllOrNothing) {
  std::ofstream(path("a.png")) << "old a";
  std::ofstream(path("b.exr")) << "old b";
  {
    OutputTransaction t;
    write_image(path("a.png"), test_image(4, 3));
    EXPECT_EQ(listing().size(), 3u) << "a.png, b.exr and a.png's temporary";
    EXPECT_EQ(error_of([&] {
                write_atomically(path("b.exr"),
                                 [](const std::string&) { throw std::runtime_error("disk full"); });
              }),
              path("b.exr") + ": disk full");
    // The run gives up without commit().
  }
  EXPECT_EQ(listing(), (std::vector<std::string>{"a.png", "b.exr"}));
  std::ifstream old_a(path("a.png"));
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(old_a), {}), "old a");
  {
    OutputTransaction t;
    write_image(path("a.png"), test_image(4, 3));
    write_image(path("b.exr"), test_image(4, 3));
    std::ifstream still_old(path("b.exr"));
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(still_old), {}), "old b")
        << "nothing is in place before commit";
    t.commit();
  }
  EXPECT_EQ(listing(), (std::vector<std::string>{"a.png", "b.exr"}));
  EXPECT_EQ(read_exr(path("b.exr")).width, 4);
}

// Issue 16: a run killed outright (SIGKILL) leaves its temporary; the next run that writes the
// same output removes it, but not the temporary of a process that is still alive.
TEST_F(IoTest, TemporariesOfDeadRunsAreRemovedByTheNextWrite) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);  // its pid is now free: a dead run's
  const std::string dead = "out.png.tmp-" + std::to_string(child) + "-0";
  const std::string alive = "out.png.tmp-" + std::to_string(::getpid()) + "-999";
  std::ofstream(path(dead)) << "half an image";
  std::ofstream(path(alive)) << "being written";
  std::ofstream(path("other.png.tmp-" + std::to_string(child) + "-0")) << "not ours";
  write_image(path("out.png"), test_image(2, 2));
  std::vector<std::string> expected = {alive, "other.png.tmp-" + std::to_string(child) + "-0",
                                       "out.png"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(listing(), expected);
}

}  // namespace io_test
}  // namespace nimbus
