// Triangle-mesh walls (coredem/dem/triangle_mesh.h): STL round trips, ASCII/binary detection,
// welding, topology, every reading and checking error with what its message must name, and the
// generators' orientation and volume.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include <coredem/dem/triangle_mesh.h>

namespace fs = std::filesystem;
using coredem::dem::boundingBox;
using coredem::dem::checkMesh;
using coredem::dem::MeshCheckOptions;
using coredem::dem::MeshError;
using coredem::dem::meshRectangle;
using coredem::dem::meshRevolved;
using coredem::dem::meshTopology;
using coredem::dem::readStl;
using coredem::dem::StlOptions;
using coredem::dem::TriangleMesh;
using coredem::dem::writeStl;

namespace {

using Vec3 = std::array<double, 3>;

Vec3 vertex(const TriangleMesh& mesh, std::size_t t, int k) {
  const auto v = static_cast<std::size_t>(mesh.triangles[3 * t + static_cast<std::size_t>(k)]);
  return {mesh.vertices[3 * v], mesh.vertices[3 * v + 1], mesh.vertices[3 * v + 2]};
}

Vec3 normalOf(const TriangleMesh& mesh, std::size_t t) {
  const Vec3 a = vertex(mesh, t, 0), b = vertex(mesh, t, 1), c = vertex(mesh, t, 2);
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

/// Signed volume enclosed by a closed mesh (m³): > 0 when its normals point outwards.
double signedVolume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 a = vertex(mesh, t, 0), n = normalOf(mesh, t);
    volume += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6.0;
  }
  return volume;
}

/// requireClosed on, no domain.
MeshCheckOptions closedRequired() {
  MeshCheckOptions options;
  options.requireClosed = true;
  return options;
}

/// Cylinder of radius 0.05 m and height 0.2 m along z, capped: 2 segments + 2 vertices.
TriangleMesh closedCylinder(int segments) {
  return meshRevolved({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {{0.0, 0.05}, {0.2, 0.05}}, segments, true,
                      true);
}

/// A folder of its own for each test, removed afterwards.
class MeshFiles : public ::testing::Test {
protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    _dir = fs::temp_directory_path() /
           ("coredem_mesh_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(_dir);
    fs::create_directories(_dir);
  }
  void TearDown() override { fs::remove_all(_dir); }

  fs::path path(const std::string& name) const { return _dir / name; }

  fs::path writeText(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
    return path(name);
  }

  /// Every word in `parts` must be in the MeshError that `action` throws.
  static void expectMeshError(const std::function<void()>& action,
                              const std::vector<std::string>& parts) {
    try {
      action();
      ADD_FAILURE() << "no MeshError; expected one with: " << parts.front();
    } catch (const MeshError& error) {
      const std::string message = error.what();
      for (const auto& part : parts) {
        EXPECT_NE(message.find(part), std::string::npos)
            << "'" << part << "' missing in: " << message;
      }
    }
  }

  fs::path _dir;
};

std::string facet(const std::string& a, const std::string& b, const std::string& c) {
  return "facet normal 0 0 0\n outer loop\n  vertex " + a + "\n  vertex " + b + "\n  vertex " + c +
         "\n endloop\nendfacet\n";
}

std::string solid(const std::vector<std::string>& facets) {
  std::string text = "solid test\n";
  for (const auto& f : facets) {
    text += f;
  }
  return text + "endsolid test\n";
}

/// Triangles of both meshes at the same coordinates, in the same order and winding.
void expectSameTriangles(const TriangleMesh& a, const TriangleMesh& b, double tolerance) {
  ASSERT_EQ(a.triangleCount(), b.triangleCount());
  for (std::size_t t = 0; t < a.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      for (int d = 0; d < 3; ++d) {
        ASSERT_NEAR(vertex(a, t, k)[d], vertex(b, t, k)[d], tolerance)
            << "triangle " << t << " vertex " << k;
      }
    }
  }
}

} // namespace

// ---- generators ---------------------------------------------------------------------------

