#pragma once
// Pictures of a model for people to look at (issue 17: "renders of the model from every camera
// beside its photo and silhouette overlay"): the mesh shaded as clay from a camera's own
// viewpoint, and one panel per view that puts the photograph, that render and the silhouette
// comparison side by side.

#include <opencv2/core/mat.hpp>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/stereo_views.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// CV_8UC3 image of the camera's size: `mesh` (any orientation) shaded by the angle between
// each triangle and the viewing ray, lit from the camera and a little from above, on a dark
// grey background. Nearer triangles hide farther ones (drawn far to near by their farthest
// vertex, which is exact for the small, non-intersecting triangles of a closed surface up to
// a pixel along occluding edges). Triangles with a vertex behind the camera are skipped.
cv::Mat RenderShadedMesh(const TriangleMesh& mesh, const CameraModel& camera);

// The silhouette's bounding box in `mask` (CV_8UC1) grown by an eighth of its larger side (at
// least 8 px) and clipped to the image; the whole image if the mask is empty.
cv::Rect SubjectBox(const cv::Mat& mask);

// The photograph, the model shaded from the view's camera, and the model's coverage against
// the silhouette (ReprojectionOverlay: white covered, red missed, blue covered outside),
// cropped to SubjectBox and side by side in one CV_8UC3 image; each panel at most
// `panel_width` pixels wide and 480 high, magnified at most 2x (pixels kept sharp).
cv::Mat ViewComparisonPanel(const StereoView& view, const TriangleMesh& mesh, int panel_width);

}  // namespace silnet::aggregator
