#include "shared/io/point_cloud_ply.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>

#include "shared/util/check.h"

namespace silnet {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the PLY writer stores native floats as little-endian");

constexpr const char* kProperties[] = {"x", "y", "z", "nx", "ny", "nz"};
constexpr size_t kRecordBytes = 6 * sizeof(float);

}  // namespace

std::size_t WritePointCloudPly(const std::filesystem::path& path, const OrientedPointCloud& cloud) {
  SILNET_CHECK(cloud.points.size() == cloud.normals.size());
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\n";
  for (const std::string& comment : cloud.comments) {
    SILNET_CHECK(comment.find('\n') == std::string::npos);
    header << "comment " << comment << "\n";
  }
  header << "element vertex " << cloud.points.size() << "\n";
  for (const char* name : kProperties)
    header << "property float " << name << "\n";
  header << "end_header\n";
  std::vector<float> body;
  body.reserve(cloud.points.size() * 6);
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    for (int a = 0; a < 3; ++a)
      body.push_back(cloud.points[i][a]);
    for (int a = 0; a < 3; ++a)
      body.push_back(cloud.normals[i][a]);
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw InputError("cannot open " + path.string() + " for writing");
  const std::string text = header.str();
  file.write(text.data(), static_cast<std::streamsize>(text.size()));
  file.write(reinterpret_cast<const char*>(body.data()),
             static_cast<std::streamsize>(body.size() * sizeof(float)));
  if (!file.flush()) throw InputError("cannot write " + path.string());
  return text.size() + body.size() * sizeof(float);
}

OrientedPointCloud ReadPointCloudPly(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open " + name);
  std::ostringstream buffer;
  buffer << file.rdbuf();
  const std::string data = buffer.str();
  const size_t header_end = data.find("end_header\n");
  if (data.rfind("ply\n", 0) != 0 || header_end == std::string::npos) {
    throw InputError(name + ": not a PLY file");
  }
  OrientedPointCloud cloud;
  std::istringstream header(data.substr(0, header_end));
  size_t count = 0, property = 0;
  bool format = false, element = false;
  for (std::string line; std::getline(header, line);) {
    if (line == "ply") continue;
    if (line.rfind("comment ", 0) == 0) {
      cloud.comments.push_back(line.substr(8));
    } else if (line == "format binary_little_endian 1.0") {
      format = true;
    } else if (line.rfind("element vertex ", 0) == 0 && !element) {
      std::istringstream words(line.substr(15));
      if (!(words >> count)) throw InputError(name + ": bad vertex count");
      element = true;
    } else if (element && property < 6 &&
               line == std::string("property float ") + kProperties[property]) {
      ++property;
    } else {
      throw InputError(name + ": unexpected PLY header line '" + line +
                       "' (want binary little-endian vertices with float x y z nx ny nz)");
    }
  }
  if (!format || !element || property != 6) {
    throw InputError(name + ": PLY header lacks the format, vertex element or x y z nx ny nz");
  }
  const size_t body = header_end + std::strlen("end_header\n");
  if (count > (data.size() - body) / kRecordBytes)
    throw InputError(name + ": PLY file is truncated");
  cloud.points.resize(count);
  cloud.normals.resize(count);
  for (size_t i = 0; i < count; ++i) {
    float record[6];
    std::memcpy(record, data.data() + body + i * kRecordBytes, kRecordBytes);
    cloud.points[i] = {record[0], record[1], record[2]};
    cloud.normals[i] = {record[3], record[4], record[5]};
  }
  return cloud;
}

}  // namespace silnet
