#pragma once
// Writing a triangle mesh (mesh/mesh.h) as PLY (binary little-endian, with normals), OBJ (text,
// with normals) or STL (binary, facet normals), chosen by the extension, atomically. Small
// writers of nimbus's own: the three formats are a header and flat arrays, and Debian's
// general mesh library (assimp) would add a large dependency for them (docs/meshes.md).

#include <optional>
#include <string>

#include "nimbus/mesh/mesh.h"

namespace nimbus {

enum class MeshFormat { Ply, Obj, Stl };

// The format of a path's extension (case-insensitive), or none.
std::optional<MeshFormat> mesh_format(const std::string& path);

// Writes the mesh atomically (io/atomic_file.h). Throws std::runtime_error("PATH: problem"): an
// unknown extension ("unknown mesh format (use .ply, .obj or .stl)"), or a failed write.
void write_mesh(const std::string& path, const TriangleMesh& mesh);

}  // namespace nimbus