// nu x nv quads, (nu+1)(nv+1) vertices, every normal along u x v, bounding box origin + u + v.
TEST(MeshGenerators, RectangleHasItsGridAndNormalAlongUCrossV) {
  const TriangleMesh mesh = meshRectangle({1.0, 2.0, 3.0}, {0.0, 0.5, 0.0}, {0.0, 0.0, 0.2}, 4, 3);
  EXPECT_EQ(mesh.vertexCount(), 5u * 4u);
  EXPECT_EQ(mesh.triangleCount(), 2u * 4u * 3u);
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 n = normalOf(mesh, t);
    EXPECT_GT(n[0], 0.0) << t; // u x v = +x
    EXPECT_NEAR(n[1], 0.0, 1e-15);
    EXPECT_NEAR(n[2], 0.0, 1e-15);
  }
  const auto box = boundingBox(mesh);
  const std::array<double, 6> expected{1.0, 2.0, 3.0, 1.0, 2.5, 3.2};
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(box[i], expected[i], 1e-15);
  }
  EXPECT_NO_THROW(checkMesh(mesh, {}));
  EXPECT_THROW(meshRectangle({}, {1.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, 1, 1), MeshError);
  EXPECT_THROW(meshRectangle({}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0, 1), MeshError);
}

// A capped cylinder: 2 rings + 2 cap centres, closed, outward (signed volume > 0) and its volume
// that of the inscribed prism (n/2 R² sin(2π/n) H), within the faceting error of π R² H.
TEST(MeshGenerators, ClosedCylinderIsOutwardWithTheVolumeOfItsPrism) {
  for (const int n : {3, 8, 48}) {
    const TriangleMesh mesh = closedCylinder(n);
    EXPECT_EQ(mesh.vertexCount(), 2u * static_cast<unsigned>(n) + 2u);
    EXPECT_EQ(mesh.triangleCount(), 4u * static_cast<unsigned>(n));
    const double R = 0.05, H = 0.2;
    const double prism = 0.5 * n * R * R * std::sin(2.0 * std::numbers::pi / n) * H;
    const double exact = std::numbers::pi * R * R * H;
    const double volume = signedVolume(mesh);
    EXPECT_GT(volume, 0.0);
    EXPECT_NEAR(volume, prism, 1e-12 * exact) << n;
    EXPECT_LE(exact - volume,
              exact * (1.0 - std::sin(2.0 * std::numbers::pi / n) / (2.0 * std::numbers::pi / n)) +
                  1e-12)
        << n;
    EXPECT_NO_THROW(checkMesh(mesh, closedRequired()));
  }
  // Fine faceting: within the relative faceting error (2π/n)²/6 of π R² H.
  const double exact = std::numbers::pi * 0.05 * 0.05 * 0.2, x = 2.0 * std::numbers::pi / 256;
  EXPECT_NEAR(signedVolume(closedCylinder(256)), exact, exact * x * x / 6.0);
}

