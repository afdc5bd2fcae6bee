// Private to core/: CGAL's regular triangulation with an index per vertex,
// the one type both the mixed complex and the live-pair walk build on.
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

namespace skinmesh::detail {

using RtKernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// Info: the vertex's index (a ball, or a ball pair packed in one integer).
template <class Info>
using RegularTriangulation = CGAL::Regular_triangulation_3<
    RtKernel, CGAL::Triangulation_data_structure_3<
                  CGAL::Triangulation_vertex_base_with_info_3<Info, RtKernel,
                                                              CGAL::Regular_triangulation_vertex_base_3<RtKernel>>,
                  CGAL::Regular_triangulation_cell_base_3<RtKernel>>>;

}  // namespace skinmesh::detail
