// Every file nimbus reads is a regular file, and what it says of its own size is checked before
// it is believed (issue 44): a FIFO, a device, a directory or a dangling link given to any reader
// is one line naming it and what it is, at once (a FIFO blocked in open, /dev/zero as a grid spun
// forever); a checkpoint or a film file that claims more than it holds, or a fingerprint nested
// deeper than a scene file may be, is refused before anything of that size is allocated.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "nimbus/io/exr.h"
#include "nimbus/io/film_file.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/os/regular_file.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/instances_file.h"
#include "nimbus/scene/load.h"
#include "support/crafted_files.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace file_inputs_test {

// What a call throws, or "no error".
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

// A scene naming `path` at one of its file keys, compiled (grids are read when compiled).
std::string scene_naming(const std::string& key, const std::string& path) {
  const std::string medium = key == "density"
                                 ? R"("density": {"type": "vdb", "file": ")" + path + R"("})"
                                 : R"("sigma_a": 1, "emission": {"file": ")" + path + R"("})";
  const std::string instances =
      key == "instances" ? R"(, "instances": {"file": ")" + path + R"("})" : "";
  return R"({"camera": {"type": "perspective", "from": [0, 0, 5], "to": [0, 0, 0], "fov": 30},
    "media": {"m": {)" +
         medium + R"(}},
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}, "medium": "m")" +
         instances + "}]}";
}

struct Reader {
  const char* name;
  std::function<void(const std::string& path)> read;
  const char* prefix;      // what the message puts before "PATH: REASON"
  bool names_path = true;  // false: the reason alone, which the caller puts after the path
};

const std::vector<Reader>& readers() {
  static const std::vector<Reader> all = {
      {"scene file", [](const std::string& p) { load_scene_file(p); }, ""},
      {"checkpoint", [](const std::string& p) { load_checkpoint(p); }, ""},
      {"film file", [](const std::string& p) { load_film(p); }, ""},
      {"EXR image", [](const std::string& p) { read_exr(p); }, ""},
      {"instances file", [](const std::string& p) { read_instances_file(p); }, "", false},
      {"VDB density",
       [](const std::string& p) {
         compile_scene(load_scene_text(scene_naming("density", p), "s"));
       },
       "s: /media/m/density/file: "},
      {"temperature grid",
       [](const std::string& p) {
         compile_scene(load_scene_text(scene_naming("emission", p), "s"));
       },
       "s: /media/m/emission/file: "},
      {"instances in a scene",
       [](const std::string& p) { load_scene_text(scene_naming("instances", p), "s"); },
       "s: /objects/0/instances/file: "},
  };
  return all;
}

TEST(FileInputs, EveryReaderRefusesWhatIsNotARegularFileAtOnce) {
  test::TempDir dir("file_inputs");
  const std::string fifo = dir.file("fifo"), link = dir.file("dangling");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::filesystem::create_symlink(dir.file("nowhere"), link);
  const struct {
    std::string path, reason;
  } kinds[] = {
      {fifo, "not a regular file (a FIFO)"},
      {"/dev/zero", "not a regular file (a character device)"},
      {dir.path().string(), "cannot open file (is a directory)"},
      {link, "cannot open file (a symbolic link to a missing file)"},
      {dir.file("missing"), "cannot open file (No such file or directory)"},
  };
  for (const Reader& r : readers())
    for (const auto& k : kinds) {
      EXPECT_EQ(error_of([&] { r.read(k.path); }),
                r.prefix + (r.names_path ? k.path + ": " : "") + k.reason)
          << r.name << " of " << k.path;
    }
}

TEST(FileInputs, ARegularFileReadsSeeksAndTellsAsAFileStream) {
  test::TempDir dir("file_inputs_stream");
  std::string bytes;
  for (int i = 0; i < 200000; ++i) bytes += char('a' + i % 26);
  std::ofstream(dir.file("f"), std::ios::binary) << bytes;
  RegularFile file(dir.file("f"));
  EXPECT_EQ(file.size(), bytes.size());
  std::istream& in = file.stream();
  std::string head(70000, '\0');
  ASSERT_TRUE(in.read(head.data(), std::streamsize(head.size())));
  EXPECT_EQ(head, bytes.substr(0, 70000));
  EXPECT_EQ(in.tellg(), std::streampos(70000));
  in.seekg(199990);
  std::string tail(20, '\0');
  in.read(tail.data(), 20);
  EXPECT_EQ(in.gcount(), 10);
  EXPECT_EQ(tail.substr(0, 10), bytes.substr(199990));
  in.clear();
  in.seekg(3);
  EXPECT_EQ(char(in.get()), bytes[3]);
  EXPECT_EQ(in.tellg(), std::streampos(4));
}

