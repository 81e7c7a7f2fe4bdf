#include "aggregator/hulls/ply_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

TriangleMesh RandomMesh(size_t vertices, size_t triangles, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> coordinate(-5.0f, 5.0f);
  std::uniform_int_distribution<int32_t> index(0, static_cast<int32_t>(vertices) - 1);
  TriangleMesh mesh;
  for (size_t v = 0; v < vertices; ++v)
    mesh.vertices.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  for (size_t t = 0; t < triangles; ++t)
    mesh.triangles.push_back({index(rng), index(rng), index(rng)});
  return mesh;
}

std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

TEST(PlyIoTest, RoundTripIsBitExact) {
  silnet::testing::TempDir dir;
  const TriangleMesh mesh = RandomMesh(1000, 2000, 7);
  const std::string path = (dir / "mesh.ply").string();
  WritePlyMesh(path, mesh);
  const TriangleMesh back = ReadPlyMesh(path);
  ASSERT_EQ(back.vertices.size(), mesh.vertices.size());
  ASSERT_EQ(back.triangles.size(), mesh.triangles.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    EXPECT_EQ(back.vertices[v], mesh.vertices[v]);  // exact float equality
  EXPECT_EQ(back.triangles, mesh.triangles);
  // Header then 12 bytes per vertex and 13 per face, nothing else.
  const std::string bytes = ReadBytes(path);
  EXPECT_EQ(bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  const size_t body = bytes.size() - (bytes.find("end_header\n") + 11);
  EXPECT_EQ(body, 1000u * 12 + 2000u * 13);
}

TEST(PlyIoTest, LittleEndianLayoutOfOneTriangle) {
  silnet::testing::TempDir dir;
  TriangleMesh mesh;
  mesh.vertices = {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0), Eigen::Vector3f(0, 0, 1)};
  mesh.triangles = {{0, 1, 2}};
  WritePlyMesh((dir / "t.ply").string(), mesh);
  const std::string bytes = ReadBytes(dir / "t.ply");
  const std::string body = bytes.substr(bytes.find("end_header\n") + 11);
  ASSERT_EQ(body.size(), 3u * 12 + 13);
  // 1.0f is 0x3f800000, stored low byte first.
  EXPECT_EQ(body.substr(0, 4), std::string("\x00\x00\x80\x3f", 4));
  EXPECT_EQ(body.substr(36),
            std::string("\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00", 13));
}

TEST(PlyIoTest, RejectsTruncatedAndForeignFiles) {
  silnet::testing::TempDir dir;
  const std::string path = (dir / "mesh.ply").string();
  WritePlyMesh(path, RandomMesh(10, 10, 3));
  const std::string bytes = ReadBytes(path);
  {
    std::ofstream cut(dir / "cut.ply", std::ios::binary);
    cut.write(bytes.data(), static_cast<std::streamsize>(bytes.size() - 5));
  }
  EXPECT_THROW(ReadPlyMesh((dir / "cut.ply").string()), InputError);
  {
    std::ofstream ascii(dir / "ascii.ply");
    ascii << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
             "property float z\nelement face 0\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n";
  }
  EXPECT_THROW(ReadPlyMesh((dir / "ascii.ply").string()), InputError);
  EXPECT_THROW(ReadPlyMesh((dir / "missing.ply").string()), InputError);
}

// Counts whose byte sizes overflow (12 x 2^62 is 0 modulo 2^64; "-1" reads as 2^64 - 1) are
// a truncated file, not an allocation of exabytes.
TEST(PlyIoTest, RejectsCountsWhoseSizesOverflow) {
  silnet::testing::TempDir dir;
  for (const std::string& counts :
       {std::string("element vertex 4611686018427387904\n"), std::string("element vertex -1\n")}) {
    {
      std::ofstream file(dir / "huge.ply", std::ios::binary);
      file << "ply\nformat binary_little_endian 1.0\n"
           << counts
           << "property float x\nproperty float y\nproperty float z\nelement face 0\n"
              "property list uchar int vertex_indices\nend_header\n";
      file << std::string(24, '\0');
    }
    EXPECT_THAT([&] { ReadPlyMesh((dir / "huge.ply").string()); },
                ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("truncated")))
        << counts;
  }
}

}  // namespace
}  // namespace silnet::aggregator
