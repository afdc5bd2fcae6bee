// Private to core/: CGAL's regular triangulation with an index per vertex,
// the one type the mixed complex, the live-pair walk and the skin's
// topology count (dual_complex.hpp) build on.
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <array>

namespace skinmesh::detail {

using RtKernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// Per cell, for the dual complex's count (dual_complex.hpp): whether the
// cell is in K, whether each facet is (facet i opposite vertex i), and its
// index among the cells outside K (-1: in K).
struct DualComplexMarks {
  bool in = false;
  std::array<bool, 4> facet_in{{false, false, false, false}};
  long outside = -1;
};

// Info: the vertex's index (a ball, or a ball pair packed in one integer).
template <class Info>
using RegularTriangulation = CGAL::Regular_triangulation_3<
    RtKernel, CGAL::Triangulation_data_structure_3<
                  CGAL::Triangulation_vertex_base_with_info_3<Info, RtKernel,
                                                              CGAL::Regular_triangulation_vertex_base_3<RtKernel>>,
                  CGAL::Triangulation_cell_base_with_info_3<DualComplexMarks, RtKernel,
                                                            CGAL::Regular_triangulation_cell_base_3<RtKernel>>>>;

}  // namespace skinmesh::detail
