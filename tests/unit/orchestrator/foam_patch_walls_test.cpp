// DEM walls taken from the patches of the CFD mesh (walls.meshes[].from_cfd, docs/case-schema.md
// "walls"): a hand-written ASCII polyMesh of one hexahedral cell, its patches as triangles (the
// mesh's points, OpenFOAM's outward winding), the case-file key with the pre-flight and Configure,
// and every refusal with its advice.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <coredem/dem/triangle_mesh.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/preflight.h>
#include <coredem/participant/foam_patches.h>
#include <coredem/v1/configure.pb.h>

#include "admission.h"
#include "case_text.h"
#include "configure.h"
#include "configure_map.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;
namespace dem = coredem::dem;

namespace {

const char* kBanner =
    R"(/*--------------------------------*- C++ -*----------------------------------*\
| =========                 |                                                 |
| \\      /  F ield         | OpenFOAM: The Open Source CFD Toolbox           |
\*---------------------------------------------------------------------------*/
)";

std::string header(const std::string& cls, const std::string& object,
                   const std::string& format = "ascii") {
  return std::string(kBanner) + "FoamFile\n{\n    version     2.0;\n    format      " + format +
         ";\n    class       " + cls +
         ";\n    location    \"constant/polyMesh\";\n    object      " + object +
         ";\n}\n// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * "
         "//\n\n";
}

/// One hexahedral cell [0, 0.1]³ m (OpenFOAM's hex numbering), all six faces on the boundary,
/// each wound so that its normal points out of the cell (OpenFOAM's boundary convention).
const char* kPoints = R"(8
(
(0 0 0)
(0.1 0 0)
(0.1 0.1 0)
(0 0.1 0)
(0 0 0.1)
(0.1 0 0.1)
(0.1 0.1 0.1)
(0 0.1 0.1)
)
)";

const char* kFaces = R"(6
(
4(0 4 7 3)
4(1 2 6 5)
4(0 1 5 4)
4(3 7 6 2)
4(0 3 2 1)
4(4 5 6 7)
)
)";

const char* kBoundary = R"(4
(
    walls
    {
        type            wall;
        inGroups        1(wall);
        nFaces          4;
        startFace       0;
    }
    inlet
    {
        type            patch;
        nFaces          1;
        startFace       4;
    }
    outlet
    {
        type            patch;
        nFaces          1;
        startFace       5;
    }
    spare
    {
        type            wall;
        nFaces          0;
        startFace       6;
    }
)
)";

/// A case around the cell: the grid is the cell, 8 particles in its middle, the DEM walls the
/// cell's four side walls plus inlet and outlet (closed).
const char* kCase = R"(name: foam-walls
time: {end: 0.01, dt: 0.001}
grid:
  origin: [0, 0, 0]
  spacing: [0.01, 0.01, 0.01]
  cells: [10, 10, 10]
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - name: bed
    material: glass
    count: 8
    diameter: 0.004
    region: {min: [0.03, 0.03, 0.03], max: [0.07, 0.07, 0.07]}
walls:
  meshes:
    - from_cfd: [walls, inlet, outlet]
      closed: true
cfd:
  participant: coredemFoam
  case: openfoam
)";

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

/// An OpenFOAM case folder `dir` with the cell's polyMesh (the files as given).
void writeCase(const fs::path& dir, const std::string& points = kPoints,
               const std::string& faces = kFaces, const std::string& boundary = kBoundary) {
  write(dir / "system" / "controlDict", header("dictionary", "controlDict") + "application x;\n");
  write(dir / "constant" / "polyMesh" / "points", header("vectorField", "points") + points);
  write(dir / "constant" / "polyMesh" / "faces", header("faceList", "faces") + faces);
  write(dir / "constant" / "polyMesh" / "boundary",
        header("polyBoundaryMesh", "boundary") + boundary);
}

using Vec = std::array<double, 3>;

Vec corner(const FoamPatchSurface& s, std::size_t t, int k) {
  const auto v = std::size_t(s.triangles[3 * t + std::size_t(k)]);
  return {s.vertices[3 * v], s.vertices[3 * v + 1], s.vertices[3 * v + 2]};
}