// Lateral normals point away from the axis and the volume stays positive whichever way the
// profile runs, along any axis; a frustum (hopper) has the volume of its faceted cone.
TEST(MeshGenerators, RevolvedNormalsPointOutwardWhicheverWayTheProfileRuns) {
  const Vec3 origin{0.1, -0.2, 0.3};
  const double len = std::sqrt(3.0);
  const Vec3 axis{1.0 / len, 1.0 / len, 1.0 / len};
  const double r0 = 0.02, R = 0.06, H = 0.1;
  const int n = 64;
  for (const bool reversed : {false, true}) {
    std::vector<std::array<double, 2>> profile{{0.0, r0}, {H, R}};
    if (reversed) {
      std::swap(profile[0], profile[1]);
    }
    const TriangleMesh open = meshRevolved(origin, {2.0, 2.0, 2.0}, profile, n, false, false);
    EXPECT_EQ(open.triangleCount(), 2u * n);
    for (std::size_t t = 0; t < open.triangleCount(); ++t) {
      const Vec3 a = vertex(open, t, 0), b = vertex(open, t, 1), c = vertex(open, t, 2);
      Vec3 radial{};
      const Vec3 centroid{(a[0] + b[0] + c[0]) / 3 - origin[0],
                          (a[1] + b[1] + c[1]) / 3 - origin[1],
                          (a[2] + b[2] + c[2]) / 3 - origin[2]};
      const double along = centroid[0] * axis[0] + centroid[1] * axis[1] + centroid[2] * axis[2];
      for (int d = 0; d < 3; ++d) {
        radial[d] = centroid[d] - along * axis[d];
      }
      const Vec3 nrm = normalOf(open, t);
      EXPECT_GT(nrm[0] * radial[0] + nrm[1] * radial[1] + nrm[2] * radial[2], 0.0)
          << "triangle " << t << (reversed ? " (reversed profile)" : "");
    }
    const TriangleMesh closed = meshRevolved(origin, axis, profile, n, true, true);
    EXPECT_NO_THROW(checkMesh(closed, closedRequired()));
    const double frustum = std::numbers::pi * H / 3.0 * (r0 * r0 + r0 * R + R * R);
    const double facets = std::sin(2.0 * std::numbers::pi / n) / (2.0 * std::numbers::pi / n);
    EXPECT_NEAR(signedVolume(closed), frustum * facets, 1e-12);
  }
  // A cone ending on the axis is closed by its apex: one cap, n + 2 vertices.
  const TriangleMesh cone = meshRevolved({}, {0.0, 0.0, 1.0}, {{0.0, R}, {H, 0.0}}, n, true, true);
  EXPECT_EQ(cone.vertexCount(), static_cast<std::size_t>(n) + 2u);
  EXPECT_NO_THROW(checkMesh(cone, closedRequired()));
  EXPECT_GT(signedVolume(cone), 0.0);
  EXPECT_THROW(meshRevolved({}, {0.0, 0.0, 0.0}, {{0.0, R}, {H, R}}, n, false, false), MeshError);
  EXPECT_THROW(meshRevolved({}, {0.0, 0.0, 1.0}, {{0.0, R}}, n, false, false), MeshError);
  EXPECT_THROW(meshRevolved({}, {0.0, 0.0, 1.0}, {{0.0, -R}, {H, R}}, n, false, false), MeshError);
  EXPECT_THROW(meshRevolved({}, {0.0, 0.0, 1.0}, {{0.0, R}, {H, R}}, 2, false, false), MeshError);
}

// ---- topology -----------------------------------------------------------------------------

// A square of two triangles: 5 edges, the diagonal one id in both triangles, used twice.
TEST(MeshTopology, SharedEdgesHaveOneId) {
  const TriangleMesh square = meshRectangle({}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1, 1);
  const auto topology = meshTopology(square);
  EXPECT_EQ(topology.edgeCount, 5);
  ASSERT_EQ(topology.triangleEdges.size(), 6u);
  ASSERT_EQ(topology.edgeUse.size(), 5u);
  ASSERT_EQ(topology.edgeVertices.size(), 10u);
  // Triangle (a, b, c) then (a, c, d): edge 2 of the first (c→a) is edge 0 of the second (a→c).
  EXPECT_EQ(topology.triangleEdges[2], topology.triangleEdges[3]);
  EXPECT_EQ(topology.edgeUse[static_cast<std::size_t>(topology.triangleEdges[2])], 2);
  int open = 0;
  for (const auto use : topology.edgeUse) {
    open += use == 1 ? 1 : 0;
  }
  EXPECT_EQ(open, 4);
  // Every edge joins the vertices its triangles name.
  for (std::size_t t = 0; t < 2; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
      const auto a = square.triangles[3 * t + k], b = square.triangles[3 * t + (k + 1) % 3];
      const auto p = topology.edgeVertices[2 * e], q = topology.edgeVertices[2 * e + 1];
      EXPECT_TRUE((p == a && q == b) || (p == b && q == a)) << t << " " << k;
    }
  }
}

// A closed cylinder: every edge of two triangles, E = 3F/2 and V - E + F = 2.
TEST(MeshTopology, ClosedCylinderIsASphereTopologically) {
  const TriangleMesh mesh = closedCylinder(16);
  const auto topology = meshTopology(mesh);
  for (const auto use : topology.edgeUse) {
    EXPECT_EQ(use, 2);
  }
  const auto F = static_cast<std::int64_t>(mesh.triangleCount());
  EXPECT_EQ(2 * topology.edgeCount, 3 * F);
  EXPECT_EQ(static_cast<std::int64_t>(mesh.vertexCount()) - topology.edgeCount + F, 2);
}

// ---- reading and writing ------------------------------------------------------------------

