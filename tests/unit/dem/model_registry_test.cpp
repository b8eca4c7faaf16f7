// The parameter path of the model families (src/model_registry.h, kernels/model_list.h), with a
// family of the test's own whose models have parameters: a declared parameter gets its `models:`
// row ("<family>.<model>.<key>"), its value is range-checked and stored in the family's ParamPack,
// enters the hash text when it differs from its default (only for the chosen model), is checked
// when set in code, and reaches the model's kernel through Dispatch. The drag laws and the Nusselt
// correlations use the same templates (models.cpp).
#include <array>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/convection.h"
#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/model_list.h"
#include "coredem/dem/models.h"
#include "model_registry.h"

using namespace coredem::dem;
namespace k = coredem::dem::kernels;

namespace {

struct ScaleModel {
  static constexpr const char* name = "scale";
  static constexpr const char* doc = "y = c x";
  struct Params {
    double c = 2.0;
  };
  static constexpr auto params() {
    return std::array{k::ModelParam<Params>{"c", &Params::c, 0.0, 10.0, true, "-", "factor"}};
  }
  static double evaluate(const Params& p, double x) { return p.c * x; }
};

struct AffineModel {
  static constexpr const char* name = "affine";
  static constexpr const char* doc = "y = a x + b";
  struct Params {
    double a = 1.0;
    double b = 0.5;
  };
  static constexpr auto params() {
    return std::array{k::ModelParam<Params>{"a", &Params::a, -1.0, 1.0, false, "-", "slope"},
                      k::ModelParam<Params>{"b", &Params::b, 0.0, 5.0, false, "m", "offset"}};
  }
  static double evaluate(const Params& p, double x) { return p.a * x + p.b; }
};

using TestModels = k::ModelList<ScaleModel, AffineModel>;
using TestPack = k::ParamPack<TestModels>;

enum class TestModel : int { Scale = 0, Affine = 1 };

struct TestFamily {
  template <class M>
  static double evaluate(const TestPack& pack, const double& x) {
    return M::evaluate(pack.template of<M>(), x);
  }
};

struct TestConfig {
  TestModel model = TestModel::Scale;
  TestPack params{};
  struct Nested {
    TestPack params{};
  } nested;
};

TestPack& nestedParams(TestConfig& c) {
  return c.nested.params;
}

using Row = registry::ParamRow<TestConfig>;

std::vector<Row> rows() {
  return registry::paramRowsOf<TestConfig, TestModels, &TestConfig::params>("test");
}

const Row& rowOf(const std::vector<Row>& all, const std::string& key) {
  for (const Row& r : all)
    if (r.key == key)
      return r;
  throw std::runtime_error("no row " + key);
}

} // namespace

TEST(ModelParamRegistry, EntriesComeFromTheList) {
  constexpr auto entries = registry::entriesOf<TestModel>(TestModels{});
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].name, "scale");
  EXPECT_EQ(entries[0].value, TestModel::Scale);
  EXPECT_EQ(entries[1].name, "affine");
  EXPECT_EQ(entries[1].value, TestModel::Affine);
  EXPECT_EQ(entries[1].doc, "y = a x + b");
}

// One row per declared parameter, in id and declaration order, with key, range and default
// from the declaration.
TEST(ModelParamRegistry, RowsComeFromTheDeclarations) {
  const std::vector<Row> all = rows();
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].key, "test.scale.c");
  EXPECT_EQ(all[1].key, "test.affine.a");
  EXPECT_EQ(all[2].key, "test.affine.b");
  EXPECT_EQ(all[0].values, "number in (0, 10]");
  EXPECT_EQ(all[1].values, "number in [-1, 1]");
  EXPECT_EQ(all[0].defaultValue, "2");
  EXPECT_EQ(all[2].defaultValue, "0.5");
  EXPECT_EQ(all[2].doc, "offset (m), affine only");
  for (const Row& r : all) {
    EXPECT_EQ(r.family, "test");
    ASSERT_NE(r.apply, nullptr) << r.key;
    TestConfig c;
    EXPECT_EQ(r.apply(c, r.defaultValue), "") << r.key;
  }
}

// A value in range is stored in its model's Params (and nowhere else); one outside the declared
// range, or not a number, is refused with the range and leaves the value unchanged.
TEST(ModelParamRegistry, ValuesAreRangeCheckedAndStored) {
  const std::vector<Row> all = rows();
  TestConfig c;
  EXPECT_EQ(rowOf(all, "test.scale.c").apply(c, "3.5"), "");
  EXPECT_EQ(c.params.of<ScaleModel>().c, 3.5);
  EXPECT_EQ(c.params.of<AffineModel>().a, 1.0);
  EXPECT_EQ(c.params.of<AffineModel>().b, 0.5);
  EXPECT_EQ(c.nested.params.of<ScaleModel>().c, 2.0);
  EXPECT_EQ(rowOf(all, "test.scale.c").apply(c, "10"), ""); // hi included
  EXPECT_EQ(c.params.of<ScaleModel>().c, 10.0);
  for (const char* bad : {"0", "-1", "10.5", "nan", "inf", "abc", "3.5x", ""}) {
    const std::string e = rowOf(all, "test.scale.c").apply(c, bad);
    EXPECT_NE(e.find("number in (0, 10]"), std::string::npos) << bad << ": " << e;
    EXPECT_EQ(c.params.of<ScaleModel>().c, 10.0) << bad;
  }
  EXPECT_EQ(rowOf(all, "test.affine.a").apply(c, "-1"), ""); // lo included
  EXPECT_EQ(c.params.of<AffineModel>().a, -1.0);
  EXPECT_NE(rowOf(all, "test.affine.a").apply(c, "-1.5"), "");
  EXPECT_EQ(c.params.of<AffineModel>().a, -1.0);

  // The same rows for a pack reached through a function (a nested member).
  const auto nested = registry::paramRowsOf<TestConfig, TestModels, &nestedParams>("test");
  EXPECT_EQ(rowOf(nested, "test.affine.b").apply(c, "2.5"), "");
  EXPECT_EQ(c.nested.params.of<AffineModel>().b, 2.5);
  EXPECT_EQ(c.params.of<AffineModel>().b, 0.5);
}

