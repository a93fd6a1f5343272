// mesh_size on a .geo that never uses h (issue 17, silent traps):
//  - geo_variable_use reads the script's text: h used in an expression counts; h inside a
//    comment or a string, or as part of a longer name (hx, h_max), does not; a script that
//    includes other files and does not use h here is indeterminate;
//  - a case giving mesh_size for such a script is refused, naming the file, the line of
//    mesh_size, the key and what to do; a script that uses h is accepted.

#include <gtest/gtest.h>

#include "../test_files.hpp"
#include "coupling/case_file.hpp"
#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

using testing::TemporaryDirectory;
using testing::write_text;

GeoVariableUse use_in(const std::string& script) {
  static const TemporaryDirectory directory("geo-variable");
  const std::filesystem::path path = directory.path() / "script.geo";
  write_text(path, script);
  return geo_variable_use(path, "h");
}

TEST(GeoVariableUse, CountsOnlyTheIdentifierInCode) {
  EXPECT_EQ(use_in("DefineConstant[ h = 0.1 ];\nPoint(1) = {0, 0, 0, h};\n"), GeoVariableUse::used);
  EXPECT_EQ(use_in("Point(1) = {0,0,0,2*h};"), GeoVariableUse::used);
  EXPECT_EQ(use_in("lc = 0.1; // the size h is not used\nPoint(1) = {0, 0, 0, lc};\n"),
            GeoVariableUse::unused);
  EXPECT_EQ(use_in("/* h\n h */ Point(1) = {0, 0, 0, 0.1};"), GeoVariableUse::unused);
  EXPECT_EQ(use_in("Printf(\"h = %g\", 0.1);\nhx = 0.1; h_max = 2; Point(1) = {0, 0, 0, hx};"),
            GeoVariableUse::unused);
  EXPECT_EQ(use_in("Include \"sizes.geo\";\nPoint(1) = {0, 0, 0, lc};"),
            GeoVariableUse::indeterminate);
  EXPECT_THROW(geo_variable_use("/nonexistent/robin/script.geo", "h"), InputError);
}

/// A two-body case whose upper body is `geo` with mesh_size 0.05.
std::filesystem::path case_with_upper_mesh(const std::filesystem::path& directory,
                                           const std::string& geo) {
  write_text(directory / "upper.geo", geo);
  write_text(directory / "lower.geo",
             "DefineConstant[ h = 0.1 ];\nPoint(1) = {0, 0, 0, h};\n");  // never meshed here
  const std::filesystem::path case_file = directory / "case.toml";
  write_text(case_file,
             "[[body]]\n"
             "name = \"upper\"\n"
             "mesh = \"upper.geo\"\n"
             "mesh_size = 0.05\n"
             "model = \"plane_strain\"\n"
             "contact_boundary = \"contact\"\n"
             "material = { young = 1000.0, poisson = 0.25 }\n"
             "dirichlet = [{ boundary = \"top\", fix = \"both\" }]\n"
             "\n"
             "[[body]]\n"
             "name = \"lower\"\n"
             "mesh = \"lower.geo\"\n"
             "model = \"plane_strain\"\n"
             "contact_boundary = \"contact\"\n"
             "material = { young = 1000.0, poisson = 0.25 }\n"
             "dirichlet = [{ boundary = \"bottom\", fix = \"both\" }]\n");
  return case_file;
}

TEST(GeoVariableUse, MeshSizeOnAScriptWithoutHIsRefusedNamingFileLineAndKey) {
  const TemporaryDirectory directory("geo-variable-case");
  const std::filesystem::path case_file =
      case_with_upper_mesh(directory.path(), "lc = 0.1;\nPoint(1) = {0, 0, 0, lc};\n");
  try {
    read_case_file(case_file);
    FAIL() << "mesh_size on a script without h was accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(case_file.string() + ":4:"), std::string::npos) << message;
    EXPECT_NE(message.find("body[1].mesh_size"), std::string::npos) << message;
    EXPECT_NE(message.find("never uses the variable h"), std::string::npos) << message;
  }
  const std::filesystem::path accepted =
      case_with_upper_mesh(directory.path(), "DefineConstant[ h = 0.1 ];\nPoint(1) = {0,0,0,h};\n");
  EXPECT_EQ(read_case_file(accepted).bodies[0].mesh_options.size, 0.05);
}

}  // namespace
}  // namespace robin
