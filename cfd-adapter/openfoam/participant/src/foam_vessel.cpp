// Vessels from one description (foam_vessel.h): the O-grid or box blockMeshDict and the matching
// case.yaml part.
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/yaml_section.h>
#include <coredem/participant/foam_vessel.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

constexpr double kBig = 1e6;             // m: no vessel is larger
constexpr long long kMaxCells = 100000000; // hexahedra: beyond any mesh blockMesh makes here

std::string num(double v) {
  return fmt::format("{:.10g}", std::abs(v) < 1e-15 ? 0.0 : v);
}

std::string point(const Vec3& p) {
  return fmt::format("({} {} {})", num(p[0]), num(p[1]), num(p[2]));
}

std::string yamlVec(const Vec3& p) {
  return fmt::format("[{}, {}, {}]", num(p[0]), num(p[1]), num(p[2]));
}

/// Global coordinates of the local (u, v, w), w along the axis: a cyclic permutation of (x, y, z),
/// so right-handed blocks stay right-handed.
Vec3 global(const VesselSpec& s, double u, double v, double w) {
  Vec3 p = s.origin;
  p[std::size_t(s.axis)] += w;
  p[std::size_t((s.axis + 1) % 3)] += u;
  p[std::size_t((s.axis + 2) % 3)] += v;
  return p;
}

Vec3 axisVector(const VesselSpec& s) {
  Vec3 a{0.0, 0.0, 0.0};
  a[std::size_t(s.axis)] = 1.0;
  return a;
}

constexpr const char* kHeader = R"(/*--------------------------------*- C++ -*----------------------------------*\
  written by coredem mesh from {} (edit that file and run coredem mesh again)
\*---------------------------------------------------------------------------*/
FoamFile
{{
    version     2.0;
    format      ascii;
    class       dictionary;
    location    "system";
    object      blockMeshDict;
}}
// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //
)";

