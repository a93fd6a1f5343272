// The [reference] table of a case file (coupling/case_file_reference.hpp): every key against its
// literal value, the default contact modulus from the bodies' materials written out by hand,
// the Hertz formulas against numbers computed here, and each input error naming file, line and
// key.

#include "coupling/case_file_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "../test_files.hpp"
#include "coupling/case_file.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

namespace fs = std::filesystem;
using testing::TemporaryDirectory;
using testing::write_text;

/// Two bodies (E = 1000, nu = 0.3 plane strain; E = 2000, nu = 0.25 plane stress) followed by
/// `reference`, meshes by absolute path.
std::string case_text(const std::string& reference) {
  const std::string data = ROBIN_TEST_DATA;
  return "title = \"reference\"\n\n" + reference +
         "\n[[body]]\n"
         "name = \"upper\"\n"
         "mesh = \"" +
         data +
         "/case_upper.geo\"\n"
         "model = \"plane_strain\"\n"
         "contact_boundary = \"contact\"\n"
         "[body.material]\n"
         "young = 1000.0\n"
         "poisson = 0.3\n"
         "[[body.dirichlet]]\n"
         "boundary = \"top\"\n"
         "fix = \"both\"\n\n"
         "[[body]]\n"
         "name = \"lower\"\n"
         "mesh = \"" +
         data +
         "/case_lower.msh\"\n"
         "model = \"plane_stress\"\n"
         "contact_boundary = \"contact\"\n"
         "[body.material]\n"
         "young = 2000\n"
         "poisson = 0.25\n"
         "[[body.dirichlet]]\n"
         "boundary = \"bottom\"\n"
         "fix = \"both\"\n";
}

/// 1-based line of the first line of `text` containing `marker`.
int line_containing(const std::string& text, const std::string& marker) {
  std::istringstream stream(text);
  std::string line;
  for (int number = 1; std::getline(stream, line); ++number) {
    if (line.find(marker) != std::string::npos) return number;
  }
  return 0;
}

class ReferenceTable : public ::testing::Test {
 protected:
  /// Writes the case with `reference` and reads it.
  CaseDefinition read(const std::string& reference) {
    write_text(path(), case_text(reference));
    return read_case_file(path());
  }
  /// The InputError message of reading the case with `reference` ("" when it succeeds).
  std::string error(const std::string& reference) {
    try {
      static_cast<void>(read(reference));
    } catch (const InputError& failure) {
      return failure.what();
    }
    return "";
  }
  /// "FILE:LINE: " of the line containing `marker` in the case with `reference`.
  std::string at(const std::string& reference, const std::string& marker) {
    return path().string() + ":" + std::to_string(line_containing(case_text(reference), marker)) +
           ": ";
  }
  fs::path path() const { return directory_.path() / "case.toml"; }

 private:
  TemporaryDirectory directory_{"case-file-reference"};
};

TEST_F(ReferenceTable, AbsentTableGivesNoReference) {
  EXPECT_FALSE(read("").reference.has_value());
}

TEST_F(ReferenceTable, EveryKeyIsReadAsWritten) {
  const CaseDefinition definition = read(
      "[reference]\nkind = \"hertz_cylinder\"\nload = 100.0\nradius = 10\n"
      "contact_modulus = 1.1e5\ncenter = [0.5, -2]\n");
  ASSERT_TRUE(definition.reference.has_value());
  const ReferenceSolution& reference = *definition.reference;
  EXPECT_EQ(reference.kind, ReferenceKind::hertz_cylinder);
  ASSERT_TRUE(reference.load.has_value());
  EXPECT_EQ(*reference.load, 100.0);
  EXPECT_EQ(reference.radius, 10.0);
  EXPECT_EQ(reference.contact_modulus, 1.1e5);
  EXPECT_TRUE(reference.contact_modulus_given);
  ASSERT_TRUE(reference.center.has_value());
  EXPECT_EQ(reference.center->x(), 0.5);
  EXPECT_EQ(reference.center->y(), -2.0);
  EXPECT_EQ(reference.location, path().string() + ":3");
}

TEST_F(ReferenceTable, DefaultContactModulusComesFromBothMaterials) {
  const CaseDefinition definition = read("[reference]\nkind = \"hertz_cylinder\"\nradius = 1\n");
  ASSERT_TRUE(definition.reference.has_value());
  EXPECT_FALSE(definition.reference->load.has_value());
  EXPECT_FALSE(definition.reference->center.has_value());
  EXPECT_FALSE(definition.reference->contact_modulus_given);
  // Plane strain E' = 1000 / (1 - 0.09) = 1098.901...; plane stress E' = 2000.
  // E* = 1 / (0.00091 + 0.0005) = 709.2198581560284.
  EXPECT_NEAR(definition.reference->contact_modulus, 709.2198581560284, 1e-10);
}

