#include "aggregator/report/mesh_viewer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <system_error>

#include "aggregator/report/html_table.h"
#include "shared/io/replace_file.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace fs = std::filesystem;
namespace {

// The script that builds the view; ID_ and LAYERS_ are replaced by MeshViewerHtml.
constexpr const char* kViewerScript = R"JS(
(function () {
  const root = document.getElementById(ID_);
  const say = function (state, message) {
    root.setAttribute('data-viewer-state', state);
    root.querySelector('.viewer-message').textContent = message;
  };
  try {
    if (!window.THREE || !THREE.OrbitControls) throw new Error('three.js did not load');
    const layers = LAYERS_;
    const sequence = SEQUENCE_;
    if (sequence) layers.forEach(function (layer, i) { layer.visible = i === 0; });
    const decode = function (text, Type) {
      const bytes = atob(text);
      const buffer = new Uint8Array(bytes.length);
      for (let i = 0; i < bytes.length; ++i) buffer[i] = bytes.charCodeAt(i);
      return new Type(buffer.buffer);
    };
    const holder = root.querySelector('.viewer-canvas');
    const width = holder.clientWidth || 800, height = holder.clientHeight || 500;
    const renderer = new THREE.WebGLRenderer({antialias: true});
    if (!renderer.getContext()) throw new Error('no WebGL');
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(width, height);
    holder.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0x2b2b2b);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 0.55));
    const camera = new THREE.PerspectiveCamera(40, width / height, 1e-3, 1e3);
    const headlight = new THREE.DirectionalLight(0xffffff, 0.75);
    camera.add(headlight);
    scene.add(camera);
    const box = new THREE.Box3();
    const objects = {};
    let triangles = 0;
    for (const layer of layers) {
      const mesh = (window.silnetMeshes || {})[layer.name];
      if (!mesh) throw new Error('the mesh ' + layer.name + ' did not load');
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position',
                            new THREE.BufferAttribute(decode(mesh.positions, Float32Array), 3));
      geometry.setAttribute('normal',
                            new THREE.BufferAttribute(decode(mesh.normals, Float32Array), 3));
      geometry.setIndex(new THREE.BufferAttribute(decode(mesh.indices, Uint32Array), 1));
      const material = layer.wireframe
          ? new THREE.MeshBasicMaterial({color: layer.colour, wireframe: true, transparent: true,
                                         opacity: 0.35})
          : new THREE.MeshStandardMaterial({color: layer.colour, roughness: 0.85, metalness: 0,
                                            side: THREE.DoubleSide});
      const object = new THREE.Mesh(geometry, material);
      object.visible = layer.visible;
      scene.add(object);
      objects[layer.name] = object;
      geometry.computeBoundingBox();
      if (layer.visible || sequence) box.union(geometry.boundingBox);
      if (layer.visible) triangles += mesh.triangles;
    }
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
    camera.near = radius / 100;
    camera.far = radius * 100;
    const start = START_;
    const eye = new THREE.Vector3(start.eye[0], start.eye[1], start.eye[2]);
    if (!start.direction) eye.sub(centre);
    camera.up.set(start.up[0], start.up[1], start.up[2]);
    camera.position.copy(centre).add(eye.normalize().multiplyScalar(2.6 * radius));
    camera.updateProjectionMatrix();
    const controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.copy(centre);
    const render = function () { renderer.render(scene, camera); };
    controls.addEventListener('change', render);
    controls.update();
    const slider = root.querySelector('input.viewer-sequence');
    if (slider) {
      slider.addEventListener('input', function () {
        layers.forEach(function (layer, i) {
          objects[layer.name].visible = i === Number(slider.value);
        });
        root.querySelector('.viewer-frame').textContent = layers[Number(slider.value)].label;
        render();
      });
    }
    for (const toggle of root.querySelectorAll('input[data-layer]')) {
      toggle.addEventListener('change', function () {
        objects[toggle.getAttribute('data-layer')].visible = toggle.checked;
        render();
      });
    }
    render();
    say('drawn ' + triangles + ' triangles',
        'Drag to turn, scroll to zoom, right-drag to move.');
  } catch (error) {
    say('error: ' + error.message, '3D view unavailable: ' + error.message);
  }
})();
)JS";

// `text` with every occurrence of `from` replaced by `to`.
std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// `text` as the inside of a single-quoted JavaScript string that is safe inside <script>.
std::string JsString(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '<') {
      out += "\\x3c";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      if (c == '\\' || c == '\'') out += '\\';
      out += c;
    }
  }
  return out;
}

bool IsPlainName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

}  // namespace

std::string Base64(const void* data, size_t size) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (size_t i = 0; i < size; i += 3) {
    const size_t n = std::min<size_t>(3, size - i);
    uint32_t chunk = static_cast<uint32_t>(bytes[i]) << 16;
    if (n > 1) chunk |= static_cast<uint32_t>(bytes[i + 1]) << 8;
    if (n > 2) chunk |= bytes[i + 2];
    out += kAlphabet[(chunk >> 18) & 63];
    out += kAlphabet[(chunk >> 12) & 63];
    out += n > 1 ? kAlphabet[(chunk >> 6) & 63] : '=';
    out += n > 2 ? kAlphabet[chunk & 63] : '=';
  }
  return out;
}