/// (b - a) x (c - a) of triangle t: its normal by the right-hand rule, twice its area long.
Vec normal(const FoamPatchSurface& s, std::size_t t) {
  const Vec a = corner(s, t, 0), b = corner(s, t, 1), c = corner(s, t, 2);
  const Vec u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

/// Every triangle's normal points away from the cell's centre, and no triangle is degenerate.
void expectOutward(const FoamPatchSurface& s) {
  for (std::size_t t = 0; t < s.triangles.size() / 3; ++t) {
    const Vec n = normal(s, t);
    Vec centroid{};
    for (int k = 0; k < 3; ++k) {
      for (int d = 0; d < 3; ++d) {
        centroid[std::size_t(d)] += corner(s, t, k)[std::size_t(d)] / 3.0;
      }
    }
    double outward = 0.0;
    for (int d = 0; d < 3; ++d) {
      outward += n[std::size_t(d)] * (centroid[std::size_t(d)] - 0.05);
    }
    EXPECT_GT(outward, 0.0) << "triangle " << t << " of face " << s.sourceFace[t];
    EXPECT_GT(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1e-6) << "triangle " << t;
  }
}

class FoamPatchWalls : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir() = fs::temp_directory_path() / ("coredem-foam-walls-" + std::to_string(::getpid()));
    writeCase(dir() / "openfoam");
  }
  static void TearDownTestSuite() { fs::remove_all(dir()); }
  static fs::path& dir() {
    static fs::path d;
    return d;
  }
  static CaseConfig parse(const std::string& text) {
    return parseCase(text, dir() / "case.yaml", dir());
  }
  static std::string errorOf(const std::string& text) {
    try {
      const CaseConfig c = parse(text);
      (void)checkCaseConsistency(c);
    } catch (const CaseError& e) {
      return e.what();
    }
    return "";
  }
  /// The error of kCase with cfd.case naming a copy of the cell's case changed by `edit`.
  template <class Edit>
  static std::string errorWithCase(const std::string& name, Edit edit,
                                   const std::string& text = kCase) {
    const fs::path foam = dir() / name;
    writeCase(foam);
    edit(foam);
    return errorOf(replace(text, "case: openfoam", "case: " + name));
  }
};

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

} // namespace

TEST_F(FoamPatchWalls, TheWallPatchBecomesTrianglesOfTheMeshPoints) {
  const auto boundary = readFoamBoundary(dir() / "openfoam");
  ASSERT_EQ(boundary.size(), 4u);
  EXPECT_EQ(boundary[0].name, "walls");
  EXPECT_EQ(boundary[0].type, "wall");
  EXPECT_EQ(boundary[0].nFaces, 4);
  EXPECT_EQ(boundary[2].startFace, 5);

  const FoamPatchSurface s = readFoamPatches(dir() / "openfoam", {"walls"});
  EXPECT_EQ(s.faces, 4u);
  ASSERT_EQ(s.triangles.size(), 3u * 8); // 4 quads, 2 triangles each
  ASSERT_EQ(s.vertices.size(), 3u * 8);  // the side walls use all 8 points
  ASSERT_EQ(s.pointIndex.size(), 8u);
  // Every vertex is a point of the mesh, bit for bit.
  const double p[8][3] = {{0, 0, 0},   {0.1, 0, 0},   {0.1, 0.1, 0},   {0, 0.1, 0},
                          {0, 0, 0.1}, {0.1, 0, 0.1}, {0.1, 0.1, 0.1}, {0, 0.1, 0.1}};
  for (std::size_t v = 0; v < 8; ++v) {
    for (std::size_t d = 0; d < 3; ++d) {
      EXPECT_EQ(s.vertices[3 * v + d], p[s.pointIndex[v]][d]);
    }
  }
  // Renumbered in order of first use: face 0 is 4(0 4 7 3).
  EXPECT_EQ(s.pointIndex[0], 0);
  EXPECT_EQ(s.pointIndex[1], 4);
  EXPECT_EQ(s.pointIndex[2], 7);
  EXPECT_EQ(s.triangles[0], 0);
  EXPECT_EQ(s.triangles[1], 1);
  EXPECT_EQ(s.triangles[2], 2);
  for (std::size_t t = 0; t < 8; ++t) {
    EXPECT_EQ(s.sourceFace[t], std::int64_t(t / 2));
    EXPECT_EQ(s.sourcePatch[t], 0u);
  }
  expectOutward(s);
  // Open (no top and bottom) but consistently oriented.
  dem::TriangleMesh mesh{"walls", s.vertices, s.triangles};
  EXPECT_NO_THROW(dem::checkMesh(mesh, dem::MeshCheckOptions{false, std::nullopt}));
  EXPECT_THROW(dem::checkMesh(mesh, dem::MeshCheckOptions{true, std::nullopt}), dem::MeshError);

  // All three patches: a closed surface, outward (positive enclosed volume 0.001 m³).
  const FoamPatchSurface all = readFoamPatches(dir() / "openfoam", {"walls", "inlet", "outlet"});
  ASSERT_EQ(all.triangles.size(), 3u * 12);
  EXPECT_EQ(all.sourcePatch[8], 1u);
  EXPECT_EQ(all.sourcePatch[11], 2u);
  expectOutward(all);
  dem::TriangleMesh closed{"cell", all.vertices, all.triangles};
  EXPECT_NO_THROW(dem::checkMesh(closed, dem::MeshCheckOptions{true, std::nullopt}));
  double volume = 0.0;
  for (std::size_t t = 0; t < 12; ++t) {
    const Vec a = corner(all, t, 0), n = normal(all, t);
    volume += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6.0;
  }
  EXPECT_NEAR(volume, 1e-3, 1e-15);
}