// ASCII (shortest round-trip digits) gives back the very same triangles and welded vertices.
TEST_F(MeshFiles, AsciiRoundTripKeepsTrianglesAndWelding) {
  const TriangleMesh mesh = closedCylinder(24);
  writeStl(mesh, path("cylinder.stl"), false);
  const TriangleMesh back = readStl(path("cylinder.stl"));
  EXPECT_EQ(back.name, path("cylinder.stl").string());
  EXPECT_EQ(back.vertexCount(), 2u * 24u + 2u);
  expectSameTriangles(mesh, back, 0.0);
  EXPECT_NO_THROW(checkMesh(back, closedRequired()));
  EXPECT_GT(signedVolume(back), 0.0);
}

// Binary (single precision) gives back the triangles within float rounding, welded the same.
TEST_F(MeshFiles, BinaryRoundTripKeepsTrianglesAndWelding) {
  const TriangleMesh mesh = closedCylinder(24);
  writeStl(mesh, path("cylinder.stl"), true);
  EXPECT_EQ(fs::file_size(path("cylinder.stl")), 84u + 50u * mesh.triangleCount());
  const TriangleMesh back = readStl(path("cylinder.stl"));
  EXPECT_EQ(back.vertexCount(), 2u * 24u + 2u);
  expectSameTriangles(mesh, back, 1e-8);
  EXPECT_NO_THROW(checkMesh(back, closedRequired()));
}

// Many exporters begin binary files with "solid": the size decides.
TEST_F(MeshFiles, BinaryFileStartingWithSolidIsReadAsBinary) {
  const TriangleMesh mesh = closedCylinder(8);
  writeStl(mesh, path("part.stl"), true);
  std::fstream file(path("part.stl"), std::ios::in | std::ios::out | std::ios::binary);
  const std::string header = "solid part exported by a CAD tool facet normal";
  file.write(header.data(), static_cast<std::streamsize>(header.size()));
  file.close();
  const TriangleMesh back = readStl(path("part.stl"));
  EXPECT_EQ(back.triangleCount(), mesh.triangleCount());
  EXPECT_EQ(back.vertexCount(), mesh.vertexCount());
}

// scale multiplies every coordinate (a file in millimetres read with 0.001).
TEST_F(MeshFiles, ScaleMultipliesTheCoordinates) {
  writeStl(meshRectangle({0.0, 0.0, 10.0}, {1000.0, 0.0, 0.0}, {0.0, 500.0, 0.0}, 2, 2),
           path("plate.stl"), false);
  const auto box = boundingBox(readStl(path("plate.stl"), {.scale = 0.001}));
  const std::array<double, 6> expected{0.0, 0.0, 0.01, 1.0, 0.5, 0.01};
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(box[i], expected[i], 1e-15) << i;
  }
  EXPECT_THROW(readStl(path("plate.stl"), {.scale = 0.0}), MeshError);
  EXPECT_THROW(readStl(path("plate.stl"), {.scale = std::nan("")}), MeshError);
}

// Several solids, keywords in any case, tabs and CRLF, signs and exponents; the stored normals
// (here wrong) are ignored.
TEST_F(MeshFiles, AsciiReadsSeveralSolidsAnyCaseAnyWhitespace) {
  const std::string text = "  SOLID first part\r\n"
                           "\tFacet Normal 0 0 -1\r\n  OUTER LOOP\r\n"
                           "vertex 0 0 0\r\n VERTEX +1.0 0 0\r\n vertex 1E0 1e+0 0.0\r\n"
                           "EndLoop\r\n endfacet\r\nENDSOLID first part\r\n"
                           "solid\nfacet normal 1 0 0 outer loop vertex 0 0 0 vertex 1 1 0 vertex "
                           "0 1 0 endloop endfacet\nendsolid";
  const TriangleMesh mesh = readStl(writeText("two.stl", text));
  EXPECT_EQ(mesh.triangleCount(), 2u);
  EXPECT_EQ(mesh.vertexCount(), 4u);
  EXPECT_GT(normalOf(mesh, 0)[2], 0.0);
  EXPECT_GT(normalOf(mesh, 1)[2], 0.0);
  EXPECT_NO_THROW(checkMesh(mesh, {}));
}

