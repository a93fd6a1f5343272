// Command-line overrides of case-file keys (--set KEY=VALUE, coupling/case_file_overrides.hpp):
// values replace or add keys of tests/data/case_minimal.toml before the case is interpreted, so
// every check of the reader applies to them, and the messages name the override.

#include "coupling/case_file_overrides.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "coupling/case_file.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

namespace fs = std::filesystem;

const fs::path minimal_case = fs::path(ROBIN_TEST_DATA) / "case_minimal.toml";

/// The message of the InputError of reading the minimal case with `overrides`.
std::string read_error(const std::vector<std::string>& overrides) {
  try {
    read_case_file(minimal_case, overrides);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

std::string parse_error(const std::string& text) {
  try {
    parse_case_override(text);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError for " << text;
  return "";
}

TEST(CaseOverrides, ReplaceAndAddKeysOfEveryKind) {
  const std::vector<std::string> overrides{
      "coupling.tolerance=1e-10",         // [coupling] is not in the file: created
      "body[2].material.young=2e5",       // a key of an inline table
      "title=\"sweep 1\"",                // a TOML string
      "body[1].body_force=[0.0, -2.5]",   // a key the file does not have
      "solver.interface_operator=dense",  // a bare word is a string
      "solver.linear_solver=multigrid",
      "coupling.per_body=false",
      "solver.qp_max_iterations=77",
      "body[2].dirichlet[1].fix=x"};
  const CaseDefinition definition = read_case_file(minimal_case, overrides);
  EXPECT_EQ(definition.coupling.tolerance, 1e-10);
  // Body 2 has poisson = 0: the shear modulus C33 is E / 2.
  EXPECT_DOUBLE_EQ(definition.bodies[1].definition.material.stiffness(2, 2), 1e5);
  EXPECT_EQ(definition.title, "sweep 1");
  EXPECT_EQ(definition.bodies[0].definition.body_force.x(), 0.0);
  EXPECT_EQ(definition.bodies[0].definition.body_force.y(), -2.5);
  EXPECT_EQ(definition.solver.body.interface_operator, InterfaceOperatorKind::dense);
  EXPECT_EQ(definition.solver.body.linear_solver, LinearSolverKind::multigrid);
  EXPECT_FALSE(definition.coupling.acceleration.per_body);
  EXPECT_EQ(definition.solver.qp.max_iterations, 77);
  ASSERT_EQ(definition.bodies[1].definition.dirichlet.size(), 1u);
  EXPECT_EQ(definition.bodies[1].definition.dirichlet[0].x, 0.0);
  EXPECT_FALSE(definition.bodies[1].definition.dirichlet[0].y.has_value());
  EXPECT_EQ(definition.overrides, overrides);
  // Unchanged keys keep the file's values: E = 1000, nu = 0.25 give C33 = E / (2 (1 + nu)).
  EXPECT_DOUBLE_EQ(definition.bodies[0].definition.material.stiffness(2, 2), 400.0);
}

TEST(CaseOverrides, AppliedInOrderAndIntoArrayElements) {
  const CaseDefinition definition =
      read_case_file(minimal_case, {"body[1].body_force=[1.0, 2.0]", "body[1].body_force[2]=-3",
                                    "coupling.max_iterations=5", "coupling.max_iterations=9"});
  EXPECT_EQ(definition.bodies[0].definition.body_force.x(), 1.0);
  EXPECT_EQ(definition.bodies[0].definition.body_force.y(), -3.0);
  EXPECT_EQ(definition.coupling.max_iterations, 9);
}

TEST(CaseOverrides, StringsKeepQuotesAndBackslashes) {
  const CaseDefinition definition = read_case_file(minimal_case, {R"(title=it's "a" \ b)"});
  EXPECT_EQ(definition.title, R"(it's "a" \ b)");
}

TEST(CaseOverrides, MeshPathsAreRelativeToTheCaseFile) {
  const CaseDefinition definition = read_case_file(minimal_case, {"body[1].mesh=case_lower.geo"});
  EXPECT_EQ(definition.bodies[0].mesh_path,
            fs::absolute(fs::path(ROBIN_TEST_DATA) / "case_lower.geo").lexically_normal());
}

TEST(CaseOverrides, WrongTypeAndRangeNameTheOverride) {
  EXPECT_EQ(read_error({"coupling.tolerance=abc"}),
            "--set coupling.tolerance=abc: coupling.tolerance: expected a number, found a string");
  EXPECT_EQ(read_error({"coupling.relaxation=2"}),
            "--set coupling.relaxation=2: coupling.relaxation: must be in (0, 2), got 2");
  EXPECT_EQ(read_error({"coupling.max_iterations=1.5"}),
            "--set coupling.max_iterations=1.5: coupling.max_iterations: expected an integer, "
            "found a floating-point number");
  EXPECT_EQ(read_error({"body[2].model=plane"}),
            "--set body[2].model=plane: body 'lower': body[2].model: 'plane' is not one of: "
            "plane_strain, plane_stress");
}

TEST(CaseOverrides, UnknownKeysAreRefusedAsInTheFile) {
  EXPECT_EQ(
      read_error({"coupling.tolerence=1e-9"})
          .rfind(
              "--set coupling.tolerence=1e-9: unknown key 'coupling.tolerence' (expected one of: "
              "relaxation, tolerance,",
              0),
      0u);
  EXPECT_EQ(read_error({"body[1].material.youngs=5"}),
            "--set body[1].material.youngs=5: body 'upper': unknown key "
            "'body[1].material.youngs' (expected one of: young, poisson, voigt)");
  EXPECT_EQ(read_error({"colour=1"}).rfind("--set colour=1: unknown key 'colour'", 0), 0u);
}

TEST(CaseOverrides, IndicesMustNameExistingElements) {
  EXPECT_EQ(read_error({"body[3].name=third"}),
            "--set body[3].name=third: body[3]: the case file has 2 element(s) in body (an "
            "override changes an element, it does not add one)");
  EXPECT_EQ(read_error({"body[1].dirichlet[1].x=0"}),
            "--set body[1].dirichlet[1].x=0: the case file has no body[1].dirichlet (an override "
            "changes an element of an array, it does not add one)");
  EXPECT_EQ(read_error({"body[1].name.first=1"}),
            "--set body[1].name.first=1: body[1].name is string, not a table");
  // A key the file does not have becomes a table on the way.
  EXPECT_EQ(read_error({"title.text=1"}),
            "--set title.text=1: title: expected a string, found a table");
  EXPECT_EQ(read_error({"coupling[1]=1"}).rfind("--set coupling[1]=1: the case file has no", 0),
            0u);
}

TEST(CaseOverrides, MissingKeysOfACreatedTableNameTheOverride) {
  EXPECT_EQ(read_error({"gap.constants.R=5"}),
            "--set gap.constants.R=5: gap.expression: missing required key");
  const CaseDefinition definition =
      read_case_file(minimal_case, {"gap.expression=\"x^2 / (2*R)\"", "gap.constants.R=5"});
  ASSERT_TRUE(definition.gap_expression.has_value());
  EXPECT_EQ(*definition.gap_expression, "x^2 / (2*R)");
  EXPECT_EQ(definition.gap_constants.at("R"), 5.0);
}

TEST(CaseOverrides, ErrorsThatNameNoOverrideListThem) {
  // The material is checked as a whole (young and poisson together): the message names the
  // file's table and lists the overrides applied.
  const std::string message =
      read_error({"coupling.tolerance=1e-9", "body[1].material.poisson=0.5"});
  EXPECT_NE(message.find("Poisson"), std::string::npos) << message;
  EXPECT_NE(message.find("(with the overrides --set coupling.tolerance=1e-9, --set "
                         "body[1].material.poisson=0.5)"),
            std::string::npos)
      << message;
}

TEST(CaseOverrides, BoundaryNamesCheckedAgainstTheMeshNameTheOverride) {
  const CaseDefinition definition =
      read_case_file(minimal_case, {"body[2].dirichlet[1].boundary=tops"});
  try {
    load_body(definition.bodies[1]);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what())
                  .rfind("--set body[2].dirichlet[1].boundary=tops: body 'lower': "
                         "body[2].dirichlet[1].boundary: boundary 'tops' is not a physical curve",
                         0),
              0u)
        << error.what();
  }
}

TEST(CaseOverrides, ValuesThatAreNotOneTomlValue) {
  EXPECT_EQ(read_error({"body[1].body_force=[1,"})
                .rfind("--set body[1].body_force=[1,: the value '[1,' is not a TOML value: ", 0),
            0u);
  EXPECT_EQ(
      read_error({"coupling.tolerance=1\ncoupling = 2"}).rfind("--set coupling.tolerance=1", 0),
      0u);
}

TEST(CaseOverrides, MalformedKeyPaths) {
  EXPECT_EQ(parse_error("coupling.tolerance"),
            "--set coupling.tolerance: expected KEY=VALUE, e.g. coupling.tolerance=1e-10");
  for (const std::string text : {"=1", "coupling..tolerance=1", "body[0].name=x", "body[x].name=x",
                                 "body[1.name=x", "coupling.tolerance =1", "a.b.=1"}) {
    EXPECT_EQ(parse_error(text).rfind("--set " + text + ": '", 0), 0u) << parse_error(text);
  }
  const CaseOverride parsed = parse_case_override("body[2].material.voigt[1][3]=0.5=x");
  ASSERT_EQ(parsed.path.size(), 3u);
  EXPECT_EQ(parsed.path[0].key, "body");
  EXPECT_EQ(parsed.path[0].indices, std::vector<int>{2});
  EXPECT_EQ(parsed.path[2].key, "voigt");
  EXPECT_EQ(parsed.path[2].indices, (std::vector<int>{1, 3}));
  EXPECT_EQ(parsed.value, "0.5=x");
}

TEST(CaseOverrides, WithoutOverridesTheFileIsReadAsItIs) {
  const CaseDefinition definition = read_case_file(minimal_case);
  EXPECT_TRUE(definition.overrides.empty());
  // A named default object: GCC 12 at -O3 reports the strings of a temporary CouplingOptions{}
  // as maybe-uninitialized (a false positive) once the tests share a precompiled header.
  const CouplingOptions defaults;
  EXPECT_EQ(definition.coupling.tolerance, defaults.tolerance);
}

}  // namespace
}  // namespace robin
