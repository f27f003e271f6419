// CGAL's Delaunay refinement mesher (Mesh_3, from Debian's libcgal-dev) on nimbus's own function,
// for bench/mesh_side_by_side.py (docs/benchmarks.md, "Meshes side by side"):
//
//   mesh_cgal SCENE FACET_DISTANCE THREADS OUT.stl
//
// The domain is Labeled_mesh_domain_3::create_implicit_mesh_domain over −F (CGAL's implicit
// functions are negative inside) in a sphere around the object's bounds, its surface points found
// to 10⁻⁶ of the sphere's box's half-diagonal (CGAL's default, 10⁻³, would be above the error
// bounds compared). The criteria are surface ones only: facet angle 30°, facet size (the radius
// of a facet's surface Delaunay ball) a tenth of the bounds' diagonal, facet distance the
// setting; no cell criteria, no perturbation or exudation, since only the surface is kept (the
// facets of the complex). Mesh_3 rather than the older Surface_mesher (make_surface_mesh): the
// same kind of Delaunay refinement by the same facet criteria, but Mesh_3 is the maintained one
// and runs in parallel on oneTBB, so that the 2-thread time means something (on one thread the
// sequential mesher runs; its meshes differ by about 1 % from run to run, the parallel ones
// more). No sharp features are
// given: CGAL, like the other meshers, sees only the function. Built only where CMake finds CGAL,
// and on request.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/make_mesh_3.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <map>

#include "mesh_anchor.h"
#include "nimbus/frep/tape.h"

namespace {

using namespace nimbus;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<Kernel>;

template <class Concurrency>
TriangleMesh refine(const Tape& tape, double facet_distance) {
  using Triangulation =
      typename CGAL::Mesh_triangulation_3<Domain, CGAL::Default, Concurrency>::type;
  using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation>;
  using Criteria = CGAL::Mesh_criteria_3<Triangulation>;
  const Box& bounds = tape.bounds.box;
  const Vec3 c = bounds.center();
  const double diagonal = length(bounds.extent());
  // Just outside the bounds, where −F > 0.
  const double radius = 0.55 * diagonal;
  const auto function = [&tape](const Kernel::Point_3& p) {
    return -evaluate(tape, Vec3{p.x(), p.y(), p.z()});
  };
  CGAL::Random random(0);
  const Domain domain = Domain::create_implicit_mesh_domain(
      function, Kernel::Sphere_3({c.x, c.y, c.z}, radius * radius), 1e-6, &random);
  const Criteria criteria(CGAL::parameters::facet_angle = 30,
                          CGAL::parameters::facet_size = 0.1 * diagonal,
                          CGAL::parameters::facet_distance = facet_distance);
  const Complex complex = CGAL::make_mesh_3<Complex>(
      domain, criteria, CGAL::parameters::no_perturb(), CGAL::parameters::no_exude());
  TriangleMesh m;
  std::map<typename Triangulation::Vertex_handle, std::uint32_t> index;
  const auto vertex = [&](typename Triangulation::Vertex_handle v) {
    const auto [it, fresh] = index.try_emplace(v, std::uint32_t(m.positions.size()));
    if (fresh) {
      const auto& p = v->point();
      m.positions.push_back({p.x(), p.y(), p.z()});
    }
    return it->second;
  };
  for (auto f = complex.facets_in_complex_begin(); f != complex.facets_in_complex_end(); ++f) {
    const auto& [cell, i] = *f;
    m.triangles.push_back({vertex(cell->vertex((i + 1) & 3)), vertex(cell->vertex((i + 2) & 3)),
                           vertex(cell->vertex((i + 3) & 3))});
  }
  return m;
}

// On one thread CGAL's sequential mesher, which takes no locks; on more its parallel one.
TriangleMesh mesh_cgal(const Tape& tape, double facet_distance) {
  if (tbb::this_task_arena::max_concurrency() > 1)
    return refine<CGAL::Parallel_tag>(tape, facet_distance);
  return refine<CGAL::Sequential_tag>(tape, facet_distance);
}

}  // namespace

int main(int argc, char** argv) {
  return mesh_anchor::run(argc, argv, "mesh_cgal", mesh_cgal);
}
