// The [[interface]] tables of a case file (coordinator/coupling/case_file_interface.hpp): a case
// of N bodies names its contact interfaces; each body's contact boundaries follow from them.
// Every error names the file, the line and the field.

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "coupling/case_file.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

namespace fs = std::filesystem;

const fs::path data = ROBIN_TEST_DATA;

fs::path write_case(const std::string& text) {
  static std::atomic<int> counter{0};
  const fs::path directory = fs::temp_directory_path() /
                             ("robin_case_interface_test_" + std::to_string(::getpid())) /
                             std::to_string(counter++);
  fs::create_directories(directory);
  const fs::path path = directory / "case.toml";
  std::ofstream(path) << std::regex_replace(text, std::regex("@DATA@"), data.string());
  return path;
}

std::string read_error(const fs::path& path) {
  try {
    static_cast<void>(read_case_file(path));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

std::string body(const std::string& name, const std::string& side) {
  return "[[body]]\nname = \"" + name + "\"\nmesh = \"@DATA@/row_block_" + side +
         ".geo\"\nmodel = \"plane_strain\"\nmaterial = { young = 1000.0, poisson = 0.3 }\n"
         "dirichlet = [{ boundary = \"bottom\", fix = \"both\" }]\n\n";
}

/// Three blocks and their two interfaces (as tests/data/row_of_three.toml).
std::string three_bodies() {
  return body("left", "left") + body("middle", "middle") + body("right", "right") +
         "[[interface]]\nbodies = [\"left\", \"middle\"]\nboundaries = [\"right\", \"left\"]\n\n"
         "[[interface]]\nbodies = [\"middle\", \"right\"]\nboundaries = [\"right\", \"left\"]\n"
         "method = \"node-to-node\"\n";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(CaseFileInterfaces, InterfacesGiveTheBodiesTheirContactBoundaries) {
  const CaseDefinition definition = read_case_file(write_case(three_bodies()));
  ASSERT_EQ(definition.bodies.size(), 3u);
  ASSERT_EQ(definition.interfaces.size(), 2u);
  const InterfaceDefinition& first = definition.interfaces[0].definition;
  EXPECT_EQ(first.body_a, 0);
  EXPECT_EQ(first.body_b, 1);
  EXPECT_EQ(first.boundary_a, "right");
  EXPECT_EQ(first.boundary_b, "left");
  EXPECT_FALSE(first.contact.has_value());  // the case's [contact]
  const InterfaceDefinition& second = definition.interfaces[1].definition;
  EXPECT_EQ(second.body_a, 1);
  EXPECT_EQ(second.body_b, 2);
  ASSERT_TRUE(second.contact.has_value());
  EXPECT_EQ(second.contact->method, ContactMethod::node_to_node);
  // the middle block's boundaries in interface order; the outer blocks one each
  EXPECT_EQ(definition.bodies[1].definition.contact_boundaries,
            (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(definition.bodies[0].definition.contact_boundaries, std::vector<std::string>{"right"});
  EXPECT_EQ(definition.bodies[2].definition.contact_boundaries, std::vector<std::string>{"left"});
  EXPECT_EQ(body_names(definition), (std::vector<std::string>{"left", "middle", "right"}));
}

TEST(CaseFileInterfaces, TwoBodiesWithoutInterfacesHaveOneInterface) {
  const CaseDefinition definition = read_case_file(data / "case_minimal.toml");
  ASSERT_EQ(definition.interfaces.size(), 1u);
  const InterfaceDefinition& only = definition.interfaces[0].definition;
  EXPECT_EQ(only.body_a, 0);
  EXPECT_EQ(only.body_b, 1);
  EXPECT_EQ(only.boundary_a, "contact");
  EXPECT_EQ(only.boundary_b, "contact");
}

TEST(CaseFileInterfaces, ACaseWideNonMortarBodyAppliesOnlyToItsInterfaces) {
  const std::string text = "[contact]\nnon_mortar = \"right\"\n\n" + three_bodies();
  const CaseDefinition definition = read_case_file(write_case(text));
  // interface 1 does not touch 'right': its non-mortar side is chosen automatically
  ASSERT_TRUE(definition.interfaces[0].definition.contact.has_value());
  EXPECT_EQ(definition.interfaces[0].definition.contact->non_mortar, "");
  ASSERT_TRUE(definition.interfaces[1].definition.contact.has_value());
  EXPECT_EQ(definition.interfaces[1].definition.contact->non_mortar, "right");
}

struct InterfaceError {
  std::string name;
  std::string from, to;
  std::vector<std::string> fragments;
};

class CaseFileInterfaceError : public ::testing::TestWithParam<InterfaceError> {};

TEST_P(CaseFileInterfaceError, MessageNamesTheFieldAndTheProblem) {
  const InterfaceError& error = GetParam();
  const std::string message =
      read_error(write_case(replaced(three_bodies(), error.from, error.to)));
  ASSERT_FALSE(message.empty());
  for (const std::string& fragment : error.fragments) {
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected: " << fragment << "\nmessage:  " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllErrors, CaseFileInterfaceError,
    ::testing::Values(
        InterfaceError{"UnknownBody",
                       "bodies = [\"left\", \"middle\"]",
                       "bodies = [\"left\", \"centre\"]",
                       {"case.toml:", "interface[1].bodies: 'centre' is not the name of a body",
                        "'left', 'middle', 'right'"}},
        InterfaceError{"BodyJoinedToItself",
                       "bodies = [\"left\", \"middle\"]",
                       "bodies = [\"left\", \"left\"]",
                       {"interface[1].bodies: joins body 'left' to itself"}},
        InterfaceError{"NotTwoBodies",
                       "bodies = [\"left\", \"middle\"]",
                       "bodies = [\"left\"]",
                       {"interface[1].bodies: expected an array of two strings"}},
        InterfaceError{"MissingBoundaries",
                       "boundaries = [\"right\", \"left\"]\n\n",
                       "\n\n",
                       {"interface[1].boundaries: missing required key"}},
        InterfaceError{"TheSameInterfaceTwice",
                       "bodies = [\"middle\", \"right\"]\nboundaries = [\"right\", \"left\"]",
                       "bodies = [\"middle\", \"left\"]\nboundaries = [\"left\", \"right\"]",
                       {"interface[2]", "the same interface as interface[1]"}},
        InterfaceError{"BodyInNoInterface",
                       "bodies = [\"middle\", \"right\"]",
                       "bodies = [\"middle\", \"left\"]",
                       {"body 'right'", "body[3]: the body is in no [[interface]]"}},
        InterfaceError{"ContactBoundaryBesideInterfaces",
                       "model = \"plane_strain\"",
                       "model = \"plane_strain\"\ncontact_boundary = \"right\"",
                       {"body[1].contact_boundary: the case has [[interface]] tables"}},
        InterfaceError{"NonMortarNotOnTheInterface",
                       "method = \"node-to-node\"",
                       "non_mortar = \"left\"",
                       {"interface[2].non_mortar: 'left' is not one of the interface's bodies"}},
        InterfaceError{
            "UnknownKey",
            "method = \"node-to-node\"",
            "gap = 0.1",
            {"unknown key 'interface[2].gap'", "bodies, boundaries, method, non_mortar"}}),
    [](const ::testing::TestParamInfo<InterfaceError>& info) { return info.param.name; });

TEST(CaseFileInterfaces, MoreThanTwoBodiesWithoutInterfacesSaysWhatIsMissing) {
  const std::string text = body("left", "left") + body("middle", "middle") + body("right", "right");
  const std::string message = read_error(write_case(
      std::regex_replace(text, std::regex("model = "), "contact_boundary = \"left\"\nmodel = ")));
  EXPECT_NE(message.find("expected exactly two [[body]] tables, found 3 (a case of more bodies "
                         "names its contact interfaces in [[interface]] tables)"),
            std::string::npos)
      << message;
}

TEST(CaseFileInterfaces, AnUnknownInterfaceBoundaryIsNamedWhenTheMeshIsRead) {
  CaseDefinition definition = read_case_file(write_case(replaced(
      three_bodies(), "boundaries = [\"right\", \"left\"]", "boundaries = [\"right\", \"side\"]")));
  try {
    load_meshes(definition);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("interface[1].boundaries[2]: boundary 'side' is not a physical curve"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("body 'middle'"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace robin
