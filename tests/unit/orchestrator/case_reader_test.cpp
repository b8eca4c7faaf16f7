// The case reader's table (orchestrator/src/case_read.h): every part comes after the parts it
// reads, each part is read once, and every top-level key of the case file has its reader.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "case_read.h"

namespace cr = coredem::orchestrator::caseread;

TEST(CaseReader, EveryPartComesAfterWhatItNeeds) {
  EXPECT_EQ(cr::checkReaderOrder(cr::caseReaders()), "");
}

TEST(CaseReader, OrderCheckFindsAPartReadTooEarly) {
  const std::vector<cr::CaseReader> bad = {{"walls.meshes", {"cfd"}, cr::readMeshWalls},
                                           {"cfd", {}, cr::readCfd}};
  EXPECT_EQ(cr::checkReaderOrder(bad), "'walls.meshes' needs 'cfd', which is not read before it");
}

TEST(CaseReader, EachPartOnceAndEveryTopLevelKeyRead) {
  std::set<std::string> parts;
  for (const auto& r : cr::caseReaders()) {
    EXPECT_TRUE(parts.insert(r.part).second) << r.part << " is read twice";
  }
  for (const char* key :
       {"name",           "time",          "grid",      "gravity",       "species",
        "gas_properties", "materials",     "particles", "initial_state", "walls",
        "models",         "dem",           "cfd",       "gas",           "checkpoint",
        "output",         "solid_species", "reactions", "chemistry",     "coupling"}) {
    EXPECT_EQ(parts.count(key), 1u) << key;
  }
}
