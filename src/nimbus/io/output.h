#pragma once
// Choosing the image writer from the output file's extension, and checking an output path before
// a long render rather than after it.

#include <string>
#include <vector>

#include "nimbus/io/image.h"
#include "nimbus/scene/input_file.h"

namespace nimbus {

// Writes `.exr` (linear float) or `.png` (8-bit sRGB), extension case-insensitive. Throws
// std::runtime_error("PATH: unknown image format (use .exr or .png)") for any other extension.
void write_image(const std::string& path, const Image& image);

// Throws std::runtime_error("PATH: problem") unless the extension is known, the directory exists
// and is writable and is not /dev, /proc or /sys (or inside them), and the path is not itself a
// directory or another file that is not a regular one.
void check_output_path(const std::string& path);

// The same check for a file of any kind: the directory exists and is writable, and the path is
// not itself a directory.
void check_writable_path(const std::string& path);

// A file that a run reads or writes, with what named it: "-o", "--stats", "the scene file",
// a JSON pointer in the scene.
struct NamedFile {
  std::string what;
  std::string path;
};

// The files a run of `scene_file` reads: the scene file ("the scene file") and each file
// compiling it read ("the file of /media/cloud/density/file"), for check_outputs_distinct.
std::vector<NamedFile> scene_inputs(const std::string& scene_file,
                                    const std::vector<InputFile>& read);

// Whether two paths name one file: the same device and inode where both exist, else the same
// absolute path once the links along it that exist are resolved.
bool same_file(const std::string& a, const std::string& b);

// Throws std::runtime_error("WHAT PATH: problem") for the first output that is one of the inputs
// or an earlier output, which writing it would destroy or overwrite. `reader` names who reads
// the inputs: "-o out.json: is the scene file (out.json), which the run reads".
void check_outputs_distinct(const std::vector<NamedFile>& outputs,
                            const std::vector<NamedFile>& inputs,
                            const std::string& reader = "the run");

}  // namespace nimbus