TEST_F(FoamPatchWalls, AFaceWithAVertexInAnEdgeIsFannedFromAnotherVertex) {
  // Point 8 in the middle of the edge 1-5, in the two faces that share that edge, each starting
  // at a vertex on that edge: a fan from the first vertex would hold a zero-area triangle.
  const std::string points = replace(kPoints, "8\n(", "9\n(");
  const std::string withMid = replace(points, "(0 0.1 0.1)\n)", "(0 0.1 0.1)\n(0.1 0 0.05)\n)");
  const std::string faces =
      replace(replace(kFaces, "4(1 2 6 5)", "5(5 8 1 2 6)"), "4(0 1 5 4)", "5(1 8 5 4 0)");
  writeCase(dir() / "hanging", withMid, faces);
  const FoamPatchSurface s = readFoamPatches(dir() / "hanging", {"walls", "inlet", "outlet"});
  EXPECT_EQ(s.triangles.size(), 3u * 14); // 4 quads, 2 pentagons, 2 quads
  expectOutward(s);
  dem::TriangleMesh closed{"hanging", s.vertices, s.triangles};
  EXPECT_NO_THROW(dem::checkMesh(closed, dem::MeshCheckOptions{true, std::nullopt}));
}

TEST_F(FoamPatchWalls, TheCaseKeyBuildsTheWallAndPassesPreflight) {
  const CaseConfig c = parse(kCase);
  ASSERT_EQ(c.walls.meshes.size(), 1u);
  const MeshWallConfig& m = c.walls.meshes[0];
  EXPECT_EQ(m.fromCfd, (std::vector<std::string>{"walls", "inlet", "outlet"}));
  EXPECT_EQ(m.file, "");
  EXPECT_EQ(m.name, "openfoam/constant/polyMesh:walls, inlet, outlet");
  EXPECT_EQ(std::string(m.sourceKey()), "from_cfd");
  EXPECT_EQ(m.path, dir() / "openfoam" / "constant" / "polyMesh");
  EXPECT_TRUE(m.closed);
  EXPECT_EQ(m.triangles.size(), 3u * 12);
  EXPECT_EQ(m.vertices.size(), 3u * 8);
  EXPECT_TRUE(checkCaseConsistency(c).empty());
  // One patch name without a list, open.
  const CaseConfig one =
      parse(replace(replace(kCase, "[walls, inlet, outlet]", "walls"), "closed: true", ""));
  EXPECT_EQ(one.walls.meshes[0].triangles.size(), 3u * 8);
  // Particles outside the closed cell (in a taller grid): the same pre-flight as for a closed STL.
  EXPECT_HAS(errorOf(replace(replace(kCase, "max: [0.07, 0.07, 0.07]", "max: [0.07, 0.07, 0.11]"),
                             "cells: [10, 10, 10]", "cells: [10, 10, 12]")),
             "outside the closed mesh wall walls.meshes[0] ('openfoam/constant/polyMesh:walls");

  // Configure carries it under its name; the DEM server's admission and mapping take it.
  coredem::orchestrator::SubcyclePlan plan;
  plan.nSub = 10;
  plan.dtDem = 1e-4;
  const coredem::v1::Configure cfg = buildConfigure(c, dir(), 1e-3, plan);
  ASSERT_EQ(cfg.walls().meshes_size(), 1);
  EXPECT_EQ(cfg.walls().meshes(0).name(), m.name);
  EXPECT_EQ(coredem::server::admitConfigure(cfg, coredem::server::limitsFor(1ull << 30, 1000)), "");
  const dem::DemConfig d = coredem::server::toDemConfig(cfg, nullptr);
  ASSERT_EQ(d.meshes.size(), 1u);
  EXPECT_EQ(d.meshes[0].vertices, m.vertices);
  EXPECT_EQ(d.meshes[0].triangles, m.triangles);
}