std::string InstallMeshViewer(const fs::path& report_dir, const fs::path& three_dir) {
  const fs::path viewer = report_dir / "viewer";
  std::error_code error;
  fs::create_directories(viewer, error);
  if (error) return fmt::format("cannot create {}: {}", viewer.string(), error.message());
  for (const fs::path& file :
       {three_dir / "three.min.js", three_dir / "examples/js/controls/OrbitControls.js"}) {
    if (!fs::exists(file))
      return fmt::format("{} is missing (install Debian's libjs-three)", file.string());
    fs::copy_file(file, viewer / file.filename(), fs::copy_options::overwrite_existing, error);
    if (error) return fmt::format("cannot copy {}: {}", file.string(), error.message());
  }
  return "";
}

void WriteViewerMesh(const fs::path& report_dir, const std::string& name, const DisplayMesh& mesh) {
  SILNET_CHECK_MSG(IsPlainName(name), "viewer mesh name '" << name << "'");
  SILNET_CHECK(mesh.normals.size() == mesh.positions.size());
  static_assert(sizeof(Eigen::Vector3f) == 12 && sizeof(std::array<uint32_t, 3>) == 12);
  ReplaceFile(report_dir / "viewer" / (name + ".js"),
              fmt::format("window.silnetMeshes = window.silnetMeshes || {{}};\n"
                          "window.silnetMeshes['{}'] = {{triangles: {},\n positions: '{}',\n "
                          "normals: '{}',\n indices: '{}'}};\n",
                          name, mesh.triangles.size(),
                          Base64(mesh.positions.data(), 12 * mesh.positions.size()),
                          Base64(mesh.normals.data(), 12 * mesh.normals.size()),
                          Base64(mesh.triangles.data(), 12 * mesh.triangles.size())));
}

std::string MeshViewerHtml(const std::string& id, const std::vector<ViewerLayer>& layers,
                           const std::optional<ViewerStart>& start, bool sequence) {
  SILNET_CHECK_MSG(IsPlainName(id), "viewer id '" << id << "'");
  std::string html = fmt::format(
      "<div id=\"{}\" class=\"viewer\" data-viewer-state=\"loading\">\n"
      "<div class=\"viewer-canvas\" style=\"width:100%;max-width:960px;height:540px\"></div>\n"
      "<p class=\"viewer-controls\">",
      id);
  std::string json = "[";
  for (const ViewerLayer& layer : layers) {
    SILNET_CHECK_MSG(IsPlainName(layer.name), "viewer mesh name '" << layer.name << "'");
    if (!sequence) {
      html += fmt::format("<label><input type=\"checkbox\" data-layer=\"{}\"{}> {}</label> ",
                          layer.name, layer.visible ? " checked" : "", EscapeHtml(layer.label));
    }
    if (json.size() > 1) json += ",";
    json += fmt::format("{{name: '{}', label: '{}', colour: {}, wireframe: {}, visible: {}}}",
                        layer.name, JsString(layer.label), layer.colour, layer.wireframe,
                        layer.visible);
  }
  json += "]";
  if (sequence && !layers.empty()) {
    html += fmt::format(
        "<input type=\"range\" class=\"viewer-sequence\" min=\"0\" max=\"{}\" value=\"0\" "
        "style=\"width:50%\"> <span class=\"viewer-frame\">{}</span> ",
        layers.size() - 1, EscapeHtml(layers.front().label));
  }
  html += "<span class=\"viewer-message muted\">loading the 3D view</span></p>\n";
  html += "<script src=\"viewer/three.min.js\"></script>\n";
  html += "<script src=\"viewer/OrbitControls.js\"></script>\n";
  for (const ViewerLayer& layer : layers)
    html += fmt::format("<script src=\"viewer/{}.js\"></script>\n", layer.name);
  html += "<script>";
  // Without a start: from the side (-y) and above, z up; `eye` is then a direction.
  const std::string start_json =
      start
          ? fmt::format("{{eye: [{}, {}, {}], up: [{}, {}, {}], direction: false}}", start->eye.x(),
                        start->eye.y(), start->eye.z(), start->up.x(), start->up.y(), start->up.z())
          : std::string("{eye: [0, -2.4, 0.9], up: [0, 0, 1], direction: true}");
  std::string script = ReplaceAll(kViewerScript, "ID_", fmt::format("'{}'", id));
  script = ReplaceAll(script, "LAYERS_", json);
  script = ReplaceAll(script, "START_", start_json);
  html += ReplaceAll(script, "SEQUENCE_", sequence ? "true" : "false");
  html += "</script>\n</div>\n";
  return html;
}

}  // namespace silnet::aggregator
