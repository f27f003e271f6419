#pragma once
// Writing a triangle mesh (mesh/mesh.h) as PLY (binary little-endian, with normals), OBJ (text,
// with normals), STL (binary, facet normals) or glTF 2.0 binary (.glb: positions, normals,
// 32-bit indices), chosen by the extension, atomically. Small writers of nimbus's own: the four
// formats are a header and flat arrays (GLB's header a JSON text), and Debian's general mesh
// library (assimp) or its glTF library (tinygltf) would add a dependency for them
// (docs/meshes.md).

#include <optional>
#include <string>

#include "nimbus/mesh/mesh.h"

namespace nimbus {

enum class MeshFormat { Ply, Obj, Stl, Glb };

// The format of a path's extension (case-insensitive), or none.
std::optional<MeshFormat> mesh_format(const std::string& path);

// Writes the mesh atomically (io/atomic_file.h). Throws std::runtime_error("PATH: problem"): an
// unknown extension ("unknown mesh format (use .ply, .obj, .stl or .glb)"), a mesh the format
// cannot hold (STL past 2^32 triangles; GLB empty or past 4 GiB), or a failed write.
void write_mesh(const std::string& path, const TriangleMesh& mesh);

}  // namespace nimbus