TEST_F(FoamPatchWalls, BadInputsAreRefusedSayingWhatToDo) {
  // No cfd section: the default participant has no mesh.
  const std::string noCfd =
      errorOf(std::string(kCase).substr(0, std::string(kCase).find("\ncfd:") + 1));
  EXPECT_HAS(noCfd, "walls.meshes[0].from_cfd: from_cfd takes the walls from the mesh of the "
                    "OpenFOAM case in cfd.case, but the CFD participant is coredem-gas");
  EXPECT_HAS(noCfd, "participant: coredemFoam");
  EXPECT_HAS(noCfd, "walls.meshes[].file");
  EXPECT_HAS(errorOf(replace(kCase, "participant: coredemFoam\n  case: openfoam",
                             "participant: coredem-gas")),
             "the CFD participant is coredem-gas (cfd.participant)");
  // file and from_cfd together; scale with from_cfd; an empty list; a non-name.
  EXPECT_HAS(errorOf(replace(kCase, "      closed: true", "      file: cell.stl")),
             "walls.meshes[0].from_cfd: give either 'file' (an STL file) or 'from_cfd'");
  EXPECT_HAS(errorOf(replace(kCase, "      closed: true", "      scale: 0.001")),
             "walls.meshes[0].scale: not used with from_cfd: the CFD mesh's points are in metres");
  EXPECT_HAS(errorOf(replace(kCase, "[walls, inlet, outlet]", "[]")),
             "walls.meshes[0].from_cfd: expected a list of patch names");
  EXPECT_HAS(errorOf(replace(kCase, "[walls, inlet, outlet]", "[walls, [inlet]]")),
             "walls.meshes[0].from_cfd[1]: expected a patch name");
  // An unknown patch lists those there; a patch twice; a patch without faces.
  const std::string unknown = errorOf(replace(kCase, "[walls, inlet, outlet]", "[wall]"));
  EXPECT_HAS(unknown, "walls.meshes[0].from_cfd: no patch 'wall' in ");
  EXPECT_HAS(unknown, "openfoam/constant/polyMesh/boundary; its patches: walls (wall, 4 faces), "
                      "inlet (patch, 1 faces), outlet (patch, 1 faces), spare (wall, 0 faces)");
  EXPECT_HAS(errorOf(replace(kCase, "[walls, inlet, outlet]", "[walls, walls]")),
             "patch 'walls' is listed twice");
  EXPECT_HAS(errorOf(replace(kCase, "[walls, inlet, outlet]", "[walls, spare]")),
             "patch 'spare' of " + (dir() / "openfoam/constant/polyMesh/boundary").string() +
                 " has no faces (nFaces 0)");
  // A patch of another type.
  const std::string empty = errorWithCase("empty-type", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/boundary",
          header("polyBoundaryMesh", "boundary") +
              replace(kBoundary,
                      "type            patch;\n        nFaces          1;\n        "
                      "startFace       4;",
                      "type            empty;\n        nFaces          1;\n        startFace     "
                      "  4;"));
  });
  EXPECT_HAS(empty, "patch 'inlet' of ");
  EXPECT_HAS(empty, "is of type empty: only patches of type wall or patch");
  // Closed required, open patches given.
  const std::string open = errorOf(replace(kCase, "[walls, inlet, outlet]", "[walls, inlet]"));
  EXPECT_HAS(open, "walls.meshes[0].from_cfd: openfoam/constant/polyMesh:walls, inlet: the "
                   "surface is not closed");
  EXPECT_HAS(open, " of patch 'walls'); a closed wall is required (walls.meshes[0].closed: true): "
                   "name every patch around the fluid in walls.meshes[0].from_cfd, or set "
                   "walls.meshes[0].closed: false for an open wall");
  // No mesh yet: the advice follows the case (blockMeshDict, Allmesh, neither).
  const std::string blockMesh = errorWithCase("unmeshed", [](const fs::path& foam) {
    fs::remove_all(foam / "constant/polyMesh");
    write(foam / "system/blockMeshDict", "FoamFile {}\n");
  });
  EXPECT_HAS(blockMesh, "walls.meshes[0].from_cfd: ");
  EXPECT_HAS(blockMesh, "unmeshed/constant/polyMesh not found: the CFD mesh is not made yet");
  EXPECT_HAS(blockMesh, "blockMesh -case ");
  const std::string allmesh = errorWithCase("allmesh", [](const fs::path& foam) {
    fs::remove(foam / "constant/polyMesh/faces");
    write(foam / "Allmesh", "#!/bin/sh\n");
  });
  EXPECT_HAS(allmesh, "allmesh/constant/polyMesh/faces not found");
  EXPECT_HAS(allmesh, "run the case's mesh script ");
  EXPECT_HAS(allmesh, "allmesh/Allmesh first");
  // Binary and compressed files.
  const std::string binary = errorWithCase("binary", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/points", header("vectorField", "points", "binary") + "8\n(");
  });
  EXPECT_HAS(binary, "binary/constant/polyMesh/points is written in binary format; from_cfd "
                     "reads ASCII mesh files only");
  EXPECT_HAS(binary, "writeFormat ascii;");
  EXPECT_HAS(binary, "foamFormatConvert -constant -case ");
  EXPECT_HAS(binary, "foamToSurface");
  EXPECT_HAS(binary, "walls.meshes[].file");
  const std::string gz = errorWithCase("gz", [](const fs::path& foam) {
    fs::rename(foam / "constant/polyMesh/faces", foam / "constant/polyMesh/faces.gz");
  });
  EXPECT_HAS(gz, "gz/constant/polyMesh/faces.gz is compressed (gzip)");
  EXPECT_HAS(gz, "foamFormatConvert -constant");
  // A syntax error names the file and line; a face beyond the points.
  const std::string syntax = errorWithCase("syntax", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/points",
          header("vectorField", "points") + replace(kPoints, "(0.1 0 0)", "(0.1 0 zero)"));
  });
  EXPECT_HAS(syntax, "syntax/constant/polyMesh/points:");
  EXPECT_HAS(syntax, ": expected a finite number; is it a mesh file OpenFOAM wrote in ASCII?");
  const std::string range = errorWithCase("range", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/faces",
          header("faceList", "faces") + replace(kFaces, "4(0 4 7 3)", "4(0 4 7 9)"));
  });
  EXPECT_HAS(range, "face 0 (patch 'walls') refers to point 9, but points holds 8");
}

