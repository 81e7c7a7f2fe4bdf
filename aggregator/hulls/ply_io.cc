#include "aggregator/hulls/ply_io.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the PLY writer stores native floats and ints as little-endian");

template <typename T>
void Append(std::vector<char>* out, T value) {
  const char* bytes = reinterpret_cast<const char*>(&value);
  out->insert(out->end(), bytes, bytes + sizeof(T));
}

template <typename T>
T Take(const std::string& data, size_t* at, const std::string& path) {
  if (*at + sizeof(T) > data.size()) throw InputError(path + ": PLY file is truncated");
  T value;
  std::memcpy(&value, data.data() + *at, sizeof(T));
  *at += sizeof(T);
  return value;
}

}  // namespace

void WritePlyMesh(const std::string& path, const TriangleMesh& mesh) {
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment silnet visual hull\n"
         << "element vertex " << mesh.vertices.size() << "\nproperty float x\n"
         << "property float y\nproperty float z\nelement face " << mesh.triangles.size()
         << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<char> body;
  body.reserve(mesh.vertices.size() * 12 + mesh.triangles.size() * 13);
  for (const Eigen::Vector3f& v : mesh.vertices) {
    for (int a = 0; a < 3; ++a)
      Append<float>(&body, v[a]);
  }
  for (const auto& t : mesh.triangles) {
    Append<uint8_t>(&body, 3);
    for (int32_t index : t)
      Append<int32_t>(&body, index);
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw InputError("cannot open " + path + " for writing");
  const std::string text = header.str();
  file.write(text.data(), static_cast<std::streamsize>(text.size()));
  file.write(body.data(), static_cast<std::streamsize>(body.size()));
  if (!file.flush()) throw InputError("cannot write " + path);
}

TriangleMesh ReadPlyMesh(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open " + path);
  std::ostringstream buffer;
  buffer << file.rdbuf();
  const std::string data = buffer.str();
  const size_t header_end = data.find("end_header\n");
  if (data.rfind("ply\n", 0) != 0 || header_end == std::string::npos) {
    throw InputError(path + ": not a PLY file");
  }
  // The header must be exactly the writer's, apart from counts and comments.
  std::istringstream header(data.substr(0, header_end));
  std::vector<std::string> lines;
  size_t vertex_count = 0, face_count = 0;
  for (std::string line; std::getline(header, line);) {
    if (line.rfind("comment", 0) == 0 || line == "ply") continue;
    std::istringstream words(line);
    std::string word, element;
    words >> word;
    if (word == "element") {
      size_t count = 0;
      words >> element >> count;
      if (!words) throw InputError(path + ": malformed line '" + line + "'");
      if (element == "vertex") vertex_count = count;
      if (element == "face") face_count = count;
      line = "element " + element;
    }
    lines.push_back(line);
  }
  const std::vector<std::string> expected = {"format binary_little_endian 1.0",
                                             "element vertex",
                                             "property float x",
                                             "property float y",
                                             "property float z",
                                             "element face",
                                             "property list uchar int vertex_indices"};
  if (lines != expected) {
    throw InputError(path +
                     ": unsupported PLY layout (need binary little-endian float x y z "
                     "vertices and uchar/int triangle faces)");
  }
  TriangleMesh mesh;
  size_t at = header_end + std::string("end_header\n").size();
  // Compared by division: counts from the header can be anything, their products overflow.
  const size_t body = data.size() - at;
  if (vertex_count > body / 12 || face_count > (body - vertex_count * 12) / 13) {
    throw InputError(path + ": PLY file is truncated");
  }
  mesh.vertices.resize(vertex_count);
  for (Eigen::Vector3f& v : mesh.vertices) {
    for (int a = 0; a < 3; ++a)
      v[a] = Take<float>(data, &at, path);
  }
  mesh.triangles.resize(face_count);
  for (auto& t : mesh.triangles) {
    if (Take<uint8_t>(data, &at, path) != 3) throw InputError(path + ": a face is not a triangle");
    for (int32_t& index : t) {
      index = Take<int32_t>(data, &at, path);
      if (index < 0 || static_cast<size_t>(index) >= vertex_count) {
        throw InputError(path + ": face index out of range");
      }
    }
  }
  if (at != data.size()) throw InputError(path + ": trailing bytes after the faces");
  return mesh;
}

}  // namespace silnet::aggregator