/// The O-grid of a cylinder with an optional conical bottom.
VesselFiles cylinderFiles(const VesselSpec& s, const std::string& source) {
  const double R = s.radius, H = s.height, hc = s.coneHeight;
  const int q = s.around / 4;
  const long long nr = std::max(1L, std::lround(R / 2.0 / s.cellSize));
  std::vector<std::pair<double, double>> levels; // (w, r)
  std::vector<long long> layers;
  if (hc > 0.0) {
    levels = {{0.0, s.coneRadius}, {hc, R}, {H, R}};
    layers = {std::max(1L, std::lround(hc / s.cellSize)),
              std::max(1L, std::lround((H - hc) / s.cellSize))};
  } else {
    levels = {{0.0, R}, {H, R}};
    layers = {std::max(1L, std::lround(H / s.cellSize))};
  }
  VesselFiles f;
  long long nLayers = 0;
  for (long long n : layers) {
    nLayers += n;
  }
  f.cells = nLayers * (q * q + 4LL * q * nr);
  if (f.cells > kMaxCells) {
    throw ConfigError(fmt::format("{}: the mesh would have {} cells (more than {}); give a larger "
                                  "cell_size or fewer cells around",
                                  source, f.cells, kMaxCells));
  }
  std::string d = fmt::format(fmt::runtime(kHeader), source);
  d += fmt::format("// Cylinder radius {} m, height {} m", num(R), num(H));
  if (hc > 0.0) {
    d += fmt::format(", conical bottom {} m high from radius {} m", num(hc), num(s.coneRadius));
  }
  d += fmt::format(
      ".\n// O-grid: per level a central square (half-width r/2) and four outer blocks bounded "
      "by\n// 90-degree arcs; {} cells around, {} along each square side, {} radially, {} "
      "layers:\n// {} cells. Vertices per level L (offset 8 L): 0-3 square corners, 4-7 arc "
      "corners at\n// 225, 315, 45, 135 degrees.\nvertices\n(\n",
      s.around, q, nr, fmt::join(layers, " + "), f.cells);
  const double c = std::numbers::sqrt2 / 2.0;
  for (const auto& [w, r] : levels) {
    const double a = r / 2.0, b = r * c;
    d += fmt::format("    // w = {} m, r = {} m\n", num(w), num(r));
    for (const auto& [u, v] : std::vector<std::pair<double, double>>{
             {-a, -a}, {a, -a}, {a, a}, {-a, a}, {-b, -b}, {b, -b}, {b, b}, {-b, b}}) {
      d += "    " + point(global(s, u, v, w)) + "\n";
    }
  }
  d += ");\n\nblocks\n(\n";
  for (std::size_t k = 0; k < layers.size(); ++k) {
    const std::size_t o = 8 * k, p = 8 * (k + 1);
    d += fmt::format("    hex ({} {} {} {} {} {} {} {}) ({} {} {}) simpleGrading (1 1 1)\n", o,
                     o + 1, o + 2, o + 3, p, p + 1, p + 2, p + 3, q, q, layers[k]);
    const std::size_t ring[4][4] = {{4, 5, 1, 0}, {5, 6, 2, 1}, {6, 7, 3, 2}, {7, 4, 0, 3}};
    for (const auto& r : ring) {
      d += fmt::format("    hex ({} {} {} {} {} {} {} {}) ({} {} {}) simpleGrading (1 1 1)\n",
                       o + r[0], o + r[1], o + r[2], o + r[3], p + r[0], p + r[1], p + r[2],
                       p + r[3], q, nr, layers[k]);
    }
  }
  d += ");\n\nedges\n(\n";
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const auto [w, r] = levels[k];
    const std::size_t o = 8 * k;
    d += fmt::format("    arc {} {} {}\n", o + 4, o + 5, point(global(s, 0.0, -r, w)));
    d += fmt::format("    arc {} {} {}\n", o + 5, o + 6, point(global(s, r, 0.0, w)));
    d += fmt::format("    arc {} {} {}\n", o + 6, o + 7, point(global(s, 0.0, r, w)));
    d += fmt::format("    arc {} {} {}\n", o + 7, o + 4, point(global(s, -r, 0.0, w)));
  }
  const std::size_t t = 8 * (levels.size() - 1);
  d += fmt::format("\n);\n\nboundary\n(\n    inlet\n    {{\n        type patch;\n        faces\n"
                   "        (\n            (0 3 2 1) (4 0 1 5) (5 1 2 6) (6 2 3 7) (7 3 0 4)\n"
                   "        );\n    }}\n    outlet\n    {{\n        type patch;\n        faces\n"
                   "        (\n            ({0} {1} {2} {3}) ({4} {5} {1} {0}) ({5} {6} {2} {1}) "
                   "({6} {7} {3} {2}) ({7} {4} {0} {3})\n        );\n    }}\n    walls\n    {{\n"
                   "        type wall;\n        faces\n        (\n",
                   t, t + 1, t + 2, t + 3, t + 4, t + 5, t + 6, t + 7);
  for (std::size_t k = 0; k + 1 < levels.size(); ++k) {
    const std::size_t o = 8 * k, p = 8 * (k + 1);
    d += fmt::format("            ({} {} {} {}) ({} {} {} {}) ({} {} {} {}) ({} {} {} {})\n", o + 4,
                     o + 5, p + 5, p + 4, o + 5, o + 6, p + 6, p + 5, o + 6, o + 7, p + 7, p + 6,
                     o + 7, o + 4, p + 4, p + 7);
  }
  d += "        );\n    }\n);\n\nmergePatchPairs\n(\n);\n\n"
       "// ************************************************************************* //\n";
  f.blockMeshDict = d;

  // The case.yaml part: the coupling grid (cells of cell_size across, centred; the height split
  // evenly), the inscribed DEM walls, the distributor at the inlet, the patches.
  const double inscribed = std::cos(std::numbers::pi / s.around);
  const long long across = std::max(1LL, (long long)std::ceil(2.0 * R / s.cellSize - 1e-9));
  const long long along = std::max(1L, std::lround(H / s.cellSize));
  Vec3 origin = global(s, -across * s.cellSize / 2.0, -across * s.cellSize / 2.0, 0.0);
  Vec3 spacing{}, cells{};
  spacing[std::size_t(s.axis)] = H / double(along);
  cells[std::size_t(s.axis)] = double(along);
  for (int k = 1; k < 3; ++k) {
    spacing[std::size_t((s.axis + k) % 3)] = s.cellSize;
    cells[std::size_t((s.axis + k) % 3)] = double(across);
  }
  Vec3 g{0.0, 0.0, 0.0};
  g[std::size_t(s.axis)] = -9.81;
  const Vec3 a = axisVector(s);
  std::string y = fmt::format(
      "# written by coredem mesh from {}: the DEM walls and the coupling grid of the vessel\n"
      "# whose CFD mesh is system/blockMeshDict. Copy into case.yaml.\n"
      "gravity: {}   # = openfoam/constant/g: the vessel's axis points up\n"
      "grid:                 # {} x {} x {} cells around the vessel\n"
      "  origin: {}\n  spacing: {}\n  cells: [{}, {}, {}]\n"
      "walls:\n"
      "  # The CFD wall faces are flat quads between points on the circle ({} around): they lie\n"
      "  # inside it by up to r (1 - cos(pi/{})). The DEM walls are the inscribed ones, radius\n"
      "  # r cos(pi/{}) = {} r: they touch every face along its middle.\n"
      "  planes:            # the distributor: keeps the particles above the inlet\n"
      "    - {{point: {}, normal: {}}}\n"
      "  cylinders:\n"
      "    - {{point: {}, axis: {}, radius: {}, from: {}, to: {}, side: inside, caps: [end]}}\n",
      source, yamlVec(g), cells[0], cells[1], cells[2], yamlVec(origin), yamlVec(spacing),
      cells[0], cells[1], cells[2], s.around, s.around, s.around, num(inscribed),
      yamlVec(s.origin), yamlVec(a), yamlVec(s.origin), yamlVec(a), num(R * inscribed), num(hc),
      num(H));
  if (hc > 0.0) {
    y += fmt::format("  cones:\n    - {{point: {}, axis: {}, from: 0.0, to: {}, radius_from: {}, "
                     "radius_to: {}, side: inside}}\n",
                     yamlVec(s.origin), yamlVec(a), num(hc), num(s.coneRadius * inscribed),
                     num(R * inscribed));
  }
  const double inletRadius = hc > 0.0 ? s.coneRadius : R;
  y += fmt::format("inlets:\n  - patch: inlet    # the bottom disc, radius {} m\n"
                   "    superficial_velocity: {}   # m/s over the inlet disc: set it{}\n"
                   "outlets:\n  - patch: outlet   # the top disc\n",
                   num(inletRadius), yamlVec({0.0, 0.0, 0.0}),
                   hc > 0.0 ? fmt::format(" (the column's is (r_inlet/R)^2 = {} of it)",
                                          num(std::pow(s.coneRadius / R, 2)))
                            : std::string());
  f.caseYaml = y;
  f.summary = fmt::format(
      "cylinder of radius {} m and height {} m{}: {} blocks, {} cells ({} around, {} radially, "
      "{} layers); DEM walls inscribed in the faceted CFD wall: radius {} m (r cos(pi/{}))",
      num(R), num(H),
      hc > 0.0 ? fmt::format(" with a conical bottom {} m high from radius {} m", num(hc),
                             num(s.coneRadius))
               : std::string(),
      5 * layers.size(), f.cells, s.around, nr, fmt::join(layers, " + "), num(R * inscribed),
      s.around);
  return f;
}

