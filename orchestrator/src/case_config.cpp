#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/sha256.h>

#include "case_read.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator {

namespace caseread {

const std::vector<CaseReader>& caseReaders() {
  // The order is the order of the checks (a case with two errors reports the first); each part
  // comes after the parts it reads (checkReaderOrder, tested in case_reader_test.cpp).
  static const std::vector<CaseReader> readers = {
      {"name", {}, readName},
      {"time", {}, readTime},
      {"grid", {}, readGrid},
      {"gravity", {}, readGravity},
      {"species", {}, readSpecies},
      {"gas_properties", {}, readGasProperties},
      {"materials", {}, readMaterials},
      {"initial_state", {}, readInitialState},
      {"particles", {"materials", "initial_state"}, readParticles},
      {"walls", {"materials"}, readWalls},
      {"models", {}, readModels},
      {"material_pairs", {"materials"}, readMaterialPairs},
      {"contact_materials", {"materials", "models"}, checkContactMaterials},
      {"dem", {}, readDem},
      {"cfd", {}, readCfd},
      {"boundaries", {"cfd", "species"}, readBoundaries},
      {"walls.meshes", {"walls", "grid", "cfd"}, readMeshWalls},
      {"gas", {}, readGasSection},
      {"solid_species", {"species", "particles"}, readSolidSpecies},
      {"reactions", {"species", "solid_species"}, readReactions},
      {"chemistry", {"species", "solid_species"}, readChemistry},
      {"gas_model",
       {"gas_properties", "particles", "walls", "models", "cfd", "reactions", "chemistry"},
       resolveGasModel},
      {"ideal_gas", {"species", "gas_model", "gas"}, checkIdealGas},
      {"drag_calibration", {"models", "gravity", "particles", "gas_model"}, calibrateDrag},
      {"coupling", {"gas_model"}, readCoupling},
      {"checkpoint", {}, readCheckpoint},
      {"output", {}, readOutput},
  };
  return readers;
}

std::string checkReaderOrder(const std::vector<CaseReader>& readers) {
  for (std::size_t i = 0; i < readers.size(); ++i) {
    for (const char* need : readers[i].needs) {
      bool before = false;
      for (std::size_t j = 0; j < i; ++j) {
        before = before || std::string(readers[j].part) == need;
      }
      if (!before) {
        return fmt::format("'{}' needs '{}', which is not read before it", readers[i].part, need);
      }
    }
  }
  return {};
}

} // namespace caseread

std::string RevolvedWallConfig::key() const {
  return fmt::format("walls.{}[{}]", cone ? "cones" : "cylinders", index);
}

int materialIndex(const CaseConfig& config, const std::string& name) {
  for (std::size_t i = 0; i < config.materials.size(); ++i) {
    if (config.materials[i].name == name) {
      return int(i);
    }
  }
  return -1;
}

CaseConfig parseCase(const std::string& text, const fs::path& file, const fs::path& caseDir) {
  const std::string fileName = file.string();
  const YAML::Node root = yaml::parse(text, fileName);
  CaseConfig c;
  c.caseDir = caseDir;
  c.caseFile = fs::absolute(file);
  c.text = text;
  c.configHash = sha256Hex(text);

  if (root.IsMap() && root["stages"]) {
    const YAML::Mark m = root["stages"].Mark();
    throw CaseError(fmt::format("{}:{}:{}: stages: a staged case runs with 'coredem run' or "
                                "'coredem check' on its folder, one case per stage; it cannot be "
                                "loaded as one case here (e.g. as a campaign's base case)",
                                fileName, m.line + 1, m.column + 1));
  }
  const yaml::Section top(
      root, fileName, "",
      {"name",       "description",    "time",          "grid",      "gravity",
       "species",    "gas_properties", "materials",     "particles", "initial_state",
       "walls",      "models",         "dem",           "cfd",       "gas",
       "checkpoint", "output",         "solid_species", "reactions", "chemistry",
       "coupling",   "material_pairs", "inlets",        "outlets"},
      YAML::Mark());
  caseread::CaseReading reading{top, c, std::nullopt, {}, std::nullopt};
  for (const caseread::CaseReader& reader : caseread::caseReaders()) {
    reader.read(reading);
  }
  return c;
}

fs::path caseFileOf(const fs::path& caseDirOrFile) {
  return fs::is_directory(caseDirOrFile) ? caseDirOrFile / "case.yaml" : caseDirOrFile;
}

CaseConfig loadCase(const fs::path& caseDirOrFile) {
  const fs::path file = caseFileOf(caseDirOrFile);
  if (!fs::is_regular_file(file)) {
    throw CaseError(fmt::format("{}: case file not found; give a case folder that contains "
                                "case.yaml (or the path of a case file)",
                                file.string()));
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) {
    throw CaseError(fmt::format("{}: cannot read the case file", file.string()));
  }
  return parseCase(text.str(), file, fs::absolute(file).parent_path());
}

} // namespace coredem::orchestrator
