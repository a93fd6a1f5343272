// Contact boundaries that cannot be coupled by mortar, through the real tools: an upper block
// moved away from the lower one (its contact edge faces nothing), and an upper block whose
// "contact" edge is its top (its outward normal points the same way as the lower block's). Each
// is a clear error naming the case file and both bodies, exit status 1, for robin-monolithic and
// robin-run alike; never a run that converges to a wrong answer. The same for node-to-node
// pairing of matching contact edges whose outward normals point the same way.

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <regex>
#include <string>
#include <vector>

#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::TemporaryDirectory;

/// A copy of examples/non_matching_blocks.toml in `directory` whose upper block is the .geo
/// `upper_geo` (written there) with absolute paths to the shipped lower mesh.
std::filesystem::path write_case(const std::filesystem::path& directory,
                                 const std::string& upper_geo) {
  std::ifstream original(example("non_matching_blocks.toml"));
  std::string text((std::istreambuf_iterator<char>(original)), std::istreambuf_iterator<char>());
  const std::string meshes = (example("meshes")).string();
  text =
      std::regex_replace(text, std::regex("meshes/patch_lower.geo"), meshes + "/patch_lower.geo");
  text = std::regex_replace(text, std::regex("meshes/patch_upper.geo"),
                            (directory / "upper.geo").string());
  std::ofstream(directory / "upper.geo") << upper_geo;
  const std::filesystem::path case_file = directory / "case.toml";
  std::ofstream(case_file) << text;
  return case_file;
}

/// A rectangle [x0, x0 + 1] x [y0, y0 + 0.4] with physical curves contact (the edge named by
/// `contact_edge`: 1 bottom, 3 top), left, right and top (the other of bottom/top).
std::string rectangle_geo(double x0, double y0, int contact_edge) {
  std::ostringstream geo;
  geo << "h = 0.1;\n"
      << "Point(1) = {" << x0 << ", " << y0 << ", 0, h};\n"
      << "Point(2) = {" << x0 + 1 << ", " << y0 << ", 0, h};\n"
      << "Point(3) = {" << x0 + 1 << ", " << y0 + 0.4 << ", 0, h};\n"
      << "Point(4) = {" << x0 << ", " << y0 + 0.4 << ", 0, h};\n"
      << "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
      << "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
      << "Physical Curve(\"contact\") = {" << contact_edge << "};\n"
      << "Physical Curve(\"top\") = {" << (contact_edge == 1 ? 3 : 1) << "};\n"
      << "Physical Curve(\"left\") = {4}; Physical Curve(\"right\") = {2};\n"
      << "Physical Surface(\"block\") = {1};\n";
  return geo.str();
}

/// robin-monolithic and robin-run on the case `write` makes in a fresh directory, with
/// `arguments` added, exit with status 1 saying the two bodies do not face each other for
/// `reason`, and name the case file.
void expect_not_facing(
    const std::function<std::filesystem::path(const std::filesystem::path&)>& write,
    const std::vector<std::string>& arguments, const std::string& reason) {
  for (const std::string tool : {"robin-monolithic", "robin-run"}) {
    const TemporaryDirectory directory("mortar-bad-input");
    const std::filesystem::path case_file = write(directory.path());
    std::vector<std::string> command = {case_file.string(), "--output",
                                        (directory.path() / "out").string()};
    command.insert(command.end(), arguments.begin(), arguments.end());
    const testing::ProcessOutcome outcome =
        testing::run_tool(tool, command, directory.path(), 120.0);
    EXPECT_EQ(outcome.exit, "exited with status 1") << tool << ": " << outcome.errors;
    const std::string expected =
        "the contact boundaries of bodies 'lower' and 'upper' do not face each other: " + reason;
    EXPECT_NE(outcome.errors.find(expected), std::string::npos) << tool << ": " << outcome.errors;
    EXPECT_NE(outcome.errors.find(case_file.string()), std::string::npos)
        << tool << ": the message names the case file: " << outcome.errors;
  }
}

void expect_refused(const std::string& upper_geo, const std::string& reason) {
  expect_not_facing(
      [&upper_geo](const std::filesystem::path& directory) {
        return write_case(directory, upper_geo);
      },
      {}, reason);
}

TEST(MortarBadInput, ContactBoundariesFarApartAreAnErrorNamingBothBodies) {
  expect_refused(rectangle_geo(5.0, 0.0, 1), "no point of one projects onto the other");
}

TEST(MortarBadInput, ContactBoundariesWhoseNormalsPointTheSameWayAreAnError) {
  // The upper block's "contact" curve is its top edge at y = 0.4: outward +y, like the lower one's.
  expect_refused(rectangle_geo(0.0, 0.0, 3), "their outward normals point the same way");
}

TEST(MortarBadInput, NodeToNodePairsWhoseNormalsPointTheSameWayAreAnError) {
  // examples/two_blocks.toml with the upper body meshed like the lower one: the same nodes on
  // the contact edge y = 0 (so node-to-node pairs them all), but both outward normals are +y.
  const auto copy_two_blocks = [](const std::filesystem::path& directory) {
    std::ifstream original(example("two_blocks.toml"));
    std::string text((std::istreambuf_iterator<char>(original)), std::istreambuf_iterator<char>());
    text = std::regex_replace(text, std::regex("meshes/"), example("meshes").string() + "/");
    std::ofstream(directory / "case.toml") << text;
    return directory / "case.toml";
  };
  expect_not_facing(
      copy_two_blocks,
      {"--set", "body[2].mesh=\"" + example("meshes/block_lower.geo").string() + "\"", "--set",
       "body[2].dirichlet[1].boundary=\"bottom\"", "--set", "contact.method=\"node-to-node\""},
      "their outward normals point the same way (body 'lower' contact node (tag ");
}

}  // namespace
}  // namespace robin
