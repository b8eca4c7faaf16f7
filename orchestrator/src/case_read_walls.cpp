// walls (protocol v1.4; docs/case-schema.md "walls"): box, planes, cylinders, cones, material,
// thermal condition; then walls.meshes (STL files or patches of the CFD mesh), after cfd.
#include <algorithm>
#include <array>
#include <cmath>
#include <regex>

#include <yaml-cpp/yaml.h>

#include <coredem/dem/triangle_mesh.h>
#include <coredem/orchestrator/participants.h>

#include "case_read.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator::caseread {
namespace {

/// The range of walls.meshes[].scale: a length unit from µm to km (1e-30 was accepted before
/// and made a micro-mesh no particle can touch).
constexpr double kMinStlScale = 1e-6;
constexpr double kMaxStlScale = 1e3;

} // namespace

namespace {

using yaml::describe;
using yaml::join;

/// The axis of a cylinder or cone: nonzero, returned normalised.
Vec3 wallAxis(const Section& s) {
  Vec3 a = s.vec3("axis", std::nullopt, "axis direction, e.g. [0, 0, 1]");
  const double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  if (!(len > 0.0) || !std::isfinite(len)) {
    s.fail(s.markOf("axis"), s.full("axis"), "must be a nonzero direction, e.g. [0, 0, 1]");
  }
  for (double& x : a) {
    x /= len;
  }
  return a;
}

/// side and caps of a cylinder or cone (caps need a finite extent).
void wallSideAndCaps(const Section& s, RevolvedWallConfig& r) {
  r.side = s.choice("side", std::string("inside"), {"inside", "outside", "both"});
  if (!s.has("caps")) {
    return;
  }
  const YAML::Node caps = s.raw("caps");
  if (!caps.IsSequence()) {
    s.fail(s.markOf("caps"), s.full("caps"),
           fmt::format("expected a list of the ends to close: [], [start], [end] or [start, end]; "
                       "got {}",
                       describe(caps)));
  }
  for (std::size_t k = 0; k < caps.size(); ++k) {
    const std::string key = fmt::format("{}[{}]", s.full("caps"), k);
    if (!caps[k].IsScalar() || (caps[k].Scalar() != "start" && caps[k].Scalar() != "end")) {
      s.fail(caps[k].Mark(), key,
             fmt::format("{} is not an end; allowed: start, end", describe(caps[k])));
    }
    bool& cap = caps[k].Scalar() == "start" ? r.capStart : r.capEnd;
    if (cap) {
      s.fail(caps[k].Mark(), key, fmt::format("'{}' is listed twice", caps[k].Scalar()));
    }
    cap = true;
  }
  if ((r.capStart || r.capEnd) && !r.finite) {
    s.fail(s.markOf("caps"), s.full("caps"),
           "an infinite cylinder has no ends to cap; give 'from' and 'to' (m along the axis) or "
           "remove 'caps'");
  }
}

/// The axial extent from/to of a cylinder (both or neither) or a cone (both required).
void wallExtent(const Section& s, RevolvedWallConfig& r) {
  if (r.cone) {
    s.require("from", "m along the axis from 'point' where the cone starts");
    s.require("to", "m along the axis from 'point' where the cone ends, > from");
  } else if (s.has("from") != s.has("to")) {
    const std::string given = s.has("from") ? "from" : "to";
    s.fail(s.markOf(given), s.full(given),
           "give both 'from' and 'to' (a finite cylinder) or neither (an infinite cylinder)");
  }
  r.finite = s.has("from");
  if (!r.finite) {
    return;
  }
  r.from = s.number("from", std::nullopt, -kBig, kBig, "m along the axis from 'point'");
  r.to = s.number("to", std::nullopt, -kBig, kBig, "m along the axis from 'point', > from");
  if (!(r.to > r.from)) {
    s.fail(s.markOf("to"), s.full("to"),
           fmt::format("{} m must exceed from = {} m (the axis points from 'from' to 'to')", r.to,
                       r.from));
  }
}

/// A wall's `material:` (protocol v1.6): a material name, or "" (absent: each particle meets the
/// wall with its own material).
std::string wallMaterial(const Section& s, const CaseConfig& c) {
  if (!s.has("material")) {
    return {};
  }
  const std::string name = s.string("material", std::nullopt, "contact material of the wall");
  if (materialIndex(c, name) < 0) {
    s.fail(s.markOf("material"), s.full("material"), fmt::format("unknown material '{}'", name));
  }
  return name;
}

/// walls.cylinders, walls.cones (protocol v1.4; docs/case-schema.md "walls").
void parseWallShapes(const Section& w, CaseConfig& c) {
  if (w.has("cylinders")) {
    for (const auto& s :
         w.list("cylinders", {"point", "axis", "radius", "from", "to", "side", "caps", "material"},
                "cylinder walls")) {
      RevolvedWallConfig r;
      r.index = c.walls.revolved.size();
      r.point = s.vec3("point", std::nullopt, "m, a point on the axis");
      r.axis = wallAxis(s);
      r.radiusFrom = r.radiusTo = s.number("radius", std::nullopt, 0.0, kBig, "m, > 0", true);
      wallExtent(s, r);
      wallSideAndCaps(s, r);
      r.material = wallMaterial(s, c);
      c.walls.revolved.push_back(r);
    }
  }
  if (w.has("cones")) {
    std::size_t index = 0;
    for (const auto& s : w.list("cones",
                                {"point", "axis", "from", "to", "radius_from", "radius_to", "side",
                                 "caps", "material"},
                                "cone (frustum) walls")) {
      RevolvedWallConfig r;
      r.cone = true;
      r.index = index++;
      r.point = s.vec3("point", std::nullopt, "m, a point on the axis");
      r.axis = wallAxis(s);
      wallExtent(s, r);
      r.radiusFrom = s.number("radius_from", std::nullopt, 0.0, kBig, "m at 'from', >= 0");
      r.radiusTo = s.number("radius_to", std::nullopt, 0.0, kBig, "m at 'to', >= 0");
      if (!(r.radiusFrom > 0.0 || r.radiusTo > 0.0)) {
        s.fail(s.markOf("radius_to"), s.full("radius_to"),
               "a cone needs a radius > 0 at one end at least (radius_from or radius_to)");
      }
      wallSideAndCaps(s, r);
      r.material = wallMaterial(s, c);
      c.walls.revolved.push_back(r);
    }
  }
}

/// The patch names of walls.meshes[i].from_cfd: a list of names (or one name).
std::vector<std::string> patchNames(const Section& s) {
  const YAML::Node n = s.raw("from_cfd");
  std::vector<std::string> names;
  if (n.IsScalar()) {
    names.push_back(n.Scalar());
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) {
      if (!n[i].IsScalar() || n[i].Scalar().empty()) {
        s.fail(n[i].Mark(), fmt::format("{}[{}]", s.full("from_cfd"), i),
               fmt::format("expected a patch name, found {}", describe(n[i])));
      }
      names.push_back(n[i].Scalar());
    }
  }
  if (names.empty()) {
    s.fail(s.markOf("from_cfd"), s.full("from_cfd"),
           fmt::format("expected a list of patch names of the CFD mesh, e.g. [walls], found {}",
                       describe(n)));
  }
  return names;
}