// Points within 1e-9 of the bounding-box diagonal weld into one; 1e-6 apart stay apart.
TEST_F(MeshFiles, VerticesWithinTheToleranceAreWelded) {
  const auto square = [&](const std::string& eps) {
    return solid({facet("0 0 0", "1 0 0", "1 1 0"), facet(eps + " 0 0", "1 1 " + eps, "0 1 0")});
  };
  EXPECT_EQ(readStl(writeText("near.stl", square("1e-12"))).vertexCount(), 4u);
  EXPECT_EQ(readStl(writeText("far.stl", square("1e-6"))).vertexCount(), 6u);
}

// ---- reading errors: each names the file and says what is wrong ---------------------------

TEST_F(MeshFiles, MissingFileIsReported) {
  const fs::path file = path("nowhere.stl");
  expectMeshError([&] { readStl(file); }, {file.string(), "not found"});
}

TEST_F(MeshFiles, EmptyMeshesAreReported) {
  const fs::path empty = writeText("empty.stl", "");
  expectMeshError([&] { readStl(empty); }, {empty.string(), "empty"});
  const fs::path ascii = writeText("nothing.stl", "solid nothing\nendsolid nothing\n");
  expectMeshError([&] { readStl(ascii); }, {ascii.string(), "no triangles"});
  const fs::path binary = writeText("zero.stl", std::string(84, '\0'));
  expectMeshError([&] { readStl(binary); }, {binary.string(), "no triangles"});
}

TEST_F(MeshFiles, TruncatedBinaryIsReported) {
  writeStl(meshRectangle({}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1, 1), path("cut.stl"), true);
  fs::resize_file(path("cut.stl"), 174);
  expectMeshError([&] { readStl(path("cut.stl")); },
                  {path("cut.stl").string(), "truncated", "expected 184 bytes", "triangle count 2",
                   "found 174"});
}

TEST_F(MeshFiles, AsciiSyntaxErrorsNameTheLineAndToken) {
  const fs::path typo = writeText("typo.stl", "solid a\nfacet normal 0 0 1\nouter loop\n"
                                              "vertex 0 0 0\nvertx 1 0 0\nvertex 1 1 0\n"
                                              "endloop\nendfacet\nendsolid a\n");
  expectMeshError([&] { readStl(typo); }, {typo.string(), "line 5", "`vertx`", "`vertex`"});
  const fs::path number = writeText("number.stl", solid({facet("0 0 0", "1 0 0", "1 1,5 0")}));
  expectMeshError([&] { readStl(number); }, {number.string(), "line 6", "`1,5`", "number"});
  const fs::path quad =
      writeText("quad.stl", "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\n"
                            "endsolid q\n");
  expectMeshError([&] { readStl(quad); }, {quad.string(), "line 7", "exactly 3 vertices"});
  const fs::path cut = writeText("cut.stl", "solid c\n" + facet("0 0 0", "1 0 0", "1 1 0"));
  expectMeshError([&] { readStl(cut); }, {cut.string(), "end of the file", "`endsolid`"});
  const fs::path junk = writeText("junk.stl", "hello world\n");
  expectMeshError([&] { readStl(junk); }, {junk.string(), "not an STL file"});
}