// Issue 44: a 29-byte film file claiming 4096 x 4096 pixels allocated 1.3 GB before it said "cut
// short", one claiming 16384^2 raised bad_alloc; a checkpoint whose checksum is right held a
// fingerprint 100 000 levels deep and crashed --resume.
TEST(FileInputs, SizesAndDepthsInAFileAreCheckedBeforeTheyAreBelieved) {
  test::TempDir dir("file_inputs_crafted");
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir.file(name), std::ios::binary) << bytes;
    return dir.file(name);
  };
  const std::string small = write("4096.film", test::film_bytes(4096, 4096, 0));
  EXPECT_EQ(std::filesystem::file_size(small), 29u);
  EXPECT_EQ(error_of([&] { load_film(small); }),
            small +
                ": the film file is damaged or cut short (its header claims 4096x4096 pixels, "
                "1275068416 bytes, and 0 follow)");
  const std::string large = write("16384.film", test::film_bytes(16384, 16384, 1));
  EXPECT_EQ(error_of([&] { load_film(large); }),
            large +
                ": the film file is damaged or cut short (its header claims 16384x16384 "
                "pixels, 20401094656 bytes, and 76 follow)");
  // The film inside a checkpoint is bounded by the checkpoint's bytes, not the file's end.
  const std::string claims =
      write("claims.nck", test::checkpoint_bytes("{}", test::film_bytes(2, 2, 1)));
  EXPECT_EQ(error_of([&] { load_checkpoint(claims); }),
            claims +
                ": the film file is damaged or cut short (its header claims 2x2 pixels, 304 "
                "bytes, and 76 follow)");
  const std::string deep = write(
      "deep.nck", test::checkpoint_bytes(test::nested_arrays(100000), test::film_bytes(1, 1, 1)));
  const std::string message = error_of([&] { load_checkpoint(deep); });
  EXPECT_EQ(message.rfind(deep + ": the fingerprint: /0/0/0/", 0), 0u) << message;
  EXPECT_NE(message.find("arrays and objects nest deeper than 1025 levels"), std::string::npos)
      << message;
  // As deep as a scene's document in a fingerprint may be, and an honest film: read.
  const std::string fine = write(
      "fine.nck", test::checkpoint_bytes("{\"scene\": " + test::nested_arrays(kMaxJsonDepth) + "}",
                                         test::film_bytes(1, 1, 1)));
  EXPECT_EQ(error_of([&] { load_checkpoint(fine); }), "no error");
  // Duplicate keys and numbers beyond a double, as in a scene file.
  const std::string twice =
      write("twice.nck", test::checkpoint_bytes(R"({"a": 1, "a": 2})", test::film_bytes(1, 1, 1)));
  EXPECT_EQ(error_of([&] { load_checkpoint(twice); }),
            twice + R"(: the fingerprint: /a: duplicate key "a")");
  const std::string huge =
      write("huge.nck", test::checkpoint_bytes(R"({"a": 1e999})", test::film_bytes(1, 1, 1)));
  EXPECT_EQ(error_of([&] { load_checkpoint(huge); }),
            huge +
                ": the fingerprint: /a: the number 1e999 is beyond a double's range (finite, at "
                "most 1.8e308 in magnitude)");
  // A fingerprint's size past the file's end, within the size a fingerprint may have.
  const std::string past = write(
      "past.nck", test::checkpoint_bytes("{}", test::film_bytes(1, 1, 1), 4, uint32_t{1} << 25));
  EXPECT_EQ(error_of([&] { load_checkpoint(past); }),
            past + ": not a nimbus checkpoint (its fingerprint's size)");
}

}  // namespace file_inputs_test
}  // namespace nimbus