/// walls.meshes[i].from_cfd: the wall from patches of the mesh of cfd.case, read by the CFD
/// participant's `meshPatches` hook (the OpenFOAM case's constant/polyMesh).
void meshFromCfd(const Section& s, const CaseConfig& c, bool cfdSection, MeshWallConfig& m) {
  const std::string key = s.full("from_cfd");
  const ParticipantDescriptor& p = participant(c.cfd.participant);
  if (p.meshPatches == nullptr) {
    std::vector<std::string> withMesh;
    for (const auto& q : participantTable()) {
      if (q.meshPatches != nullptr) {
        withMesh.push_back(q.name);
      }
    }
    s.fail(s.markOf("from_cfd"), key,
           fmt::format("from_cfd takes the walls from the mesh of the OpenFOAM case in cfd.case, "
                       "but the CFD participant is {} ({}), which has no mesh; use "
                       "cfd: {{participant: {}, case: <OpenFOAM case folder>}}, or give the wall "
                       "as an STL file (walls.meshes[].file)",
                       p.name, cfdSection ? "cfd.participant" : "the default: no cfd section",
                       join(withMesh)));
  }
  m.fromCfd = patchNames(s);
  const fs::path cfdCase = fs::absolute(c.caseDir / c.cfd.caseFolder).lexically_normal();
  m.path = cfdCase / p.meshFolder;
  m.name = fmt::format("{}/{}:{}", c.cfd.caseFolder, p.meshFolder, join(m.fromCfd));
  if (m.name.size() > 200) { // the DEM server's limit on names is 256 bytes
    m.name = fmt::format("{}... ({} patches)", m.name.substr(0, 170), m.fromCfd.size());
  }
  CfdPatchSurface surface;
  try {
    surface = p.meshPatches(cfdCase, m.fromCfd);
  } catch (const CfdMeshError& e) {
    s.fail(s.markOf("from_cfd"), key, e.what());
  }
  dem::TriangleMesh mesh;
  mesh.name = m.name;
  mesh.vertices = std::move(surface.vertices);
  mesh.triangles = std::move(surface.triangles);
  try {
    // No domain: the mesh is in metres (OpenFOAM's points are); the pre-flight compares it with
    // the coupling grid.
    dem::checkMesh(mesh, dem::MeshCheckOptions{m.closed, std::nullopt});
  } catch (const dem::MeshError& e) {
    std::string what = e.what();
    // Triangle numbers mean nothing to the user: name the mesh face it comes from.
    std::string face;
    static const std::regex triangle("triangle ([0-9]+)");
    std::smatch hit;
    if (std::regex_search(what, hit, triangle)) {
      const std::size_t t = std::stoul(hit[1].str()) - 1;
      if (t < surface.sourceFace.size()) {
        face = fmt::format(" (triangle {} is part of face {} of patch '{}')", t + 1,
                           surface.sourceFace[t], m.fromCfd[surface.sourcePatch[t]]);
      }
    }
    // The STL checker's advice (export the surface again) does not fit a CFD mesh.
    const auto advice = what.find("; a closed wall is required");
    if (advice != std::string::npos && what.find("not closed") != std::string::npos) {
      what = fmt::format("{}{}; a closed wall is required ({}: true): name every patch around "
                         "the fluid in {}, or set {}: false for an open wall",
                         what.substr(0, advice), face, s.full("closed"), key, s.full("closed"));
    } else {
      what += face + "; check the CFD mesh (checkMesh)";
    }
    s.fail(s.markOf("from_cfd"), key, what);
  }
  m.vertices = std::move(mesh.vertices);
  m.triangles = std::move(mesh.triangles);
}