TEST_F(ReferenceTable, HertzHalfWidthAndPeakPressure) {
  ReferenceSolution reference;
  reference.radius = 10.0;
  reference.contact_modulus = 1.1e5;
  // a = sqrt(4 * 100 * 10 / (pi * 1.1e5)) = sqrt(4000 / 345575.19...) = 0.10758...
  const double half_width = std::sqrt(4000.0 / (std::numbers::pi * 1.1e5));
  EXPECT_NEAR(hertz_half_width(reference, 100.0), 0.107587, 1e-6);
  EXPECT_NEAR(hertz_half_width(reference, 100.0), half_width, 1e-15);
  // p0 = 2 * 100 / (pi a) = 200 / 0.3379918... = 591.727...
  EXPECT_NEAR(hertz_peak_pressure(reference, 100.0), 200.0 / (std::numbers::pi * half_width),
              1e-10);
  EXPECT_NEAR(hertz_peak_pressure(reference, 100.0), 591.727, 1e-3);
}

TEST_F(ReferenceTable, BadValueNamesFileLineAndKey) {
  const std::string reference =
      "[reference]\nkind = \"hertz_cylinder\"\nload = 100.0\nradius = -10.0\n";
  EXPECT_EQ(error(reference), at(reference, "radius =") + "reference.radius: must be > 0, got -10");
}

TEST_F(ReferenceTable, NonPositiveLoadAndModulusAreErrors) {
  const std::string load = "[reference]\nkind = \"hertz_cylinder\"\nradius = 1\nload = 0\n";
  EXPECT_EQ(error(load), at(load, "load =") + "reference.load: must be > 0, got 0");
  const std::string modulus =
      "[reference]\nkind = \"hertz_cylinder\"\nradius = 1\ncontact_modulus = -5\n";
  EXPECT_EQ(error(modulus),
            at(modulus, "contact_modulus =") + "reference.contact_modulus: must be > 0, got -5");
}

TEST_F(ReferenceTable, UnknownKindKeyAndMissingKeysAreErrors) {
  const std::string kind = "[reference]\nkind = \"hertz_cone\"\nradius = 1\n";
  EXPECT_EQ(error(kind), at(kind, "kind =") +
                             "reference.kind: 'hertz_cone' is not one of: hertz_cylinder, "
                             "hertz_sphere");
  const std::string sphere = "[reference]\nkind = \"hertz_sphere\"\nradius = 1\n";
  EXPECT_EQ(error(sphere), at(sphere, "kind =") +
                               "reference.kind: \"hertz_sphere\" is the reference of solid "
                               "bodies; a case with dimension = 2 takes \"hertz_cylinder\"");
  const std::string unknown = "[reference]\nkind = \"hertz_cylinder\"\nradius = 1\nradios = 2\n";
  EXPECT_NE(error(unknown).find(at(unknown, "radios =") + "unknown key 'reference.radios'"),
            std::string::npos)
      << error(unknown);
  const std::string no_radius = "[reference]\nkind = \"hertz_cylinder\"\n";
  EXPECT_EQ(error(no_radius),
            at(no_radius, "[reference]") + "reference.radius: missing required key");
  const std::string no_kind = "[reference]\nradius = 1\n";
  EXPECT_NE(error(no_kind).find(at(no_kind, "[reference]") + "reference.kind: missing"),
            std::string::npos)
      << error(no_kind);
  const std::string center = "[reference]\nkind = \"hertz_cylinder\"\nradius = 1\ncenter = [1]\n";
  EXPECT_EQ(error(center),
            at(center, "center =") + "reference.center: expected an array of two numbers [x, y]");
}

TEST_F(ReferenceTable, VoigtMaterialNeedsAnExplicitContactModulus) {
  const std::string reference = "[reference]\nkind = \"hertz_cylinder\"\nradius = 1\n";
  std::string text = case_text(reference);
  const std::string isotropic = "young = 2000\npoisson = 0.25\n";
  text.replace(text.find(isotropic), isotropic.size(),
               "voigt = [[2000, 500, 0], [500, 2000, 0], [0, 0, 750]]\n");
  write_text(path(), text);
  std::string message;
  try {
    static_cast<void>(read_case_file(path()));
  } catch (const InputError& failure) {
    message = failure.what();
  }
  EXPECT_NE(message.find(path().string() + ":3: reference.contact_modulus: missing: body[2] has "
                                           "no isotropic material"),
            std::string::npos)
      << message;
  text.replace(text.find("radius = 1\n"), 11, "radius = 1\ncontact_modulus = 800\n");
  write_text(path(), text);
  EXPECT_EQ(read_case_file(path()).reference->contact_modulus, 800.0);
}

TEST(ReferenceExamples, ShippedHertzCasesCarryTheirReference) {
  for (const char* name : {"hertz.toml", "hertz_cylinder.toml"}) {
    const CaseDefinition definition = read_case_file(fs::path(ROBIN_EXAMPLES) / name);
    ASSERT_TRUE(definition.reference.has_value()) << name;
    EXPECT_EQ(definition.reference->radius, 1.0) << name;
    EXPECT_FALSE(definition.reference->load.has_value()) << name;  // displacement-driven
    // Both bodies E = 1000, nu = 0.3, plane strain: E* = 1000 / (2 * 0.91) = 549.4505494505495.
    EXPECT_NEAR(definition.reference->contact_modulus, 549.4505494505495, 1e-10) << name;
  }
}

}  // namespace
}  // namespace robin
