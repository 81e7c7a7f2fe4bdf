#pragma once
// The exact polyhedral hull's mesh from its cone faces' regions (cone_face_region.h): every
// corner of a face's trapezoids named by the cone planes that meet there, so neighbouring faces
// share their vertices exactly; each face triangulated as the polygon it is (or, as the
// fallback, as its trapezoids with the cuts the neighbouring faces made on their common
// edges); coincident named vertices welded.

#include <vector>

#include "aggregator/hulls/cone_face_region.h"
#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// The faces' mesh and what it is made of.
struct FaceAssembly {
  bool success = false;       // false: some face's boundary is not closed loops (without cuts)
  TriangleMesh mesh;          // named vertices closer than the weld tolerance merged
  PolyhedralHullStats stats;  // its vertices by kind and the faces on the hull
  MeshCheck check;            // of `mesh`
  // True if the mesh has triangles and edges used by one of them only.
  bool Open() const { return check.open_edges > 0 && !mesh.triangles.empty(); }
  // Per mesh vertex, the sorted cone planes it lies on; only when the mesh is open (gap
  // filling needs them) or they were asked for.
  std::vector<std::vector<int>> vertex_planes;
};

// Assembles `regions` (one per plane of `set`, in plane order) into a mesh: each face as the
// polygon it is, its own work on `threads` threads (the mesh does not depend on their
// number), or with `with_cuts` as its trapezoids split at the neighbouring faces' cuts.
// Vertices closer than `weld_tolerance` (world units) are merged.
FaceAssembly AssembleFaces(const ConePlaneSet& set, const std::vector<FaceRegion>& regions,
                           bool with_cuts, int threads, double weld_tolerance,
                           bool keep_vertex_planes);

}  // namespace silnet::aggregator