/// walls.meshes (protocol v1.4; docs/case-schema.md "walls"): STL files or patches of the CFD
/// mesh. Called after the cfd section (from_cfd reads cfd.case).
void parseMeshWalls(const Section& w, CaseConfig& c, bool cfdSection) {
  if (!w.has("meshes")) {
    return;
  }
  // The walls are expected inside the coupling grid (pre-flight checks that too): a mesh far
  // larger than the grid is probably in millimetres. The grid is required in every case, so it is
  // always the domain (a DEM-only case still has one, covering its walls).
  std::array<double, 6> domain{};
  for (int d = 0; d < 3; ++d) {
    domain[std::size_t(d)] = c.grid.origin[std::size_t(d)];
    domain[std::size_t(d) + 3] =
        c.grid.origin[std::size_t(d)] +
        c.grid.spacing[std::size_t(d)] * double(c.grid.cells[std::size_t(d)]);
  }
  for (const auto& s : w.list("meshes", {"file", "from_cfd", "scale", "closed", "material"},
                              "triangle-mesh walls")) {
    MeshWallConfig m;
    m.material = wallMaterial(s, c);
    m.closed = s.onOff("closed", false);
    if (s.has("file") && s.has("from_cfd")) {
      s.fail(s.markOf("from_cfd"), s.full("from_cfd"),
             "give either 'file' (an STL file) or 'from_cfd' (patches of the CFD mesh), not both");
    }
    if (s.has("from_cfd")) {
      if (s.has("scale")) {
        s.fail(s.markOf("scale"), s.full("scale"),
               "not used with from_cfd: the CFD mesh's points are in metres already; remove it");
      }
      meshFromCfd(s, c, cfdSection, m);
      c.walls.meshes.push_back(std::move(m));
      continue;
    }
    m.file = s.string("file", std::nullopt,
                      "STL file, relative to the case folder (or from_cfd: patches of the CFD "
                      "mesh)");
    m.name = m.file;
    m.scale = s.number("scale", 1.0, 0.0, kBig,
                       "factor to metres, > 0 (1: file in m, 0.001: file in mm)", true);
    if (m.scale < kMinStlScale || m.scale > kMaxStlScale) {
      s.fail(s.markOf("scale"), s.full("scale"),
             fmt::format("{:g} is not a length unit: give the factor from the file's unit to "
                         "metres, from {:g} (µm) to {:g} (km), e.g. 0.001 for mm, 0.0254 for in",
                         m.scale, kMinStlScale, kMaxStlScale));
    }
    // Relative to the case folder, like initial_state and cfd.case: a resumed run finds the file
    // through run.json's case_dir, a campaign member through the links to the base case's files.
    m.path = fs::absolute(c.caseDir / m.file);
    std::error_code ec;
    const fs::file_status st = fs::status(m.path, ec);
    if (!fs::exists(st)) {
      s.fail(s.markOf("file"), s.full("file"),
             fmt::format("file '{}' not found (looked for {}); give an STL file (ASCII or binary) "
                         "relative to the case folder",
                         m.file, m.path.string()));
    }
    if (!fs::is_regular_file(st)) {
      // A directory, FIFO, socket or device (a link to /dev/zero): never opened, so that nothing
      // blocks or reads without end.
      s.fail(s.markOf("file"), s.full("file"),
             fmt::format("'{}' ({}) is {}, not a regular file; give an STL file (ASCII or binary) "
                         "relative to the case folder",
                         m.file, m.path.string(),
                         fs::is_directory(st)                                 ? "a directory"
                         : fs::is_fifo(st)                                    ? "a FIFO"
                         : fs::is_socket(st)                                  ? "a socket"
                         : fs::is_character_file(st) || fs::is_block_file(st) ? "a device"
                                                                              : "not a file"));
    }
    try {
      dem::TriangleMesh mesh = dem::readStl(m.path, dem::StlOptions{m.scale});
      mesh.name = m.file;
      dem::checkMesh(mesh, dem::MeshCheckOptions{m.closed, domain});
      m.vertices = std::move(mesh.vertices);
      m.triangles = std::move(mesh.triangles);
    } catch (const dem::MeshError& e) {
      std::string what = e.what();
      if (m.closed && what.find("not closed") != std::string::npos) {
        what += fmt::format(" (or set {}: false for an open wall)", s.full("closed"));
      }
      s.fail(s.markOf("file"), s.full("file"), what);
    }
    c.walls.meshes.push_back(std::move(m));
  }
}

} // namespace

