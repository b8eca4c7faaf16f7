// yaml::Section: every error names file:line:col, the full key and what is allowed.
#include <string>

#include <gtest/gtest.h>

#include <coredem/common/yaml_section.h>

namespace {

using coredem::ConfigError;
using coredem::yaml::Section;

std::string errorOf(const std::string& text, void (*use)(const Section&)) {
  try {
    const Section top(coredem::yaml::parse(text, "in.yaml"), "in.yaml", "", {"a", "b", "c"},
                      YAML::Mark());
    use(top);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlSection, UnknownKeyNamesLineColumnAndAllowedKeys) {
  EXPECT_EQ(errorOf("a: 1\nbb: 2\n", [](const Section&) {}),
            "in.yaml:2:1: bb: unknown key; allowed keys at the top level: a, b, c");
}

TEST(YamlSection, NumbersAreRangeChecked) {
  const auto e = errorOf("a: -1\n", [](const Section& s) {
    (void)s.number("a", std::nullopt, 0.0, Section::kMax, "s, > 0", true);
  });
  EXPECT_EQ(e, "in.yaml:1:4: a: -1 is out of range; allowed: > 0 (s, > 0)");
  EXPECT_NE(errorOf("a: x\n",
                    [](const Section& s) { (void)s.number("a", std::nullopt, 0, 1, "a fraction"); })
                .find("expected a number (a fraction), got 'x'"),
            std::string::npos);
}

TEST(YamlSection, NestedSectionsAndListsCarryTheFullKey) {
  const auto e = errorOf("b:\n  x: 1\n", [](const Section& s) { (void)s.section("b", {"y"}); });
  EXPECT_EQ(e, "in.yaml:2:3: b.x: unknown key; allowed keys in 'b': y");
  const auto l = errorOf("c:\n  - {y: 1}\n  - {z: 2}\n",
                         [](const Section& s) { (void)s.list("c", {"y"}, "things"); });
  EXPECT_NE(l.find("c[1].z: unknown key"), std::string::npos) << l;
}

TEST(YamlSection, ChoicesAndSwitches) {
  EXPECT_EQ(errorOf("a: maybe\n",
                    [](const Section& s) {
                      (void)s.choice("a", std::nullopt, {"yes", "no"});
                    }),
            "in.yaml:1:4: a: 'maybe' is not allowed; allowed: yes, no");
  EXPECT_EQ(errorOf("a: sometimes\n", [](const Section& s) { (void)s.onOff("a", false); }),
            "in.yaml:1:4: a: expected on or off, got 'sometimes'");
  const Section ok(coredem::yaml::parse("a: on\nb: 0\n", "x"), "x", "", {"a", "b"}, YAML::Mark());
  EXPECT_TRUE(ok.onOff("a", false));
  EXPECT_FALSE(ok.onOff("b", true));
  EXPECT_TRUE(ok.onOff("c", true)); // absent: the default
}

TEST(YamlSection, MissingRequiredKeyAndSyntaxErrors) {
  EXPECT_NE(errorOf("a: 1\n", [](const Section& s) { (void)s.string("b", std::nullopt, "a name"); })
                .find("missing required key 'b' (a name)"),
            std::string::npos);
  try {
    (void)coredem::yaml::parse("a: [1, 2\n", "bad.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.yaml:", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("not valid YAML"), std::string::npos);
  }
}

TEST(YamlSection, Vec3) {
  const Section s(coredem::yaml::parse("a: [1, 2, 3]\nb: [1, 2]\n", "v"), "v", "", {"a", "b"},
                  YAML::Mark());
  EXPECT_EQ(s.vec3("a", std::nullopt, "m"), (std::array<double, 3>{1, 2, 3}));
  EXPECT_THROW((void)s.vec3("b", std::nullopt, "m"), ConfigError);
}

} // namespace

// Keys given twice and a second document: YAML readers disagree on which value counts (yaml-cpp's
// lookup takes the first, an iteration the last), so both are refused with the line.
TEST(YamlSection, DuplicateKeysAndASecondDocumentAreRefused) {
  auto error = [](const std::string& text) -> std::string {
    try {
      (void)coredem::yaml::parse(text, "dup.yaml");
    } catch (const coredem::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  auto contains = [](const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
  };
  EXPECT_EQ(error("a: 1\nb: 2\n"), "");
  EXPECT_EQ(error("a: 1\n---\n"), ""); // an empty second document holds nothing to ignore
  EXPECT_EQ(error("a: {x: 1}\nb: {x: 2}\n"), ""); // the same key in two mappings
  EXPECT_EQ(error("a: 1\nb: 2\na: 3\n"),
            "dup.yaml:3:1: a: given twice in the same mapping (first at line 1): YAML readers "
            "disagree on which one counts; keep one");
  EXPECT_TRUE(contains(error("p:\n  - {d: 1, d: 2}\n"), "dup.yaml:2:12: d: given twice"));
  EXPECT_TRUE(
      contains(error("top:\n  inner:\n    k: 1\n    k: 2\n"), "dup.yaml:4:5: k: given twice"));
  EXPECT_EQ(error("a: 1\n---\nb: 2\n"),
            "dup.yaml:3:1: document: a second YAML document (after '---'): the file is read as "
            "one document and the rest would be ignored; remove the '---' separator or the "
            "second document");
}

// A complex key ('? [a, b]' or '? name: x') reaches a reader as a list or mapping where it expects
// a name (found by the sweep fuzz: "internal error: yaml-cpp: bad conversion"); refused at parse.
TEST(YamlSection, AKeyThatIsNotAPlainNameIsRefused) {
  auto error = [](const std::string& text) -> std::string {
    try {
      (void)coredem::yaml::parse(text, "key.yaml");
    } catch (const coredem::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error("? name: fuzz\nbase_case: .\n"),
            "key.yaml:1:3: key: a key must be a plain name, got a mapping (a '? ' complex key); "
            "write 'name: value'");
  EXPECT_EQ(error("a:\n  ? [x, y]\n  : 1\n"),
            "key.yaml:2:5: key: a key must be a plain name, got a list (a '? ' complex key); "
            "write 'name: value'");
  EXPECT_EQ(error("? plain\n: 1\n"), ""); // an explicit key that is a name is a name
}
