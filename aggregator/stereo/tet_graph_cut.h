#pragma once
// The graph cut of the adaptive stereo (thesis 7.4.1): a minimum s-t cut on the dual graph of
// the conforming tetrahedral mesh, one node per cell, one n-link per face shared by two cells;
// interior cells tied to the source, exterior ones merged into the sink (tet_cell_labels.h: a
// face between an exterior cell and another is the other's sink link). A face's
// capacity is its cost as a piece of surface (eq. 7.2):
//   phi(f) = (1 - exp(-tan(pi/2 (w_f - 1))^2 / sigma^2)) a_f + lambda a_f,
// a_f the face's area, w_f its photo-consistency in [0, 1]: the best mu x mu plane patch on
// the face (either side's normal), truncated at 0. Faces larger than a few footprints (cells
// the refinement left coarse, where no surface was found) get w_f = 0. The cut's surface is
// the faces between source and sink cells, oriented outwards.
// Beyond eq. 7.2, a visibility-based ballooning term (the thesis's ref. [58]): a free cell
// that fewer than `ballooning_max_votes` rays of quasi-dense points crossed (no view saw
// through it) is tied to the source with ballooning x volume / footprint, so the cut does not
// shrink away from surfaces whose tetrahedral faces score poorly; cells seen through get
// none, which keeps concavities that some view sees open. Having no sink link, the term can
// never carve the inside.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/bcc_lattice.h"
#include "aggregator/stereo/patch_photo_consistency.h"
#include "aggregator/stereo/tet_cell_labels.h"
#include "aggregator/stereo/tet_surface.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the cut.
struct TetGraphCutOptions {
  double lambda = 0.1;                    // area term, per unit of face area
  double sigma = 0.5;                     // width of the photo-consistency cost
  double max_scored_face_footprints = 4;  // longer face edges: not scored (w_f = 0)
  double ballooning = 0.3;                // per free cell, x volume / footprint; 0 = none
  uint32_t ballooning_max_votes = 1;      // cells crossed by this many rays: no ballooning
  // A face whose patch of every other point scores below this keeps that score (its cost is
  // within 2 % of the full cost below 0.5 anyway); -1 scores every face in full.
  double patch_prefilter = 0.4;
  int threads = 0;

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// The cut of one mesh, kept so cells can be forced inside and the cut updated (7.4.2).
class TetGraphCut {
 public:
  // Builds the dual graph of `mesh` (its `faces` from SortedCellFaces, kept) with `labels` and
  // the rays that crossed each cell (`votes`, LabelCells; both one per cell, votes empty:
  // every free cell balloons) and solves it. `footprint` (metres) sets the patches' point
  // spacing and the ballooning's unit. The mesh must outlive the cut. Once `cancel` (may be
  // null) is cancelled it stops before the max-flow: the cut is then empty (Cancelled()) and
  // must not be forced.
  TetGraphCut(const TetMesh& mesh, std::vector<CellFace> faces,
              const std::vector<CellLabel>& labels, const std::vector<uint32_t>& votes,
              const PatchScorer& scorer, double footprint, const TetGraphCutOptions& options,
              const Progress* cancel = nullptr);
  ~TetGraphCut();

  // Per cell: 1 on the source (interior) side of the current cut.
  const std::vector<uint8_t>& Interior() const { return interior_; }
  // The faces between the sides (and interior cells' faces on the mesh's boundary), oriented
  // outwards.
  TriangleMesh Surface() const;
  // Multiplies the ballooning term by `factor` (>= 1) and updates the cut (incrementally,
  // the same minimum cut as a graph built with the raised weight). Before any cell is forced.
  // Returns how many cells became interior (in exact arithmetic none leaves the interior: the
  // cut is the minimum one with the largest source side).
  size_t RaiseBallooning(double factor);
  // The ballooning's weight relative to the options' (1 until raised).
  double ballooning_factor() const { return ballooning_factor_; }
  // Ties the cells to the source and updates the cut (incrementally). Returns how many were
  // not interior before. Cells ForceExterior tied to the sink are skipped, and so are cells
  // labelled exterior (merged into the sink when the graph was built).
  size_t ForceInterior(const std::vector<int32_t>& cells);
  // Ties the cells to the sink and updates the cut. Returns how many were interior before.
  // Cells ForceInterior tied to the source are skipped.
  size_t ForceExterior(const std::vector<int32_t>& cells);

  // The cells ForceInterior made interior, ascending.
  std::vector<int32_t> Forced() const;
  // Per cell: 1 if ForceInterior tied it to the source, 2 if ForceExterior to the sink, else 0.
  const std::vector<uint8_t>& ForcedSide() const { return forced_side_; }
  // The mesh's faces, as given.
  const std::vector<CellFace>& Faces() const;

  // True if the construction was cancelled before the cut was solved.
  bool Cancelled() const { return cancelled_; }
  size_t nodes() const { return interior_.size(); }
  size_t links() const { return links_; }
  size_t faces_scored() const { return faces_scored_; }
  // Seconds the first max-flow took (the rest of the construction is scoring the faces).
  double seconds_max_flow() const { return seconds_max_flow_; }
  double flow() const;

 private:
  size_t Force(const std::vector<int32_t>& cells, bool interior);
  // Reads interior_ from the solved flow graph.
  void ReadSides();
  struct Graph;
  const TetMesh& mesh_;
  std::unique_ptr<Graph> graph_;
  std::vector<uint8_t> interior_;
  std::vector<uint8_t> forced_side_;
  size_t links_ = 0, faces_scored_ = 0;
  double seconds_max_flow_ = 0;
  double ballooning_factor_ = 1;
  bool cancelled_ = false;
};

}  // namespace silnet::aggregator
