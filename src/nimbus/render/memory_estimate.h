#pragma once
// What a render will hold in memory at its peak, estimated before anything large is allocated,
// so that a request the machine cannot hold is refused with one line instead of being killed
// by the OS (a 16384 × 16384 film took 15.7 GB without a word).

#include <cstddef>
#include <cstdint>
#include <string>

#include "nimbus/render/aov.h"

namespace nimbus {

struct MemoryEstimate {
  double film = 0;     // per-pixel sums, sums of squares and counts
  double image = 0;    // the float image written from the film, and a writer's copy
  double octrees = 0;  // majorant octrees at their node budget, while being built
  // The index-matched media's lookup grid and the field octree's lists of them, at their caps
  double media_lists = 0;
  double threads = 0;  // per-thread state of the render
  double objects = 0;  // the compiled objects (object_memory)
  double total() const { return film + image + octrees + media_lists + threads + objects; }
};

// What `copies` compiled objects whose shapes hold `quadrics` quadrics each take: their tapes,
// bounds, surfaces and the surface index over them (measured at 10^6 copies: about 1.3 KB a
// sphere, 2.5 KB a free form of five quadrics; charged a little more).
double object_memory(std::size_t copies, std::size_t quadrics);

// For an image of width × height, `octrees` majorant octrees (the field's and one per solid
// holding a medium) with `bins` bounds each per node, `field_objects` index-matched objects
// holding a medium, rendered on `threads` threads, with the AOV layers `aovs`.
MemoryEstimate estimate_render_memory(int width, int height, std::size_t octrees, int bins,
                                      int threads, std::size_t field_objects, AovSet aovs = {});

// The memory the system can still give (MemAvailable of /proc/meminfo), or 0 when unknown.
std::uint64_t available_memory();

// Parses a size: a number of bytes with an optional binary suffix K, M, G or T ("512M", "8G",
// "1.5G"). Throws std::invalid_argument with the problem for anything else.
std::uint64_t parse_memory_size(const std::string& text);

// "17.3 GiB", "512.0 MiB", for messages.
std::string format_memory(double bytes);

}  // namespace nimbus