// Hash text: "" at the defaults (earlier hashes stay); the chosen model's non-default values by
// key, the others' not at all.
TEST(ModelParamRegistry, ChosenNonDefaultParametersEnterTheHash) {
  const std::vector<Row> all = rows();
  TestConfig c;
  const int scale = static_cast<int>(TestModel::Scale),
            affine = static_cast<int>(TestModel::Affine);
  EXPECT_EQ(registry::paramsHashText(c.params, scale, "test"), "");
  EXPECT_EQ(registry::paramsHashText(c.params, affine, "test"), "");
  ASSERT_EQ(rowOf(all, "test.scale.c").apply(c, "3.5"), "");
  EXPECT_EQ(registry::paramsHashText(c.params, scale, "test"), "|test.scale.c:3.5;");
  EXPECT_EQ(registry::paramsHashText(c.params, affine, "test"), "");
  ASSERT_EQ(rowOf(all, "test.affine.b").apply(c, "0.1"), "");
  EXPECT_EQ(registry::paramsHashText(c.params, affine, "test"),
            "|test.affine.b:0.10000000000000001;");
  ASSERT_EQ(rowOf(all, "test.affine.a").apply(c, "-0.5"), "");
  EXPECT_EQ(registry::paramsHashText(c.params, affine, "test"),
            "|test.affine.a:-0.5;|test.affine.b:0.10000000000000001;");
  ASSERT_EQ(rowOf(all, "test.scale.c").apply(c, "3.25"), "");
  EXPECT_EQ(registry::paramsHashText(c.params, scale, "test"), "|test.scale.c:3.25;");
}

// A value set in code (not through a row) is checked against the declared range, for the chosen
// model only.
TEST(ModelParamRegistry, ParametersSetInCodeAreChecked) {
  TestConfig c;
  EXPECT_NO_THROW(registry::checkParams(c.params, 0, "test"));
  EXPECT_NO_THROW(registry::checkParams(c.params, 1, "test"));
  c.params.of<ScaleModel>().c = 0.0; // lo excluded
  try {
    registry::checkParams(c.params, 0, "test");
    FAIL() << "c = 0 accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("test.scale.c"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("number in (0, 10]"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(registry::checkParams(c.params, 1, "test")); // scale is not chosen
  c.params.of<AffineModel>().b = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(registry::checkParams(c.params, 1, "test"), coredem::UserError);
}

// The values parsed from `models:` reach the chosen model's kernel through Dispatch.
TEST(ModelParamRegistry, ParametersReachTheKernel) {
  const std::vector<Row> all = rows();
  TestConfig c;
  ASSERT_EQ(rowOf(all, "test.scale.c").apply(c, "3.5"), "");
  ASSERT_EQ(rowOf(all, "test.affine.a").apply(c, "-0.5"), "");
  ASSERT_EQ(rowOf(all, "test.affine.b").apply(c, "4"), "");
  const TestPack copied = c.params; // as DemConfig::dragLaws → EngineSetup::drag.laws
  using Call = k::Dispatch<TestFamily, TestModels>;
  EXPECT_EQ(Call::call(static_cast<int>(TestModel::Scale), copied, 2.0), 7.0);
  EXPECT_EQ(Call::call(static_cast<int>(TestModel::Affine), copied, 2.0), 3.0);
  constexpr int affineId = k::modelId<AffineModel, TestModels>;
  EXPECT_EQ(affineId, 1);
}

// The DEM's families go through the same path: every declared parameter of the drag laws and the
// Nusselt correlations has its `models:` row, and a default DemConfig hashes and checks as before.
TEST(ModelParamRegistry, DemFamiliesHaveARowPerDeclaredParameter) {
  auto expectRows = [](std::string_view family, auto list) {
    k::forEachModel(list, [&]<class M>() {
      for (const auto& p : M::params()) {
        const std::string key = registry::paramKey<M>(family, p.key);
        const ModelOption* o = findModelOption(key);
        ASSERT_NE(o, nullptr) << key;
        EXPECT_EQ(o->family, family);
        EXPECT_EQ(o->values, registry::rangeText(p));
      }
    });
  };
  expectRows("drag", k::DragLaws{});
  expectRows("convection", k::NusseltModels{});
  const DemConfig c;
  EXPECT_EQ(modelParamsHashText(c), "");
  EXPECT_NO_THROW(checkModelParams(c));
}
