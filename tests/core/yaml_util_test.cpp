// The shared YAML loader (src/core/yaml_util.hpp) refuses a key repeated in
// one mapping, at any depth and in any style, naming both lines; the same key
// in different mappings, and values that look like keys, are not repeats.
#include "core/yaml_util.hpp"

#include <gtest/gtest.h>

#include <string>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace {

using touchdown::detail::load_yaml;

std::string load_error(const std::string& yaml) { return touchdown::test::parse_error_of(load_yaml, yaml, "cfg.yaml"); }

TEST(YamlDuplicateKeys, TopLevelKeyNamesBothLines) {
  EXPECT_EQ(load_error("a: 1\nb: 2\na: 3\n"), "cfg.yaml:3: a: duplicate key (first at line 1)");
}

TEST(YamlDuplicateKeys, NestedMapNamesThePath) {
  EXPECT_EQ(load_error("limits:\n  v_max: 1\n  a_max: 2\n  v_max: 3\n"),
            "cfg.yaml:4: limits.v_max: duplicate key (first at line 2)");
  EXPECT_EQ(load_error("a:\n  b:\n    c: 1\n    d: 2\n    c: 3\n"),
            "cfg.yaml:5: a.b.c: duplicate key (first at line 3)");
}

TEST(YamlDuplicateKeys, KeyRepeatedAfterACollectionValue) {
  EXPECT_EQ(load_error("a: {b: 1}\nc: [1, 2]\na:\n  - x\n"), "cfg.yaml:3: a: duplicate key (first at line 1)");
}

TEST(YamlDuplicateKeys, MapInsideASequence) {
  EXPECT_EQ(load_error("objs:\n  - {x: 1}\n  - x: 1\n    y: 2\n    x: 3\n"),
            "cfg.yaml:5: objs[1].x: duplicate key (first at line 3)");
  EXPECT_EQ(load_error("- [1, {k: 1, k: 2}]\n"), "cfg.yaml:1: [0][1].k: duplicate key (first at line 1)");
}

TEST(YamlDuplicateKeys, FlowMapAndJson) {
  EXPECT_EQ(load_error("{a: 1, b: 2, a: 3}"), "cfg.yaml:1: a: duplicate key (first at line 1)");
  EXPECT_EQ(load_error("{\n  \"m\": {\"a\": 1,\n    \"a\": 2}\n}\n"),
            "cfg.yaml:3: m.a: duplicate key (first at line 2)");
}

TEST(YamlDuplicateKeys, QuotedAndPlainKeyAreTheSameKey) {
  EXPECT_EQ(load_error("a: 1\n'a': 2\n"), "cfg.yaml:2: a: duplicate key (first at line 1)");
}

TEST(YamlDuplicateKeys, SameKeyInDifferentMapsIsNoRepeat) {
  const YAML::Node root = load_yaml(
      "a: {x: 1}\nb: {x: 2}\nc: [{x: 1}, {x: 2}]\n"
      "x: {x: {x: 1}}\n"
      "d: &d {x: 1}\ne: *d\n"
      "f: f\ng: f\nh: [f, f]\n",
      "cfg.yaml");
  EXPECT_EQ(root.size(), 9U);
  EXPECT_EQ(root["x"]["x"]["x"].as<int>(), 1);
  EXPECT_EQ(root["e"]["x"].as<int>(), 1);
}

TEST(YamlDuplicateKeys, NestedAliasesAreNotExpanded) {
  // Nine levels of ten aliases each: 10^9 nodes if expanded.
  std::string yaml = "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 9; ++i) {
    const std::string prev = "*l" + std::to_string(i - 1);
    yaml += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) yaml += (k ? ", " : "") + prev;
    yaml += "]\n";
  }
  EXPECT_EQ(load_yaml(yaml, "cfg.yaml").size(), 10U);
  EXPECT_EQ(load_error(yaml + "l3: 1\n"), "cfg.yaml:11: l3: duplicate key (first at line 4)");
}

TEST(YamlDuplicateKeys, SyntaxErrorsStayInvalidYaml) {
  EXPECT_EQ(load_error("a: [1, 2\n").rfind("cfg.yaml:", 0), 0U);
  EXPECT_NE(load_error("a: [1, 2\n").find("invalid YAML"), std::string::npos);
}

}  // namespace
