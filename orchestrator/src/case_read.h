#pragma once
/// The case reader's parts (docs/case-schema.md): one reader or checker per concern, each with
/// the sections it needs declared, run in the order of caseReaders() (preCICE reads its
/// configuration per concern the same way). Every key is parsed once: a section a later part
/// needs again (the walls mapping, the species entries) is kept in CaseReading.

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator::caseread {

using yaml::Section;

constexpr double kBig = std::numeric_limits<double>::max();

/// What the readers share while one case file is read.
struct CaseReading {
  const Section& top;
  CaseConfig& c;
  std::optional<Section> walls;         ///< the walls mapping, checked once (walls, walls.meshes)
  std::vector<Section> species;         ///< the species entries, checked once (species, ideal gas)
  std::optional<Section> gasProperties; ///< checked once (gas_properties, ideal gas)
  bool gasModelGiven = false;           ///< gas_properties.model is in the file
  /// models: {drag.syamlal-obrien.u_mf, .eps_mf}: the case reader's own keys (calibrateDrag turns
  /// them into the DEM's c1 and d1), with their place in the file.
  struct CalibrationKey {
    std::string key;
    double value;
    YAML::Mark mark;
  };
  std::vector<CalibrationKey> dragCalibration;
};

/// One part of the case reader: the part (a top-level section, a sub-part such as
/// "walls.meshes", or a checker across sections) and the parts whose results it reads.
struct CaseReader {
  const char* part;
  std::vector<const char*> needs;
  void (*read)(CaseReading&);
};

/// The readers in the order parseCase runs them (the order of the first error a case reports).
const std::vector<CaseReader>& caseReaders();

/// "" when every reader comes after the parts it needs; else the first violation, in words.
std::string checkReaderOrder(const std::vector<CaseReader>& readers);

// Readers by concern (case_read_*.cpp).
void readName(CaseReading& r);
void readTime(CaseReading& r);
void readGrid(CaseReading& r);
void readGravity(CaseReading& r);
void readSpecies(CaseReading& r);
void readGasProperties(CaseReading& r);
void resolveGasModel(CaseReading& r);
void readMaterials(CaseReading& r);
void readMaterialPairs(CaseReading& r);
void checkContactMaterials(CaseReading& r);
void readInitialState(CaseReading& r);
void readParticles(CaseReading& r);
void readWalls(CaseReading& r);
void readModels(CaseReading& r);
void calibrateDrag(CaseReading& r);
void readDem(CaseReading& r);
void readCfd(CaseReading& r);
void readBoundaries(CaseReading& r);
void readMeshWalls(CaseReading& r);
void readGasSection(CaseReading& r);
void checkIdealGas(CaseReading& r);
void readCoupling(CaseReading& r);
void readCheckpoint(CaseReading& r);
void readOutput(CaseReading& r);
void readSolidSpecies(CaseReading& r);
void readReactions(CaseReading& r);
void readChemistry(CaseReading& r);

// Shared by the chemistry readers.
const SpeciesConfig* findSpecies(const std::vector<SpeciesConfig>& list, const std::string& name);
std::string speciesNames(const std::vector<SpeciesConfig>& list);

} // namespace coredem::orchestrator::caseread
