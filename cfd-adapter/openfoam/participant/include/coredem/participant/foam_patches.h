#pragma once
/// @file
/// Triangle surfaces from the patches of an OpenFOAM mesh (walls.meshes[].from_cfd,
/// docs/case-schema.md "walls"): reads `constant/polyMesh/{boundary,faces,points}` of a case in
/// ASCII, takes the faces of the named patches and splits each polygon into a fan of triangles
/// that keeps its winding. OpenFOAM's boundary faces point out of the fluid domain, so the
/// triangles do too (a closed set of patches is oriented outwards, as a closed STL is).

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <coredem/orchestrator/participant_descriptor.h>

namespace coredem::orchestrator {

/// A mesh that is missing, not in ASCII, malformed, or lacks a patch asked for. The message
/// names the file (or the patch) and what to do; it carries no case.yaml key.
/// Largest constant/polyMesh file from_cfd reads (an ASCII mesh of ~10^8 faces).
inline constexpr std::uintmax_t kMaxFoamMeshFileBytes = std::uintmax_t(2) << 30;

class FoamMeshError : public CfdMeshError {
public:
  using CfdMeshError::CfdMeshError;
};

/// One patch of constant/polyMesh/boundary.
struct FoamPatch {
  std::string name, type;
  std::int64_t nFaces = 0, startFace = 0;
};

/// The patches of `<foamCase>/constant/polyMesh/boundary`, in file order. Throws FoamMeshError.
std::vector<FoamPatch> readFoamBoundary(const std::filesystem::path& foamCase);

/// The surface of some patches, vertices renumbered to those its faces use (in order of first
/// use), triangles in the order of `patches`, then of the mesh's faces.
struct FoamPatchSurface {
  std::vector<double> vertices;         ///< x0,y0,z0,x1,... (m): points of the mesh, unchanged
  std::vector<std::int32_t> triangles;  ///< 3 vertex indices per triangle, the face's winding
  std::vector<std::int64_t> sourceFace; ///< per triangle: its mesh face (0-based, as in faces)
  std::vector<std::size_t> sourcePatch; ///< per triangle: its index in `patches`
  std::vector<std::int64_t> pointIndex; ///< per vertex: its index in constant/polyMesh/points
  std::size_t faces = 0;                ///< mesh faces taken
};

/// Reads the patches `patches` (names of constant/polyMesh/boundary, each once) of the OpenFOAM
/// case `foamCase`. Only patches of type wall or patch with faces qualify. A face of n vertices
/// becomes n - 2 triangles, a fan from the first of its vertices from which no fan triangle is
/// degenerate (the first vertex for a convex face without collinear corners). Throws
/// FoamMeshError: the mesh not made yet (no constant/polyMesh), binary or compressed files, a
/// syntax error (with its line), an unknown patch (listing those there), a patch of another
/// type or without faces, an index out of range.
FoamPatchSurface readFoamPatches(const std::filesystem::path& foamCase,
                                 const std::vector<std::string>& patches);

} // namespace coredem::orchestrator