/// One hexahedral block.
VesselFiles boxFiles(const VesselSpec& s, const std::string& source) {
  long long n[3];
  VesselFiles f;
  f.cells = 1;
  for (int k = 0; k < 3; ++k) {
    n[k] = std::max(1L, std::lround(s.size[std::size_t(k)] / s.cellSize));
    f.cells *= n[k];
  }
  if (f.cells > kMaxCells) {
    throw ConfigError(fmt::format("{}: the mesh would have {} cells (more than {}); give a larger "
                                  "cell_size",
                                  source, f.cells, kMaxCells));
  }
  const Vec3 lo = s.origin;
  const Vec3 hi{lo[0] + s.size[0], lo[1] + s.size[1], lo[2] + s.size[2]};
  std::string d = fmt::format(fmt::runtime(kHeader), source);
  d += fmt::format("// Box {} m, {} cells.\nvertices\n(\n", yamlVec(s.size), f.cells);
  for (int k = 0; k < 8; ++k) {
    const bool x = (k == 1 || k == 2 || k == 5 || k == 6), yy = (k % 4 == 2 || k % 4 == 3),
               z = k >= 4;
    d += "    " + point({x ? hi[0] : lo[0], yy ? hi[1] : lo[1], z ? hi[2] : lo[2]}) + "\n";
  }
  // Faces: x-, x+, y-, y+, z-, z+ (outward, as blockMesh orders them itself).
  const char* faces[6] = {"(0 4 7 3)", "(1 2 6 5)", "(0 1 5 4)", "(3 7 6 2)", "(0 3 2 1)",
                          "(4 5 6 7)"};
  std::string walls;
  for (int k = 0; k < 3; ++k) {
    if (k != s.axis) {
      walls += fmt::format(" {} {}", faces[2 * k], faces[2 * k + 1]);
    }
  }
  d += fmt::format(");\n\nblocks\n(\n    hex (0 1 2 3 4 5 6 7) ({} {} {}) simpleGrading (1 1 1)\n"
                   ");\n\nedges\n(\n);\n\nboundary\n(\n"
                   "    inlet  {{ type patch; faces ({}); }}\n"
                   "    outlet {{ type patch; faces ({}); }}\n"
                   "    walls  {{ type wall;  faces ({} ); }}\n);\n\nmergePatchPairs\n(\n);\n\n"
                   "// ************************************************************************* "
                   "//\n",
                   n[0], n[1], n[2], faces[2 * s.axis], faces[2 * s.axis + 1], walls);
  f.blockMeshDict = d;
  Vec3 spacing{}, g{0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k) {
    spacing[std::size_t(k)] = s.size[std::size_t(k)] / double(n[k]);
  }
  g[std::size_t(s.axis)] = -9.81;
  f.caseYaml = fmt::format(
      "# written by coredem mesh from {}: the DEM walls and the coupling grid of the vessel\n"
      "# whose CFD mesh is system/blockMeshDict (the grid is the mesh). Copy into case.yaml.\n"
      "gravity: {}   # = openfoam/constant/g: the vessel's axis points up\n"
      "grid:\n  origin: {}\n  spacing: {}\n  cells: [{}, {}, {}]\n"
      "walls:\n  box: {{min: {}, max: {}}}\n"
      "inlets:\n  - patch: inlet    # the bottom face\n"
      "    superficial_velocity: {}   # m/s: set it\n"
      "outlets:\n  - patch: outlet   # the top face\n",
      source, yamlVec(g), yamlVec(lo), yamlVec(spacing), n[0], n[1], n[2], yamlVec(lo),
      yamlVec(hi), yamlVec({0.0, 0.0, 0.0}));
  f.summary = fmt::format("box {} m from {}: {} x {} x {} = {} cells; the coupling grid is the "
                          "mesh, the DEM box its walls",
                          yamlVec(s.size), yamlVec(lo), n[0], n[1], n[2], f.cells);
  return f;
}

} // namespace

