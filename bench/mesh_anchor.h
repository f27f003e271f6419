// What the other meshers' drivers of bench/mesh_side_by_side.py share (bench/mesh_openvdb.cpp,
// bench/mesh_cgal.cpp): the shape's function is nimbus's own (a scene object's tape, as
// bench/mesh_error.cpp reads it), the mesh is written by nimbus's STL writer, and the driver
// prints one JSON line, the seconds to mesh and write and the triangles, as
// bench/libfive/mesh_libfive.cpp does.
//
//   DRIVER SCENE SETTING THREADS OUT.stl
#pragma once

#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>

#include "nimbus/io/mesh_file.h"
#include "nimbus/mesh/mesh.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace mesh_anchor {

// Runs `mesh` on the scene's first object's tape with the setting, on THREADS threads, writes
// its mesh and prints the JSON line; main's whole body.
inline int run(int argc, char** argv, const char* name,
               const std::function<nimbus::TriangleMesh(const nimbus::Tape&, double)>& mesh) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s SCENE SETTING THREADS OUT.stl\n", name);
    return 2;
  }
  try {
    const nimbus::Scene scene = nimbus::compile_scene(nimbus::load_scene_file(argv[1]));
    const nimbus::Tape& tape = scene.objects.at(0).tape;
    const double setting = std::stod(argv[2]);
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                std::size_t(std::stoi(argv[3])));
    // Meshing and writing, as nimbus export-mesh's own time counts them (less its scene loading).
    const auto start = std::chrono::steady_clock::now();
    nimbus::TriangleMesh m = mesh(tape, setting);
    m.normals.assign(m.positions.size(), nimbus::Vec3{0, 0, 0});  // STL writes facet normals
    nimbus::write_mesh(argv[4], m);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("{\"seconds\": %.6f, \"triangles\": %zu}\n", seconds, m.triangles.size());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 2;
  }
}

}  // namespace mesh_anchor