void readWalls(CaseReading& r) {
  CaseConfig& c = r.c;
  if (!r.top.has("walls")) {
    c.walls.material = c.materials.front().name;
    return;
  }
  const Section& w =
      r.walls.emplace(r.top.section("walls", {"box", "planes", "cylinders", "cones", "meshes",
                                              "material", "thermal", "temperature"}));
  if (w.has("box")) {
    const Section b = w.section("box", {"min", "max", "material"});
    c.walls.box =
        std::make_pair(b.vec3("min", std::nullopt, "m"), b.vec3("max", std::nullopt, "m"));
    c.walls.boxMaterial = wallMaterial(b, c);
  }
  if (w.has("planes")) {
    for (const auto& pl : w.list("planes", {"point", "normal", "material"}, "planar walls")) {
      c.walls.planes.push_back({pl.vec3("point", std::nullopt, "m"),
                                pl.vec3("normal", std::nullopt, "into the domain"),
                                wallMaterial(pl, c)});
    }
  }
  parseWallShapes(w, c);
  c.walls.material = w.string("material", c.materials.front().name, "material of the walls");
  if (materialIndex(c, c.walls.material) < 0) {
    w.fail(w.markOf("material"), "walls.material",
           fmt::format("unknown material '{}'", c.walls.material));
  }
  // Thermal condition (docs/heat-coupling.md "Walls"): adiabatic (default) or every wall held
  // at `temperature` with particle–wall conduction. Configure carries it as temperature (0 =
  // adiabatic).
  const std::string thermal =
      w.choice("thermal", std::string("adiabatic"), {"adiabatic", "fixed_temperature"});
  if (thermal == "fixed_temperature") {
    c.walls.temperature = w.number("temperature", std::nullopt, 0.0, kBig,
                                   "K, > 0 (the temperature the walls are held at)", true);
  } else {
    if (w.has("temperature")) {
      w.fail(w.markOf("temperature"), "walls.temperature",
             "walls are adiabatic (walls.thermal: adiabatic, the default), so a wall temperature "
             "has no effect; add 'thermal: fixed_temperature' to hold the walls at it, or remove "
             "it");
    }
    c.walls.temperature = 0.0;
  }
}

void readMeshWalls(CaseReading& r) {
  if (r.walls) { // after cfd: walls.meshes[].from_cfd reads cfd.case
    parseMeshWalls(*r.walls, r.c, r.top.has("cfd"));
  }
}

} // namespace coredem::orchestrator::caseread