VesselSpec readVesselSpec(const fs::path& file) {
  if (!fs::is_regular_file(file)) {
    throw ConfigError(fmt::format("{}: vessel file not found (a YAML file: shape, radius, "
                                  "height, ... ; docs/case-schema.md \"Vessels\")",
                                  file.string()));
  }
  std::ifstream in(file, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const YAML::Node root = yaml::parse(text, file.string());
  const yaml::Section top(root, file.string(), "",
                          {"shape", "axis", "origin", "radius", "height", "cone", "size",
                           "cell_size", "around"},
                          YAML::Mark());
  VesselSpec s;
  s.shape = top.choice("shape", std::nullopt, {"cylinder", "box"});
  const std::string axis = top.choice("axis", std::string("z"), {"x", "y", "z"});
  s.axis = axis[0] - 'x';
  s.origin = top.vec3("origin", Vec3{0.0, 0.0, 0.0},
                      s.shape == "box" ? "the box's min corner in m"
                                       : "centre of the bottom (the inlet) in m");
  s.cellSize = top.number("cell_size", std::nullopt, 0.0, kBig, "target cell size in m, > 0", true);
  const auto refuse = [&](const std::string& key, const std::string& why) {
    top.fail(top.markOf(key), key, why);
  };
  if (s.shape == "box") {
    for (const char* key : {"radius", "height", "cone", "around"}) {
      if (top.has(key)) {
        refuse(key, "a box has 'size' [lx, ly, lz]; remove the key");
      }
    }
    s.size = top.vec3("size", std::nullopt, "edge lengths in m", 0.0, kBig, true);
    return s;
  }
  if (top.has("size")) {
    refuse("size", "a cylinder has radius and height; remove the key");
  }
  s.radius = top.number("radius", std::nullopt, 0.0, kBig, "m, > 0", true);
  s.height = top.number("height", std::nullopt, 0.0, kBig, "m, > 0 (the cone included)", true);
  if (top.has("cone")) {
    const yaml::Section c = top.section("cone", {"height", "radius"});
    s.coneHeight = c.number("height", std::nullopt, 0.0, s.height,
                            "m, > 0 and less than the vessel's height", true);
    if (s.coneHeight >= s.height) {
      c.fail(c.markOf("height"), "cone.height",
             fmt::format("{} m leaves no cylinder above it (height {} m)", s.coneHeight,
                         s.height));
    }
    s.coneRadius = c.number("radius", std::nullopt, 0.0, s.radius,
                            "radius at the inlet in m, in (0, radius]", true);
  }
  const long long q = std::max(2L, std::lround(s.radius / s.cellSize));
  s.around = int(top.integer("around", 4 * q, 8, 4096, "cells around, a multiple of 4"));
  if (s.around % 4 != 0) {
    refuse("around", fmt::format("{} is not a multiple of 4 (the O-grid's four outer blocks)",
                                 s.around));
  }
  return s;
}

VesselFiles vesselFiles(const VesselSpec& spec, const std::string& source) {
  return spec.shape == "box" ? boxFiles(spec, source) : cylinderFiles(spec, source);
}

} // namespace coredem::orchestrator
