#include "nimbus/mesh/mesh.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace nimbus {

void append(TriangleMesh& a, const TriangleMesh& b) {
  const auto base = static_cast<std::uint32_t>(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  for (const auto& t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

double enclosed_volume(const TriangleMesh& mesh) {
  double v = 0;  // Σ p0 · (p1 × p2) / 6
  for (const auto& t : mesh.triangles)
    v += dot(mesh.positions[t[0]], cross(mesh.positions[t[1]], mesh.positions[t[2]]));
  return v / 6;
}

double surface_area(const TriangleMesh& mesh) {
  double a = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3& p = mesh.positions[t[0]];
    a += length(cross(mesh.positions[t[1]] - p, mesh.positions[t[2]] - p));
  }
  return a / 2;
}

namespace {

int find(std::vector<int>& parent, int i) {
  while (parent[size_t(i)] != i) i = parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
  return i;
}

}  // namespace

MeshTopology mesh_topology(const TriangleMesh& mesh) {
  MeshTopology top;
  // Directed edges, sorted: each undirected edge must appear once in each direction.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> directed;
  directed.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) directed.emplace_back(t[size_t(k)], t[size_t((k + 1) % 3)]);
  std::sort(directed.begin(), directed.end());
  top.watertight = std::adjacent_find(directed.begin(), directed.end()) == directed.end();
  for (const auto& [a, b] : directed)
    if (a == b || !std::binary_search(directed.begin(), directed.end(), std::make_pair(b, a)))
      top.watertight = false;
  // Vertices the triangles use, and components through shared vertices.
  const std::size_t n = mesh.positions.size();
  std::vector<char> used(n, 0);
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      used[t[size_t(k)]] = 1;
      parent[size_t(find(parent, int(t[size_t(k)])))] = find(parent, int(t[0]));
    }
  long vertices = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (used[i]) {
      ++vertices;
      top.components += find(parent, int(i)) == int(i);
    }
  const long edges = long(directed.size() / 2);
  top.euler = vertices - edges + long(mesh.triangles.size());
  if (!top.watertight) return top;
  // One fan per vertex: walking from an outgoing edge (v, a) to the next triangle's, around v,
  // returns to the start after visiting every triangle at v.
  std::vector<std::uint32_t> next(directed.size());  // per directed edge (v, a): the edge (v, b)
  auto index = [&](std::uint32_t a, std::uint32_t b) {
    return std::size_t(std::lower_bound(directed.begin(), directed.end(), std::make_pair(a, b)) -
                       directed.begin());
  };
  // In triangle (v, a, b), the edge (v, a) is followed around v by (v, b)'s twin direction: the
  // triangle sharing (b, v) reversed, i.e. the outgoing edge (v, b).
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = t[size_t(k)], a = t[size_t((k + 1) % 3)], b = t[size_t((k + 2) % 3)];
      next[index(v, a)] = std::uint32_t(index(v, b));
    }
  std::vector<int> fans(n, 0);
  std::vector<char> seen(directed.size(), 0);
  for (std::size_t e = 0; e < directed.size(); ++e) {
    if (seen[e]) continue;
    ++fans[directed[e].first];
    for (std::size_t f = e; !seen[f]; f = next[f]) seen[f] = 1;
  }
  top.manifold = true;
  for (std::size_t i = 0; i < n; ++i)
    if (used[i] && fans[i] != 1) top.manifold = false;
  return top;
}

}  // namespace nimbus
