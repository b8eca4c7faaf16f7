#pragma once
/// @file
/// Vessels from one description (`coredem mesh`, docs/case-schema.md "Vessels: coredem mesh"):
/// a vertical cylinder with an optional conical bottom, or a box, described once in a small YAML
/// file, becomes both OpenFOAM's system/blockMeshDict (a body-fitted O-grid for the cylinder:
/// per level a central square and four outer blocks bounded by 90-degree arcs) and the matching
/// case.yaml `grid`, `walls`, `inlets` and `outlets` of the DEM and the coupling. The DEM walls of
/// a cylinder are the inscribed ones: blockMesh's wall faces are flat quads between points on the
/// circle, which lie inside the circle by up to r (1 - cos(pi/n)) for n cells around, so the DEM
/// cylinder and cone take the radii r cos(pi/n) and touch every face along its middle.

#include <filesystem>
#include <string>

#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// A vessel description (the file `coredem mesh` reads).
struct VesselSpec {
  std::string shape = "cylinder"; ///< cylinder | box
  int axis = 2;                   ///< 0, 1, 2: the vessel's axis (x, y, z), inlet at its low end
  Vec3 origin{0.0, 0.0, 0.0};     ///< cylinder: centre of the bottom (inlet); box: min corner
  double radius = 0.0;            ///< cylinder radius (m)
  double height = 0.0;            ///< cylinder: total height including the cone (m)
  double coneHeight = 0.0;        ///< conical bottom's height (m); 0: a flat bottom
  double coneRadius = 0.0;        ///< conical bottom's radius at the inlet (m)
  Vec3 size{0.0, 0.0, 0.0};       ///< box: edge lengths (m)
  double cellSize = 0.0;          ///< target cell size (m)
  int around = 0;                 ///< cylinder: cells around (multiple of 4, >= 8); 0: from cellSize
};

/// Reads a vessel description (YAML); throws ConfigError naming file:line:col and the key.
VesselSpec readVesselSpec(const std::filesystem::path& file);

/// What `coredem mesh` writes.
struct VesselFiles {
  std::string blockMeshDict; ///< system/blockMeshDict
  std::string caseYaml;      ///< grid, walls, inlets, outlets for case.yaml
  long long cells = 0;       ///< hexahedra of the mesh
  std::string summary;       ///< one paragraph for the terminal
};

/// The blockMeshDict and the case.yaml part of a vessel (`source` names the description in
/// their comments).
VesselFiles vesselFiles(const VesselSpec& spec, const std::string& source);

} // namespace coredem::orchestrator