TEST_F(MeshFiles, NonFiniteCoordinatesNameTheTriangle) {
  const fs::path ascii = writeText(
      "nan.stl", solid({facet("0 0 0", "1 0 0", "1 1 0"), facet("0 0 0", "1 1 nan", "0 1 0")}));
  expectMeshError([&] { readStl(ascii); },
                  {ascii.string(), "triangle 2", "non-finite", "vertex 2", "line 9"});
  // Binary: the third coordinate of the first vertex of triangle 1 set to +inf.
  writeStl(meshRectangle({}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1, 1), path("inf.stl"), true);
  std::fstream file(path("inf.stl"), std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(84 + 12 + 8);
  const unsigned char inf[4] = {0x00, 0x00, 0x80, 0x7f};
  file.write(reinterpret_cast<const char*>(inf), 4);
  file.close();
  expectMeshError([&] { readStl(path("inf.stl")); },
                  {path("inf.stl").string(), "triangle 1", "non-finite"});
}

TEST_F(MeshFiles, UnwritableFileIsReported) {
  const fs::path file = path("no/such/folder/out.stl");
  expectMeshError([&] { writeStl(closedCylinder(4), file, true); }, {file.string(), "write"});
}

// ---- check errors: the file, the triangle (1-based, file order), its vertices, the fix -----

TEST_F(MeshFiles, DegenerateTrianglesAreReported) {
  const fs::path welded = writeText(
      "welded.stl", solid({facet("0 0 0", "1 0 0", "1 1 0"), facet("0 0 0", "1 1 0", "1 1 0")}));
  expectMeshError([&] { checkMesh(readStl(welded), {}); },
                  {welded.string(), "degenerate", "triangle 2", "(1, 1, 0)", "same point"});
  const fs::path line = writeText(
      "line.stl", solid({facet("0 0 0", "1 0 0", "1 1 0"), facet("0 0 0", "2 2 0", "1 1 0")}));
  expectMeshError([&] { checkMesh(readStl(line), {}); },
                  {line.string(), "degenerate", "triangle 2", "(2, 2, 0)", "area"});
}

TEST_F(MeshFiles, NonManifoldEdgeIsReported) {
  const fs::path file = writeText(
      "fin.stl", solid({facet("0 0 0", "1 0 0", "0 1 0"), facet("1 0 0", "0 0 0", "0 -1 0"),
                        facet("0 0 0", "1 0 0", "0 0 1")}));
  expectMeshError([&] { checkMesh(readStl(file), {}); },
                  {file.string(), "non-manifold", "triangle 3", "(0, 0, 1)", "triangles 1 and 2"});
}

// The triangle against the majority of its surface is named, wherever it is in the file.
TEST_F(MeshFiles, InvertedTriangleIsReported) {
  const std::string a = facet("0 0 0", "1 0 0", "1 1 0"), b = facet("0 0 0", "1 1 0", "0 1 0");
  const std::string good = facet("1 0 0", "2 0 0", "1 1 0"), bad = facet("1 0 0", "1 1 0", "2 0 0");
  const fs::path last = writeText("last.stl", solid({a, b, bad}));
  expectMeshError(
      [&] { checkMesh(readStl(last), {}); },
      {last.string(), "inverted triangle 3 (", "(2, 0, 0)", "neighbour triangle 1", "1 of the 3"});
  const fs::path first = writeText("first.stl", solid({facet("0 0 0", "1 1 0", "1 0 0"), b, good}));
  expectMeshError([&] { checkMesh(readStl(first), {}); },
                  {first.string(), "inverted triangle 1 (", "(1, 1, 0)", "neighbour triangle 2",
                   "1 of the 3", "flip"});
  EXPECT_NO_THROW(checkMesh(readStl(writeText("fine.stl", solid({a, b, good}))), {}));
}

// A rectangle is open: with requireClosed its first open edge, triangle and count are named.
TEST_F(MeshFiles, OpenEdgeFailsRequireClosed) {
  writeStl(meshRectangle({}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1, 1), path("plate.stl"), false);
  const TriangleMesh plate = readStl(path("plate.stl"));
  EXPECT_NO_THROW(checkMesh(plate, {}));
  expectMeshError([&] { checkMesh(plate, closedRequired()); },
                  {path("plate.stl").string(), "not closed", "4 open edge", "triangle 1",
                   "(0, 0, 0)–(1, 0, 0)"});
  // A cylinder without its top cap: the open rim.
  writeStl(meshRevolved({}, {0.0, 0.0, 1.0}, {{0.0, 1.0}, {1.0, 1.0}}, 6, true, false),
           path("cup.stl"), true);
  expectMeshError([&] { checkMesh(readStl(path("cup.stl")), closedRequired()); },
                  {path("cup.stl").string(), "6 open edge"});
}

// A 100 x 50 mm plate written in millimetres, in a 0.1 m domain: probably millimetres, with both
// boxes and the fix.
TEST_F(MeshFiles, MillimetreMeshIsReported) {
  const std::array<double, 6> domain{0.0, 0.0, 0.0, 0.1, 0.05, 0.02};
  writeStl(meshRectangle({}, {100.0, 0.0, 0.0}, {0.0, 50.0, 0.0}, 1, 1), path("mm.stl"), false);
  expectMeshError([&] { checkMesh(readStl(path("mm.stl")), {.domain = domain}); },
                  {path("mm.stl").string(), "millimetres", "scale: 0.001", "(100, 50, 0)",
                   "(0.1, 0.05, 0.02)"});
  EXPECT_NO_THROW(checkMesh(readStl(path("mm.stl"), {.scale = 0.001}), {.domain = domain}));
}