TEST_F(FoamPatchWalls, ACompactFaceListIsReadToo) {
  writeCase(dir() / "compact");
  write(dir() / "compact/constant/polyMesh/faces",
        header("faceCompactList", "faces") +
            "7\n(0 4 8 12 16 20 24)\n24\n(0 4 7 3 1 2 6 5 0 1 5 4 3 7 6 2 0 3 2 1 4 5 6 7)\n");
  const FoamPatchSurface a = readFoamPatches(dir() / "compact", {"walls", "inlet", "outlet"});
  const FoamPatchSurface b = readFoamPatches(dir() / "openfoam", {"walls", "inlet", "outlet"});
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.vertices, b.vertices);
}

// Mesh files that cannot be trusted: a FIFO as boundary hung `coredem check`, points linked to
// /dev/zero grew memory without bound, huge counts ended in std::bad_alloc (an internal error)
// and a faces list shorter than the boundary's patches was read as if complete. Each is a user
// error naming the file (and line), before anything is allocated for it.
TEST_F(FoamPatchWalls, UntrustedMeshFilesAreRefusedBeforeReadingOrAllocating) {
  const std::string fifo = errorWithCase("fifo", [](const fs::path& foam) {
    const fs::path b = foam / "constant/polyMesh/boundary";
    fs::remove(b);
    ASSERT_EQ(::mkfifo(b.c_str(), 0600), 0);
  });
  EXPECT_HAS(fifo, "fifo/constant/polyMesh/boundary is not a regular file (a directory, a FIFO, "
                   "a device or a broken link)");
  const std::string zero = errorWithCase("zero", [](const fs::path& foam) {
    const fs::path p = foam / "constant/polyMesh/points";
    fs::remove(p);
    fs::create_symlink("/dev/zero", p);
  });
  EXPECT_HAS(zero, "zero/constant/polyMesh/points is not a regular file");
  const std::string count = errorWithCase("count", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/points",
          header("vectorField", "points") + replace(kPoints, "8\n(", "999999999999\n("));
  });
  EXPECT_HAS(count, "count/constant/polyMesh/points:");
  EXPECT_HAS(count, ": a count of 999999999999 items, but only ");
  const std::string face = errorWithCase("face", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/faces",
          header("faceList", "faces") + replace(kFaces, "4(0 4 7 3)", "4000000000(0 4 7 3)"));
  });
  EXPECT_HAS(face, "face/constant/polyMesh/faces:");
  EXPECT_HAS(face, ": a count of 4000000000 vertices, but only ");
  const std::string shortList = errorWithCase("short", [](const fs::path& foam) {
    write(foam / "constant/polyMesh/faces",
          header("faceList", "faces") +
              replace(replace(kFaces, "6\n(", "5\n("), "4(4 5 6 7)\n", ""));
  });
  EXPECT_HAS(shortList, "short/constant/polyMesh/faces:");
  EXPECT_HAS(shortList, "the list holds 5 faces, but the boundary file's patches end at face 6");
}
