#pragma once
// An interactive 3D view of meshes inside a report page, on three.js from Debian's
// libjs-three (r111: global THREE, THREE.OrbitControls), opening offline from a file: the
// scripts are copied beside the page and each mesh is a script that registers itself
// (browsers refuse to fetch local files), its arrays base64-encoded little-endian.
//
//   <report dir>/viewer/three.min.js, OrbitControls.js   copied by InstallMeshViewer
//   <report dir>/viewer/<name>.js                          WriteViewerMesh
//   the page                                                MeshViewerHtml
//
// The view sets `data-viewer-state` on its container: "drawn N triangles" once it has drawn,
// "error: ..." (also shown in the page) when WebGL or a script is missing.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/report/display_mesh.h"

namespace silnet::aggregator {

// Where Debian's libjs-three puts its files.
inline constexpr const char* kThreeJsDir = "/usr/share/javascript/three";

// Copies three.min.js and OrbitControls.js from `three_dir` into `report_dir`/viewer. Returns
// an empty string, or why the viewer cannot be offered (libjs-three not installed, folder not
// writable) for the page to say instead.
std::string InstallMeshViewer(const std::filesystem::path& report_dir,
                              const std::filesystem::path& three_dir = kThreeJsDir);

// Writes `report_dir`/viewer/`name`.js registering `mesh` as window.silnetMeshes[name]
// (`name`: letters, digits, '_' or '-'), replacing an older one at once. Throws InputError
// naming the path if it cannot.
void WriteViewerMesh(const std::filesystem::path& report_dir, const std::string& name,
                     const DisplayMesh& mesh);

// One mesh of the view: the name given to WriteViewerMesh, a label for its checkbox, its
// colour (0xRRGGBB), whether it is drawn as a wireframe, and whether it shows at first.
struct ViewerLayer {
  std::string name;
  std::string label;
  unsigned colour = 0xd8c8a8;
  bool wireframe = false;
  bool visible = true;
};

// Where the view looks from at first: the direction from the meshes' centre towards `eye`,
// with `up` upwards on the screen (e.g. a photograph's camera centre and its image's up).
struct ViewerStart {
  Eigen::Vector3d eye;  // a point
  Eigen::Vector3d up;
};

// The HTML (container, checkboxes, script tags and the script) of a view of `layers`, framed
// on the visible ones, turned with the mouse (OrbitControls). `id` makes it unique in a page.
// Without `start` it looks from the side and above, z up (the simulator's world). With
// `sequence` the layers are the frames of a sequence: a slider shows one at a time (the first
// at first, whatever `visible` says), framed on all of them so the view holds still.
std::string MeshViewerHtml(const std::string& id, const std::vector<ViewerLayer>& layers,
                           const std::optional<ViewerStart>& start = std::nullopt,
                           bool sequence = false);

// Standard base64 (RFC 4648, with padding) of `size` bytes.
std::string Base64(const void* data, size_t size);

}  // namespace silnet::aggregator
