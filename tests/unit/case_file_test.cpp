// The TOML case format: every key of tests/data/case_full.toml against its literal value,
// the defaults, each input error (file, line, field, body), and load_body's boundary checks.

#include "coupling/case_file.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <atomic>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "coupling/gap_function.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

namespace fs = std::filesystem;

const fs::path data_directory = fs::path(ROBIN_TEST_DATA);

fs::path data(const std::string& name) {
  return data_directory / name;
}

/// The root of this process's scratch directories.
fs::path scratch_root() {
  return fs::temp_directory_path() / ("robin_case_file_test_" + std::to_string(::getpid()));
}

/// Removes the scratch directories when the tests end.
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code error;
    fs::remove_all(scratch_root(), error);
  }
};
[[maybe_unused]] ::testing::Environment* const scratch_cleanup =
    ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

/// A fresh directory for one written case file.
fs::path fresh_directory() {
  static std::atomic<int> counter{0};
  const fs::path directory = scratch_root() / std::to_string(counter++);
  fs::create_directories(directory);
  return directory;
}

fs::path write_case(const std::string& text, const fs::path& directory = fresh_directory()) {
  const fs::path path = directory / "case.toml";
  std::ofstream(path) << text;
  return path;
}

/// 1-based line of the `occurrence`-th line containing `marker`; 0 when absent.
int line_containing(const std::string& text, const std::string& marker, int occurrence = 1) {
  std::istringstream stream(text);
  std::string line;
  for (int number = 1; std::getline(stream, line); ++number) {
    if (line.find(marker) != std::string::npos && --occurrence == 0) return number;
  }
  return 0;
}

/// `text` with the first occurrence of `from` replaced by `to` (which must be present).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the base case";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The InputError message of read_case_file(path), or "" when it succeeds.
std::string read_error(const fs::path& path) {
  try {
    static_cast<void>(read_case_file(path));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

/// A valid two-body case; meshes by absolute path so that the file can live anywhere.
std::string base_case() {
  std::string text = R"toml(title = "base"

[gap]
expression = "x^2 / (2*R)"
constants = { R = 50.0 }

[solver]
qp_tolerance = 1e-12
interface_operator = "auto"

[coupling]
relaxation = 0.5
tolerance = 1e-8
initial_obstacle = "gap"

[[body]]
name = "upper"
mesh = "@DATA@/case_upper.geo"
mesh_size = 0.5
model = "plane_strain"
contact_boundary = "contact"
body_force = [0.0, -1.0]

[body.material]
young = 1000.0
poisson = 0.3

[[body.dirichlet]]
boundary = "top"
x = 0.0
y = -0.01

[[body.traction]]
boundary = "right"
vector = [1.0, 0.0]

[[body]]
name = "lower"
mesh = "@DATA@/case_lower.msh"
model = "plane_strain"
contact_boundary = "contact"

[body.material]
young = 2000.0
poisson = 0.25

[[body.dirichlet]]
boundary = "bottom"
fix = "both"
)toml";
  for (std::size_t at = text.find("@DATA@"); at != std::string::npos; at = text.find("@DATA@")) {
    text.replace(at, 6, data_directory.string());
  }
  return text;
}

/// The text of a file.
std::string file_text(const fs::path& path) {
  std::ifstream stream(path);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

/// Isotropic stiffness in Voigt notation, written out from the textbook formulas.
Eigen::Matrix3d isotropic_stiffness(double young, double nu, PlaneModel model) {
  Eigen::Matrix3d stiffness;
  if (model == PlaneModel::plane_strain) {
    const double factor = young / ((1.0 + nu) * (1.0 - 2.0 * nu));
    stiffness << 1.0 - nu, nu, 0.0, nu, 1.0 - nu, 0.0, 0.0, 0.0, (1.0 - 2.0 * nu) / 2.0;
    return factor * stiffness;
  }
  const double factor = young / (1.0 - nu * nu);
  stiffness << 1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, (1.0 - nu) / 2.0;
  return factor * stiffness;
}

void expect_matrix_near(const Eigen::Matrix3d& actual, const Eigen::Matrix3d& expected) {
  const double scale = expected.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(actual(i, j), expected(i, j), 1e-14 * scale)
          << "entry (" << i << ", " << j << ")";
    }
  }
}

std::string location(const fs::path& file, int line) {
  return file.string() + ":" + std::to_string(line);
}

// ---------------------------------------------------------------------------------------
// Valid files

TEST(CaseFile, FullCaseReadsEveryKey) {
  const fs::path path = data("case_full.toml");
  const std::string text = file_text(path);
  const CaseDefinition definition = read_case_file(path);
  EXPECT_EQ(definition.file, path);
  EXPECT_EQ(definition.title, "two blocks, every key");
  ASSERT_TRUE(definition.gap_expression.has_value());
  EXPECT_EQ(*definition.gap_expression, "x^2 / (2*R) + c*y");
  EXPECT_EQ(definition.gap_constants, (std::map<std::string, double>{{"R", 50.0}, {"c", 0.25}}));
  EXPECT_EQ(definition.gap_context,
            location(path, line_containing(text, "expression =")) + ": gap.expression");

  EXPECT_EQ(definition.solver.qp.relative_tolerance, 1e-10);
  EXPECT_EQ(definition.solver.qp.max_iterations, 12345);
  EXPECT_EQ(definition.solver.body.interface_operator, InterfaceOperatorKind::factor);
  EXPECT_EQ(definition.solver.body.dense_limit, 777);
  EXPECT_EQ(definition.solver.body.linear_solver, LinearSolverKind::multigrid);
  EXPECT_EQ(definition.solver.pairing_tolerance, 2e-5);

  const CouplingOptions& coupling = definition.coupling;
  EXPECT_EQ(coupling.relaxation, 0.75);
  EXPECT_EQ(coupling.tolerance, 1e-7);
  EXPECT_EQ(coupling.max_iterations, 321);
  EXPECT_EQ(coupling.initial_obstacle, InitialObstacle::zero);
  EXPECT_EQ(coupling.request_timeout_seconds, 12.5);
  EXPECT_EQ(coupling.setup_timeout_seconds, 90.5);
  EXPECT_EQ(coupling.divergence_factor, 500.0);
  EXPECT_EQ(coupling.stagnation_window, 17);
}

TEST(CaseFile, FullCaseFirstBody) {
  const fs::path path = data("case_full.toml");
  const std::string text = file_text(path);
  const CaseDefinition definition = read_case_file(path);
  const BodyCase& body = definition.bodies[0];
  const BodyDefinition& upper = body.definition;
  EXPECT_EQ(upper.name, "upper");
  EXPECT_EQ(body.context, path.string() + ": body 'upper'");
  EXPECT_EQ(body.mesh_path, fs::absolute(data("case_upper.geo")).lexically_normal());
  EXPECT_EQ(body.mesh_options.size, 0.25);
  EXPECT_EQ(body.mesh_options.element_order, 2);
  EXPECT_FALSE(body.mesh_options.recombine);
  EXPECT_EQ(upper.material.model, PlaneModel::plane_stress);
  expect_matrix_near(upper.material.stiffness,
                     isotropic_stiffness(210e3, 0.3, PlaneModel::plane_stress));
  EXPECT_EQ(upper.contact_boundaries, std::vector<std::string>{"contact"});
  EXPECT_EQ(upper.body_force, Eigen::Vector3d(0.5, -1.5, 0.0));
  EXPECT_TRUE(upper.mesh.nodes.empty());  // meshes are read by load_body

  ASSERT_EQ(upper.dirichlet.size(), 2u);
  EXPECT_EQ(upper.dirichlet[0].boundary, "top");
  EXPECT_EQ(upper.dirichlet[0].x, 0.0);
  EXPECT_EQ(upper.dirichlet[0].y, -0.01);
  EXPECT_EQ(upper.dirichlet[1].boundary, "left");
  EXPECT_EQ(upper.dirichlet[1].x, 0.0);  // fix = "x"
  EXPECT_EQ(upper.dirichlet[1].y, 0.002);

  ASSERT_EQ(upper.tractions.size(), 2u);
  EXPECT_EQ(upper.tractions[0].boundary, "right");
  EXPECT_FALSE(upper.tractions[0].is_pressure);
  EXPECT_EQ(upper.tractions[0].vector, Eigen::Vector3d(1.0, -2.0, 0.0));
  EXPECT_EQ(upper.tractions[1].boundary, "left");
  EXPECT_TRUE(upper.tractions[1].is_pressure);
  EXPECT_EQ(upper.tractions[1].pressure, 3.5);

  const std::vector<std::pair<std::string, std::string>> expected{
      {"contact", "body[1].contact_boundary"},
      {"top", "body[1].dirichlet[1].boundary"},
      {"left", "body[1].dirichlet[2].boundary"},
      {"right", "body[1].traction[1].boundary"},
      {"left", "body[1].traction[2].boundary"}};
  const std::vector<int> lines{
      line_containing(text, "contact_boundary"), line_containing(text, "boundary = \"top\""),
      line_containing(text, "boundary = \"left\""), line_containing(text, "boundary = \"right\""),
      line_containing(text, "boundary = \"left\"", 2)};
  ASSERT_EQ(body.boundary_references.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(body.boundary_references[i].name, expected[i].first);
    EXPECT_EQ(body.boundary_references[i].field, expected[i].second);
    EXPECT_EQ(body.boundary_references[i].location, location(path, lines[i]));
  }
}

TEST(CaseFile, FullCaseSecondBody) {
  const fs::path path = data("case_full.toml");
  const CaseDefinition definition = read_case_file(path);
  const BodyCase& body = definition.bodies[1];
  const BodyDefinition& lower = body.definition;
  EXPECT_EQ(lower.name, "lower-block_2");
  EXPECT_EQ(body.context, path.string() + ": body 'lower-block_2'");
  EXPECT_EQ(body.mesh_path, fs::absolute(data("case_lower.msh")).lexically_normal());
  EXPECT_EQ(body.mesh_options.size, 0.0);
  EXPECT_EQ(body.mesh_options.element_order, 1);
  EXPECT_FALSE(body.mesh_options.recombine);
  EXPECT_EQ(lower.material.model, PlaneModel::plane_strain);
  Eigen::Matrix3d voigt;
  voigt << 300.0, 100.0, 10.0, 100.0, 200.0, 20.0, 10.0, 20.0, 50.0;
  EXPECT_EQ(lower.material.stiffness, voigt);
  EXPECT_EQ(lower.contact_boundaries, std::vector<std::string>{"contact"});
  EXPECT_EQ(lower.body_force, Eigen::Vector3d::Zero());
  ASSERT_EQ(lower.dirichlet.size(), 1u);
  EXPECT_EQ(lower.dirichlet[0].boundary, "bottom");
  EXPECT_EQ(lower.dirichlet[0].x, 0.0);  // fix = "both"
  EXPECT_EQ(lower.dirichlet[0].y, 0.0);
  EXPECT_TRUE(lower.tractions.empty());
}

TEST(CaseFile, MissingOptionalTablesGiveTheDocumentedDefaults) {
  const fs::path path = data("case_minimal.toml");
  const CaseDefinition definition = read_case_file(path);
  EXPECT_EQ(definition.title, "case_minimal");  // the file's stem
  EXPECT_FALSE(definition.gap_expression.has_value());
  EXPECT_TRUE(definition.gap_constants.empty());
  EXPECT_EQ(definition.solver.qp.relative_tolerance, 1e-12);
  EXPECT_EQ(definition.solver.qp.max_iterations, 20000);
  EXPECT_EQ(definition.solver.body.interface_operator, InterfaceOperatorKind::automatic);
  EXPECT_EQ(definition.solver.body.dense_limit, 8000);
  EXPECT_EQ(definition.solver.body.linear_solver, LinearSolverKind::automatic);
  EXPECT_EQ(definition.solver.pairing_tolerance, 1e-6);
  EXPECT_EQ(definition.coupling.relaxation, 0.5);
  EXPECT_EQ(definition.coupling.tolerance, 1e-8);
  EXPECT_EQ(definition.coupling.max_iterations, 200);
  EXPECT_EQ(definition.coupling.initial_obstacle, InitialObstacle::gap);
  EXPECT_EQ(definition.coupling.request_timeout_seconds, 60.0);
  EXPECT_EQ(definition.coupling.setup_timeout_seconds, 3600.0);
  EXPECT_EQ(definition.coupling.divergence_factor, 1e3);
  EXPECT_EQ(definition.coupling.stagnation_window, 50);

  const BodyCase& upper = definition.bodies[0];
  EXPECT_EQ(upper.mesh_options.size, 0.0);
  EXPECT_EQ(upper.mesh_options.element_order, 1);
  EXPECT_FALSE(upper.mesh_options.recombine);
  EXPECT_EQ(upper.definition.body_force, Eigen::Vector3d::Zero());
  EXPECT_TRUE(upper.definition.dirichlet.empty());
  EXPECT_TRUE(upper.definition.tractions.empty());
  expect_matrix_near(upper.definition.material.stiffness,
                     isotropic_stiffness(1000.0, 0.25, PlaneModel::plane_strain));
  // Integers are accepted where numbers are expected (young = 2000, poisson = 0).
  expect_matrix_near(definition.bodies[1].definition.material.stiffness,
                     isotropic_stiffness(2000.0, 0.0, PlaneModel::plane_strain));
}

TEST(CaseFile, AlgorithmKeys) {
  const std::string text = replaced(base_case(), "relaxation = 0.5",
                                    "relaxation = 0.5\nalgorithm = \"robin-constant\"\nalpha = "
                                    "2.5e-5\ncontact_body = \"2\"\nstopping = \"joint\"");
  const CouplingOptions coupling = read_case_file(write_case(text)).coupling;
  EXPECT_EQ(coupling.algorithm, CouplingAlgorithm::robin_constant);
  EXPECT_EQ(coupling.alpha, 2.5e-5);
  EXPECT_EQ(coupling.contact_body, ContactBodyChoice::second);
  EXPECT_EQ(coupling.stopping, StoppingRule::joint);
  const CouplingOptions defaults = read_case_file(write_case(base_case())).coupling;
  EXPECT_EQ(defaults.algorithm, CouplingAlgorithm::robin);
  EXPECT_EQ(defaults.contact_body, ContactBodyChoice::automatic);
  EXPECT_EQ(defaults.stopping, StoppingRule::either_sequence);
  EXPECT_EQ(defaults.acceleration.method, AccelerationMethod::iqn_ils);
}

TEST(CaseFile, LinearSolverKey) {
  const auto linear_solver = [](const std::string& value) {
    const std::string text = replaced(base_case(), "qp_tolerance = 1e-12",
                                      "qp_tolerance = 1e-12\nlinear_solver = \"" + value + "\"");
    return read_case_file(write_case(text)).solver.body.linear_solver;
  };
  EXPECT_EQ(linear_solver("direct"), LinearSolverKind::direct);
  EXPECT_EQ(linear_solver("multigrid"), LinearSolverKind::multigrid);
  EXPECT_EQ(linear_solver("auto"), LinearSolverKind::automatic);
  EXPECT_EQ(read_case_file(write_case(base_case())).solver.body.linear_solver,
            LinearSolverKind::automatic);
}

/// Every choice converts to the text users write and back; other texts are none of them.
template <typename Choice>
void expect_texts(const std::vector<std::pair<Choice, std::string>>& spellings) {
  std::vector<std::string> texts;
  for (const auto& [choice, text] : spellings) {
    EXPECT_EQ(to_string(choice), text);
    EXPECT_EQ(choice_from_text<Choice>(text), choice) << text;
    texts.push_back(text);
  }
  EXPECT_EQ(choice_texts<Choice>(), texts);
  EXPECT_FALSE(choice_from_text<Choice>("").has_value());
  EXPECT_FALSE(choice_from_text<Choice>("Robin").has_value());
}

TEST(CaseFile, OptionChoicesKeepTheirTexts) {
  expect_texts<CouplingAlgorithm>({{CouplingAlgorithm::robin, "robin"},
                                   {CouplingAlgorithm::robin_constant, "robin-constant"},
                                   {CouplingAlgorithm::dirichlet_neumann, "dirichlet-neumann"},
                                   {CouplingAlgorithm::neumann_neumann, "neumann-neumann"}});
  expect_texts<ContactBodyChoice>({{ContactBodyChoice::first, "1"},
                                   {ContactBodyChoice::second, "2"},
                                   {ContactBodyChoice::automatic, "auto"}});
  expect_texts<StoppingRule>(
      {{StoppingRule::either_sequence, "either-sequence"}, {StoppingRule::joint, "joint"}});
  expect_texts<InitialObstacle>({{InitialObstacle::gap, "gap"}, {InitialObstacle::zero, "zero"}});
  expect_texts<AccelerationMethod>({{AccelerationMethod::none, "none"},
                                    {AccelerationMethod::aitken, "aitken"},
                                    {AccelerationMethod::iqn_ils, "iqn-ils"}});
  expect_texts<QuasiNewtonMixing>({{QuasiNewtonMixing::full, "full"},
                                   {QuasiNewtonMixing::relaxation, "relaxation"},
                                   {QuasiNewtonMixing::aitken, "aitken"}});
}

TEST(CaseFile, GeoOptionsAndFixComponents) {
  std::string text =
      replaced(base_case(), "mesh_size = 0.5", "recombine = true\nelement_order = 1");
  text = replaced(text, "x = 0.0\ny = -0.01", "fix = \"y\"\nx = 0.125");
  const CaseDefinition definition = read_case_file(write_case(text));
  EXPECT_TRUE(definition.bodies[0].mesh_options.recombine);
  EXPECT_EQ(definition.bodies[0].mesh_options.element_order, 1);
  EXPECT_EQ(definition.bodies[0].mesh_options.size, 0.0);
  EXPECT_EQ(definition.bodies[0].definition.dirichlet[0].x, 0.125);
  EXPECT_EQ(definition.bodies[0].definition.dirichlet[0].y, 0.0);
}

TEST(CaseFile, RelativeMeshPathsAreResolvedAgainstTheCaseFile) {
  const fs::path directory = fresh_directory();
  fs::create_directories(directory / "meshes");
  fs::copy_file(data("case_upper.geo"), directory / "meshes" / "upper.geo");
  std::string text =
      replaced(base_case(), (data_directory / "case_upper.geo").string(), "meshes/upper.geo");
  text = replaced(text, (data_directory / "case_lower.msh").string(), "meshes/../lower.msh");
  const fs::path path = write_case(text, directory);
  // lower.msh is not there yet: the message gives the resolved, normalised path.
  const std::string message = read_error(path);
  EXPECT_NE(message.find("'" + (fs::absolute(directory) / "lower.msh").string() + "'"),
            std::string::npos)
      << message;
  fs::copy_file(data("case_lower.msh"), directory / "lower.msh");
  const CaseDefinition definition = read_case_file(path);
  EXPECT_EQ(definition.bodies[0].mesh_path, fs::absolute(directory / "meshes" / "upper.geo"));
  EXPECT_EQ(definition.bodies[1].mesh_path, fs::absolute(directory / "lower.msh"));
}

TEST(CaseFile, ShippedExamplesAreValid) {
  const fs::path examples(ROBIN_EXAMPLES);
  int count = 0;
  for (const auto& entry : fs::directory_iterator(examples)) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    ++count;
    const CaseDefinition definition = read_case_file(entry.path());
    EXPECT_NE(definition.bodies[0].definition.name, definition.bodies[1].definition.name);
    for (const BodyCase& body : definition.bodies) EXPECT_TRUE(fs::exists(body.mesh_path));
  }
  EXPECT_GT(count, 0) << "no example case in " << examples;
}

// ---------------------------------------------------------------------------------------
// Errors of read_case_file: one edit of the base case each

struct ErrorCase {
  std::string name;
  std::string from;                    // replaced in the base case ...
  std::string to;                      // ... by this
  std::string line_marker;             // the error is on the line containing this (empty: no line)
  int occurrence;                      // which occurrence of line_marker
  std::vector<std::string> fragments;  // the message contains each; "{line}" is the line
};

std::vector<ErrorCase> error_cases() {
  const std::string lower_mesh = "mesh = \"" + (data_directory / "case_lower.msh").string() + "\"";
  const std::string missing_mesh = (data_directory / "case_missing.msh").string();
  const std::string voigt = "voigt = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]";
  return {
      // Unknown keys, with the full key path and the allowed keys.
      {"UnknownMaterialKey",
       "young = 1000.0",
       "youngs = 1000.0",
       "youngs",
       1,
       {"case.toml:{line}: body 'upper': unknown key 'body[1].material.youngs' (expected one "
        "of: young, poisson, voigt)"}},
      {"UnknownTopLevelKey",
       "title = ",
       "titel = ",
       "titel",
       1,
       {"case.toml:{line}: unknown key 'titel' (expected one of: title, dimension, gap, solver, "
        "coupling, contact, body, loading, reference, interface)"}},
      {"UnknownSolverKey",
       "interface_operator",
       "interface_operators",
       "interface_operators",
       1,
       {"case.toml:{line}: unknown key 'solver.interface_operators'"}},
      {"UnknownCouplingKey",
       "relaxation = 0.5",
       "relax = 0.5",
       "relax",
       1,
       {"case.toml:{line}: unknown key 'coupling.relax'"}},
      {"UnknownGapKey",
       "constants = ",
       "constant = ",
       "constant =",
       1,
       {"case.toml:{line}: unknown key 'gap.constant'"}},
      {"UnknownBodyKey",
       "body_force",
       "bodyforce",
       "bodyforce",
       1,
       {"case.toml:{line}: body 'upper': unknown key 'body[1].bodyforce'"}},
      {"UnknownDirichletKey",
       "fix = \"both\"",
       "fixed = \"both\"",
       "fixed",
       1,
       {"case.toml:{line}: body 'lower': unknown key 'body[2].dirichlet[1].fixed' (expected "
        "one of: boundary, x, y, z, fix)"}},
      {"UnknownTractionKey",
       "vector = ",
       "vectr = ",
       "vectr",
       1,
       {"case.toml:{line}: body 'upper': unknown key 'body[1].traction[1].vectr'"}},
      // Wrong types.
      {"StringForNumber",
       "young = 1000.0",
       "young = \"1000\"",
       "young",
       1,
       {"case.toml:{line}: body 'upper': body[1].material.young: expected a number, found a "
        "string"}},
      {"FloatForInteger",
       "qp_tolerance = 1e-12",
       "qp_tolerance = 1e-12\nqp_max_iterations = 1.5",
       "qp_max_iterations",
       1,
       {"case.toml:{line}: solver.qp_max_iterations: expected an integer"}},
      {"NumberForBoolean",
       "mesh_size = 0.5",
       "mesh_size = 0.5\nrecombine = 1",
       "recombine",
       1,
       {"case.toml:{line}: body 'upper': body[1].recombine: expected true or false"}},
      {"NumberForString",
       "name = \"lower\"",
       "name = 7",
       "name = 7",
       1,
       {"case.toml:{line}: body[2].name: expected a string, found an integer"}},
      {"BodyForceOfThreeNumbers",
       "[0.0, -1.0]",
       "[0.0, -1.0, 2.0]",
       "body_force",
       1,
       {"case.toml:{line}: body 'upper': body[1].body_force: expected an array of two numbers"}},
      {"NumberForTable",
       "[body.material]\nyoung = 2000.0\npoisson = 0.25",
       "material = 3",
       "material = 3",
       1,
       {"case.toml:{line}: body 'lower': body[2].material: expected a table, found an integer"}},
      // Missing required keys: reported at the table.
      {"MissingContactBoundary",
       "contact_boundary = \"contact\"\nbody_force",
       "body_force",
       "[[body]]",
       1,
       {"case.toml:{line}: body 'upper': body[1].contact_boundary: missing required key"}},
      {"MissingMesh",
       lower_mesh + "\n",
       "",
       "[[body]]",
       2,
       {"case.toml:{line}: body 'lower': body[2].mesh: missing required key"}},
      {"MissingModel",
       "model = \"plane_strain\"\ncontact_boundary = \"contact\"\n\n",
       "contact_boundary = \"contact\"\n\n",
       "[[body]]",
       2,
       {"case.toml:{line}: body 'lower': body[2].model: missing required key"}},
      {"MissingMaterial",
       "[body.material]\nyoung = 2000.0\npoisson = 0.25\n",
       "",
       "[[body]]",
       2,
       {"case.toml:{line}: body 'lower': body[2].material: missing required table"}},
      {"MissingGapExpression",
       "expression = \"x^2 / (2*R)\"\n",
       "",
       "[gap]",
       1,
       {"case.toml:{line}: gap.expression: missing required key"}},
      {"MissingDirichletBoundary",
       "boundary = \"bottom\"\n",
       "",
       "[[body.dirichlet]]",
       2,
       {"case.toml:{line}: body 'lower': body[2].dirichlet[1].boundary: missing required key"}},
      // Materials.
      {"IsotropicAndVoigt",
       "poisson = 0.25",
       "poisson = 0.25\n" + voigt,
       "young = 2000.0",
       1,
       {"case.toml:{line}: body 'lower': body[2].material.young: give either young and "
        "poisson, or voigt, not both"}},
      {"NeitherIsotropicNorVoigt",
       "young = 1000.0\npoisson = 0.3\n",
       "",
       "[body.material]",
       1,
       {"case.toml:{line}: body 'upper': body[1].material: give either young and poisson"}},
      {"YoungWithoutPoisson",
       "poisson = 0.3\n",
       "",
       "[body.material]",
       1,
       {"case.toml:{line}: body 'upper': body[1].material.poisson: missing"}},
      {"PoissonWithoutYoung",
       "young = 2000.0\n",
       "",
       "[body.material]",
       2,
       {"case.toml:{line}: body 'lower': body[2].material.young: missing"}},
      {"PoissonTooLarge",
       "poisson = 0.3",
       "poisson = 0.7",
       "[body.material]",
       1,
       {"case.toml:{line}: body 'upper': material", "0.7"}},
      {"NegativeYoung",
       "young = 2000.0",
       "young = -2000.0",
       "[body.material]",
       2,
       {"case.toml:{line}: body 'lower': material", "-2000"}},
      {"VoigtNotPositiveDefinite",
       "young = 2000.0\npoisson = 0.25",
       "voigt = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
       "[body.material]",
       2,
       {"case.toml:{line}: body 'lower': material"}},
      {"VoigtNotSymmetric",
       "young = 2000.0\npoisson = 0.25",
       "voigt = [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
       "[body.material]",
       2,
       {"case.toml:{line}: body 'lower': material"}},
      {"VoigtNotThreeByThree",
       "young = 2000.0\npoisson = 0.25",
       "voigt = [[1.0, 0.0], [0.0, 1.0]]",
       "voigt",
       1,
       {"case.toml:{line}: body 'lower': body[2].material.voigt: expected three rows of three "
        "numbers"}},
      // Boundary conditions.
      {"VectorAndPressure",
       "vector = [1.0, 0.0]",
       "vector = [1.0, 0.0]\npressure = 2.0",
       "pressure",
       1,
       {"case.toml:{line}: body 'upper': body[1].traction[1].pressure: give either vector or "
        "pressure, not both"}},
      {"NeitherVectorNorPressure",
       "vector = [1.0, 0.0]\n",
       "",
       "[[body.traction]]",
       1,
       {"case.toml:{line}: body 'upper': body[1].traction[1]: give either vector"}},
      {"DirichletPrescribesNothing",
       "x = 0.0\ny = -0.01\n",
       "",
       "[[body.dirichlet]]",
       1,
       {"case.toml:{line}: body 'upper': body[1].dirichlet[1]: prescribes nothing"}},
      {"FixBothAndY",
       "fix = \"both\"",
       "fix = \"both\"\ny = 0.5",
       "fix",
       1,
       {"case.toml:{line}: body 'lower': body[2].dirichlet[1].fix: ",
        "cannot be combined with y = 0.5"}},
      {"FixXAndX",
       "boundary = \"top\"",
       "boundary = \"top\"\nfix = \"x\"",
       "fix",
       1,
       {"case.toml:{line}: body 'upper': body[1].dirichlet[1].fix: ",
        "cannot be combined with x = 0"}},
      {"UnknownFixValue",
       "fix = \"both\"",
       "fix = \"z\"",
       "fix",
       1,
       {"case.toml:{line}: body 'lower': body[2].dirichlet[1].fix: 'z' is not one of: both, x, "
        "y"}},
      {"EmptyBoundaryName",
       "boundary = \"right\"",
       "boundary = \"\"",
       "boundary = \"\"",
       1,
       {"case.toml:{line}: body 'upper': body[1].traction[1].boundary: the boundary name is "
        "empty"}},
      // Non-finite numbers.
      {"NanDisplacement",
       "y = -0.01",
       "y = nan",
       "nan",
       1,
       {"case.toml:{line}: body 'upper': body[1].dirichlet[1].y: must be a finite number"}},
      {"InfiniteYoung",
       "young = 1000.0",
       "young = inf",
       "inf",
       1,
       {"case.toml:{line}: body 'upper': body[1].material.young: must be a finite number"}},
      {"InfiniteGapConstant",
       "R = 50.0",
       "R = -inf",
       "inf",
       1,
       {"case.toml:{line}: gap.constants.R: must be a finite number"}},
      // Ranges.
      {"RelaxationTwo",
       "relaxation = 0.5",
       "relaxation = 2.0",
       "relaxation",
       1,
       {"case.toml:{line}: coupling.relaxation: must be in (0, 2), got 2"}},
      {"RelaxationZero",
       "relaxation = 0.5",
       "relaxation = 0",
       "relaxation",
       1,
       {"case.toml:{line}: coupling.relaxation: must be in (0, 2), got 0"}},
      {"RelaxationNegative",
       "relaxation = 0.5",
       "relaxation = -0.5",
       "relaxation",
       1,
       {"case.toml:{line}: coupling.relaxation: must be in (0, 2), got -0.5"}},
      {"ZeroCouplingTolerance",
       "tolerance = 1e-8",
       "tolerance = 0.0",
       "tolerance = 0.0",
       1,
       {"case.toml:{line}: coupling.tolerance: must be > 0, got 0"}},
      {"NegativeQpTolerance",
       "qp_tolerance = 1e-12",
       "qp_tolerance = -1e-12",
       "qp_tolerance",
       1,
       {"case.toml:{line}: solver.qp_tolerance: must be > 0, got -1e-12"}},
      {"ZeroPairingTolerance",
       "qp_tolerance = 1e-12",
       "pairing_tolerance = 0.0",
       "pairing_tolerance",
       1,
       {"case.toml:{line}: solver.pairing_tolerance: must be > 0"}},
      {"ZeroQpMaxIterations",
       "qp_tolerance = 1e-12",
       "qp_max_iterations = 0",
       "qp_max_iterations",
       1,
       {"case.toml:{line}: solver.qp_max_iterations: must be >= 1"}},
      {"ZeroDenseLimit",
       "qp_tolerance = 1e-12",
       "dense_limit = 0",
       "dense_limit",
       1,
       {"case.toml:{line}: solver.dense_limit: must be >= 1, got 0"}},
      {"ZeroMaxIterations",
       "relaxation = 0.5",
       "max_iterations = 0",
       "max_iterations",
       1,
       {"case.toml:{line}: coupling.max_iterations: must be >= 1"}},
      {"ZeroRequestTimeout",
       "relaxation = 0.5",
       "request_timeout = 0.0",
       "request_timeout",
       1,
       {"case.toml:{line}: coupling.request_timeout: must be > 0"}},
      {"NegativeSetupTimeout",
       "relaxation = 0.5",
       "setup_timeout = -5.0",
       "setup_timeout",
       1,
       {"case.toml:{line}: coupling.setup_timeout: must be > 0"}},
      {"DivergenceFactorOne",
       "relaxation = 0.5",
       "divergence_factor = 1.0",
       "divergence_factor",
       1,
       {"case.toml:{line}: coupling.divergence_factor: must be > 1"}},
      {"ZeroStagnationWindow",
       "relaxation = 0.5",
       "stagnation_window = 0",
       "stagnation_window",
       1,
       {"case.toml:{line}: coupling.stagnation_window: must be >= 1"}},
      {"UnknownAlgorithm",
       "relaxation = 0.5",
       "algorithm = \"robin-neumann\"",
       "algorithm",
       1,
       {"case.toml:{line}: coupling.algorithm: 'robin-neumann' is not one of: robin, "
        "robin-constant, dirichlet-neumann, neumann-neumann"}},
      {"RobinConstantWithoutAlpha",
       "relaxation = 0.5",
       "algorithm = \"robin-constant\"",
       "algorithm",
       1,
       {"case.toml:{line}: coupling.algorithm: \"robin-constant\" needs coupling.alpha > 0"}},
      {"NegativeAlpha",
       "relaxation = 0.5",
       "alpha = -1.0",
       "alpha",
       1,
       {"case.toml:{line}: coupling.alpha: must be > 0"}},
      {"UnknownMixing",
       "relaxation = 0.5",
       "mixing = \"half\"",
       "mixing",
       1,
       {"case.toml:{line}: coupling.mixing: 'half' is not one of: full, relaxation, aitken"}},
      {"UnknownContactBody",
       "relaxation = 0.5",
       "contact_body = \"3\"",
       "contact_body",
       1,
       {"case.toml:{line}: coupling.contact_body: '3' is not one of: 1, 2, auto"}},
      {"UnknownStopping",
       "relaxation = 0.5",
       "stopping = \"first\"",
       "stopping",
       1,
       {"case.toml:{line}: coupling.stopping: 'first' is not one of: either-sequence, joint"}},
      {"UnknownInterfaceOperator",
       "\"auto\"",
       "\"sparse\"",
       "sparse",
       1,
       {"case.toml:{line}: solver.interface_operator: 'sparse' is not one of: auto, dense, "
        "factor"}},
      {"UnknownLinearSolver",
       "qp_tolerance = 1e-12",
       "linear_solver = \"amg\"",
       "amg",
       1,
       {"case.toml:{line}: solver.linear_solver: 'amg' is not one of: auto, direct, multigrid"}},
      {"LinearSolverNotAString",
       "qp_tolerance = 1e-12",
       "linear_solver = 2",
       "linear_solver",
       1,
       {"case.toml:{line}: solver.linear_solver: expected a string, found an integer"}},
      {"UnknownInitialObstacle",
       "\"gap\"",
       "\"none\"",
       "none",
       1,
       {"case.toml:{line}: coupling.initial_obstacle: 'none' is not one of: gap, zero"}},
      {"UnknownModel",
       "\"plane_strain\"",
       "\"plane_strane\"",
       "plane_strane",
       1,
       {"case.toml:{line}: body 'upper': body[1].model: 'plane_strane' is not one of: "
        "plane_strain, plane_stress"}},
      {"ElementOrderThree",
       "mesh_size = 0.5",
       "element_order = 3",
       "element_order",
       1,
       {"case.toml:{line}: body 'upper': body[1].element_order: must be 1 or 2, got 3"}},
      {"QuadraticQuadrilaterals",
       "mesh_size = 0.5",
       "element_order = 2\nrecombine = true",
       "recombine",
       1,
       {"case.toml:{line}: body 'upper': body[1].recombine: ", "quadratic quadrilaterals"}},
      {"NegativeMeshSize",
       "mesh_size = 0.5",
       "mesh_size = -0.5",
       "mesh_size",
       1,
       {"case.toml:{line}: body 'upper': body[1].mesh_size: must be > 0, got -0.5"}},
      // Bodies and meshes.
      {"DuplicateBodyNames",
       "name = \"lower\"",
       "name = \"upper\"",
       "name = \"upper\"",
       2,
       {"case.toml:{line}: body 'upper': body[2].name: duplicates the name of body[1]"}},
      {"InvalidBodyName",
       "name = \"upper\"",
       "name = \"up per\"",
       "up per",
       1,
       {"case.toml:{line}: body 'up per': body[1].name: 'up per' is not a valid body name"}},
      {"EmptyBodyName",
       "name = \"upper\"",
       "name = \"\"",
       "name = \"\"",
       1,
       {"case.toml:{line}: body[1].name: '' is not a valid body name"}},
      {"ThreeBodies",
       "fix = \"both\"\n",
       "fix = \"both\"\n\n[[body]]\nname = \"third\"\n",
       "[[body]]",
       3,
       {"case.toml:{line}: expected exactly two [[body]] tables, found 3"}},
      {"MissingMeshFile",
       "case_lower.msh",
       "case_missing.msh",
       "case_missing",
       1,
       {"case.toml:{line}: body 'lower': body[2].mesh: mesh file '" + missing_mesh +
        "' does not exist"}},
      {"MeshSizeOnMsh",
       lower_mesh,
       lower_mesh + "\nmesh_size = 0.1",
       "mesh_size = 0.1",
       1,
       {"case.toml:{line}: body 'lower': body[2].mesh_size: applies only to a .geo mesh"}},
      {"RecombineOnMsh",
       lower_mesh,
       lower_mesh + "\nrecombine = true",
       "recombine",
       1,
       {"case.toml:{line}: body 'lower': body[2].recombine: applies only to a .geo mesh"}},
      {"MeshNeitherMshNorGeo",
       "case_lower.msh",
       "case_lower.stl",
       "case_lower.stl",
       1,
       {"case.toml:{line}: body 'lower': body[2].mesh: ", "is neither a .msh nor a .geo file"}},
      // The gap expression and its constants.
      {"GapSyntaxError",
       "(2*R)\"",
       "(2*R\"",
       "expression",
       1,
       {"case.toml:{line}: gap.expression: ", "parenthesis"}},
      {"GapUnknownVariable",
       "x^2 / (2*R)",
       "x + w",
       "expression",
       1,
       {"case.toml:{line}: gap.expression: ", "\"w\"", "position 4"}},
      {"GapConstantNotANumber",
       "R = 50.0",
       "R = \"50\"",
       "constants",
       1,
       {"case.toml:{line}: gap.constants.R: expected a number, found a string"}},
      {"GapConstantNamedX",
       "{ R = 50.0 }",
       "{ R = 50.0, x = 1.0 }",
       "constants",
       1,
       {"case.toml:{line}: gap.constants: 'x' is a variable of the expression"}},
      {"GapConstantInvalidName",
       "{ R = 50.0 }",
       "{ R = 50.0, \"2b\" = 1.0 }",
       "constants",
       1,
       {"case.toml:{line}: gap.constants: '2b' is not a valid constant name"}},
      // TOML syntax: file:line:column and toml++'s description.
      {"TomlSyntaxError",
       "relaxation = 0.5",
       "relaxation = = 0.5",
       "relaxation",
       1,
       {"case.toml:{line}:", "TOML syntax error"}},
      {"TomlDuplicateKey",
       "young = 1000.0",
       "young = 1000.0\nyoung = 1.0",
       "young = 1.0",
       1,
       {"case.toml:{line}:", "TOML syntax error", "young"}},
  };
}

void PrintTo(const ErrorCase& error, std::ostream* stream) {
  *stream << error.name;
}

class CaseFileError : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(CaseFileError, MessageNamesFileLineFieldAndBody) {
  const ErrorCase& error = GetParam();
  const std::string text = replaced(base_case(), error.from, error.to);
  const std::string message = read_error(write_case(text));
  ASSERT_FALSE(message.empty()) << "no InputError for the edited case:\n" << text;
  const int line =
      error.line_marker.empty() ? 0 : line_containing(text, error.line_marker, error.occurrence);
  ASSERT_TRUE(error.line_marker.empty() || line > 0) << error.line_marker;
  for (std::string fragment : error.fragments) {
    const std::size_t at = fragment.find("{line}");
    if (at != std::string::npos) fragment.replace(at, 6, std::to_string(line));
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected: " << fragment << "\nmessage:  " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(AllErrors, CaseFileError, ::testing::ValuesIn(error_cases()),
                         [](const ::testing::TestParamInfo<ErrorCase>& info) {
                           return info.param.name;
                         });

TEST(CaseFile, TomlSyntaxErrorGivesLineAndColumn) {
  // "relaxation = = 0.5": toml++ stops at the second '=', column 14.
  const std::string text = replaced(base_case(), "relaxation = 0.5", "relaxation = = 0.5");
  const std::string message = read_error(write_case(text));
  const int line = line_containing(text, "relaxation");
  const std::regex pattern("case\\.toml:" + std::to_string(line) +
                           ":([0-9]+): TOML syntax error: .+");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(message, match, pattern)) << message;
  EXPECT_EQ(std::stoi(match[1]), 14) << message;
}

TEST(CaseFile, BodyCountOtherThanTwoIsAnError) {
  const std::string text = base_case();
  const std::string one_body = text.substr(0, text.find("[[body]]\nname = \"lower\""));
  const std::string no_body = text.substr(0, text.find("[[body]]"));
  EXPECT_NE(read_error(write_case(one_body)).find("expected exactly two [[body]] tables, found 1"),
            std::string::npos);
  const std::string message = read_error(write_case(no_body));
  EXPECT_NE(message.find("case.toml: expected exactly two [[body]] tables, found 0"),
            std::string::npos)
      << message;
  const std::string single_table = replaced(no_body, "title", "[body]\nname = \"a\"\n\n[x]\ntitle");
  const std::string table_message = read_error(write_case(single_table));
  EXPECT_NE(table_message.find("unknown key 'x'"), std::string::npos) << table_message;
  const std::string body_table = no_body + "\n[body]\nname = \"a\"\n";
  const std::string body_message = read_error(write_case(body_table));
  EXPECT_NE(body_message.find("body: expected an array of tables ([[body]]), found a table"),
            std::string::npos)
      << body_message;
}

TEST(CaseFile, MissingCaseFileIsNamed) {
  const fs::path path = fresh_directory() / "absent.toml";
  const std::string message = read_error(path);
  EXPECT_NE(message.find(path.string() + ": case file not found"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------------------
// load_body

TEST(LoadBody, ReadsTheMeshWithTheCaseOptions) {
  const CaseDefinition definition = read_case_file(data("case_full.toml"));
  const BodyDefinition upper = load_body(definition.bodies[0]);
  EXPECT_EQ(upper.name, "upper");
  EXPECT_EQ(upper.dirichlet.size(), 2u);
  expect_matrix_near(upper.material.stiffness,
                     isotropic_stiffness(210e3, 0.3, PlaneModel::plane_stress));
  // element_order = 2: quadratic triangles; mesh_size = 0.25 on the unit edge y = 0: 4 edges.
  ASSERT_FALSE(upper.mesh.blocks.empty());
  for (const ElementBlock& block : upper.mesh.blocks) {
    EXPECT_EQ(block.type, ElementType::triangle6);
  }
  const BoundaryGroup& contact = upper.mesh.boundaries.at("contact");
  EXPECT_EQ(contact.type, FacetType::line3);
  EXPECT_EQ(contact.facet_count(), 4u);
  for (int node : contact.nodes()) EXPECT_NEAR(upper.mesh.nodes[node].y(), 0.0, 1e-12);
  for (const Eigen::Vector3d& node : upper.mesh.nodes) {
    EXPECT_GE(node.x(), -1e-12);
    EXPECT_LE(node.x(), 1.0 + 1e-12);
    EXPECT_GE(node.y(), -1e-12);
    EXPECT_LE(node.y(), 1.0 + 1e-12);
  }
  const BodyDefinition lower = load_body(definition.bodies[1]);
  for (int node : lower.mesh.boundaries.at("bottom").nodes()) {
    EXPECT_NEAR(lower.mesh.nodes[node].y(), -1.0, 1e-12);
  }
}

/// The InputError message of load_body for body `index` of the edited base case.
std::string load_error(const std::string& text, int index, std::string& case_path) {
  const fs::path path = write_case(text);
  case_path = path.string();
  const CaseDefinition definition = read_case_file(path);
  try {
    static_cast<void>(load_body(definition.bodies[index]));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(LoadBody, UnknownContactBoundaryListsTheMeshBoundaries) {
  const std::string text = replaced(base_case(), "contact_boundary = \"contact\"\nbody_force",
                                    "contact_boundary = \"kontakt\"\nbody_force");
  std::string path;
  const std::string message = load_error(text, 0, path);
  const std::string expected =
      location(path, line_containing(text, "kontakt")) +
      ": body 'upper': body[1].contact_boundary: boundary 'kontakt' is not a physical curve of "
      "mesh '" +
      (data_directory / "case_upper.geo").string() + "' (available: contact, left, right, top)";
  EXPECT_EQ(message, expected);
}

TEST(LoadBody, UnknownDirichletAndTractionBoundaries) {
  const std::string dirichlet_text =
      replaced(base_case(), "boundary = \"bottom\"", "boundary = \"floor\"");
  std::string path;
  const std::string dirichlet_message = load_error(dirichlet_text, 1, path);
  EXPECT_NE(dirichlet_message.find(location(path, line_containing(dirichlet_text, "floor")) +
                                   ": body 'lower': body[2].dirichlet[1].boundary: boundary "
                                   "'floor'"),
            std::string::npos)
      << dirichlet_message;
  EXPECT_NE(dirichlet_message.find((data_directory / "case_lower.msh").string()),
            std::string::npos);
  EXPECT_NE(dirichlet_message.find("(available: bottom, contact, left, right)"), std::string::npos);

  const std::string traction_text =
      replaced(base_case(), "boundary = \"right\"", "boundary = \"rite\"");
  const std::string traction_message = load_error(traction_text, 0, path);
  EXPECT_NE(traction_message.find(location(path, line_containing(traction_text, "rite")) +
                                  ": body 'upper': body[1].traction[1].boundary: boundary 'rite'"),
            std::string::npos)
      << traction_message;
}

// A mesh without physical groups: the message names the case file, the line of `mesh`, the
// body and the key.
TEST(LoadBody, MeshReaderErrorsCarryTheCaseContext) {
  const std::string text = replaced(base_case(), "case_upper.geo", "case_no_surface.geo");
  std::string path;
  const std::string message = load_error(text, 0, path);
  EXPECT_EQ(message.rfind(location(path, line_containing(text, "case_no_surface.geo")) +
                              ": body 'upper': body[1].mesh: ",
                          0),
            0u)
      << message;
  EXPECT_NE(message.find("case_no_surface.geo"), std::string::npos) << message;
}

TEST(LoadBody, HandBuiltBodyCaseIsCheckedToo) {
  BodyCase body;
  body.definition.name = "x";
  body.definition.contact_boundaries = {"nowhere"};
  body.mesh_path = data("case_upper.geo");
  body.context = "hand: body 'x'";
  try {
    static_cast<void>(load_body(body));
    FAIL() << "no InputError for an unknown contact boundary";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what())
                  .rfind("hand: body 'x': contact_boundary: boundary "
                         "'nowhere' is not a physical curve of mesh",
                         0),
              0u)
        << error.what();
  }
}

// ---------------------------------------------------------------------------------------
// Solid bodies (dimension = 3)

/// A valid case of two solid blocks; `@DATA@` is the test data directory.
std::string solid_case() {
  std::string text = R"toml(title = "solid blocks"
dimension = 3

[gap]
expression = "(x^2 + y^2) / (2*R) + z"
constants = { R = 50.0 }

[[body]]
name = "upper"
mesh = "@DATA@/solid_block.geo"
mesh_size = 0.3
contact_boundary = "bottom"
body_force = [0.0, 0.0, -1.0]

[body.material]
young = 1000.0
poisson = 0.3

[[body.dirichlet]]
boundary = "top"
z = -0.01

[[body.dirichlet]]
boundary = "left"
fix = "all"

[[body.traction]]
boundary = "right"
vector = [1.0, 2.0, 3.0]

[[body]]
name = "lower"
mesh = "@DATA@/solid_block_hexahedra.geo"
contact_boundary = "top"

[body.material]
voigt = [[10, 1, 2, 0, 0, 0], [1, 11, 3, 0, 0, 0], [2, 3, 12, 0, 0, 0],
         [0, 0, 0, 4, 0, 0], [0, 0, 0, 0, 5, 0], [0, 0, 0, 0, 0, 6]]

[[body.dirichlet]]
boundary = "bottom"
fix = "z"
)toml";
  for (std::size_t at = text.find("@DATA@"); at != std::string::npos; at = text.find("@DATA@")) {
    text.replace(at, 6, data_directory.string());
  }
  return text;
}

/// The isotropic solid stiffness (Voigt xx, yy, zz, yz, xz, xy; engineering shear strains),
/// written out from the textbook formulas C = lambda 1 1' + 2 mu I, mu on the shear entries.
Eigen::MatrixXd isotropic_solid_stiffness(double young, double nu) {
  const double lambda = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double mu = young / (2.0 * (1.0 + nu));
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(6, 6);
  stiffness.topLeftCorner(3, 3).setConstant(lambda);
  for (int i = 0; i < 3; ++i) stiffness(i, i) += 2.0 * mu;
  for (int i = 3; i < 6; ++i) stiffness(i, i) = mu;
  return stiffness;
}

TEST(SolidCaseFile, ReadsVectorsMaterialsAndSupportsOfSolidBodies) {
  const fs::path path = write_case(solid_case());
  CaseDefinition definition = read_case_file(path);
  EXPECT_EQ(definition.dimension, 3);
  const BodyDefinition& upper = definition.bodies[0].definition;
  EXPECT_EQ(upper.body_force, Eigen::Vector3d(0.0, 0.0, -1.0));
  ASSERT_EQ(upper.tractions.size(), 1u);
  EXPECT_EQ(upper.tractions[0].vector, Eigen::Vector3d(1.0, 2.0, 3.0));
  ASSERT_EQ(upper.dirichlet.size(), 2u);
  EXPECT_FALSE(upper.dirichlet[0].x.has_value());
  EXPECT_EQ(upper.dirichlet[0].z, -0.01);
  EXPECT_EQ(upper.dirichlet[1].x, 0.0);
  EXPECT_EQ(upper.dirichlet[1].y, 0.0);
  EXPECT_EQ(upper.dirichlet[1].z, 0.0);
  const Eigen::MatrixXd expected = isotropic_solid_stiffness(1000.0, 0.3);
  ASSERT_EQ(upper.material.stiffness.rows(), 6);
  EXPECT_LE((upper.material.stiffness - expected).cwiseAbs().maxCoeff(), 1e-12 * 1000.0);
  const BodyDefinition& lower = definition.bodies[1].definition;
  ASSERT_EQ(lower.material.stiffness.rows(), 6);
  EXPECT_EQ(lower.material.stiffness(2, 1), 3.0);
  EXPECT_EQ(lower.material.stiffness(5, 5), 6.0);
  EXPECT_EQ(lower.dirichlet[0].z, 0.0);
  EXPECT_FALSE(lower.dirichlet[0].x.has_value());
  load_meshes(definition);
  EXPECT_EQ(definition.bodies[0].definition.mesh.dimension, 3);
  EXPECT_EQ(definition.bodies[1].definition.mesh.dimension, 3);
}

TEST(SolidCaseFile, TheGapFunctionTakesZ) {
  const GapFunction gap("(x^2 + y^2) / (2*R) + z", {{"R", 50.0}}, "test");
  EXPECT_DOUBLE_EQ(gap(3.0, 4.0, 0.5), 25.0 / 100.0 + 0.5);
  EXPECT_DOUBLE_EQ(gap(3.0, 4.0), 25.0 / 100.0);  // plane bodies: z = 0
  const std::string constant = replaced(solid_case(), "R = 50.0", "z = 50.0");
  const fs::path path = write_case(constant);
  EXPECT_NE(read_error(path).find("'z' is a variable of the expression, not a constant"),
            std::string::npos)
      << read_error(path);
}

/// The error of `text`, expected to start with "FILE:LINE" of the line containing `marker`.
void expect_solid_error(const std::string& text, const std::string& marker,
                        const std::string& message) {
  const fs::path path = write_case(text);
  const std::string error = read_error(path);
  EXPECT_EQ(error.rfind(location(path, line_containing(text, marker)), 0), 0u) << error;
  EXPECT_NE(error.find(message), std::string::npos) << error;
}

TEST(SolidCaseFile, PlaneKeysAndSizesAreErrorsInASolidCase) {
  const std::string base = solid_case();
  expect_solid_error(replaced(base, "dimension = 3", "dimension = 4"), "dimension = 4",
                     "dimension: must be 2 (plane bodies) or 3 (solid bodies), got 4");
  expect_solid_error(replaced(base, "mesh_size = 0.3", "mesh_size = 0.3\nmodel = \"plane_strain\""),
                     "model =", "a solid body (dimension = 3) has no plane model");
  expect_solid_error(replaced(base, "vector = [1.0, 2.0, 3.0]", "vector = [1.0, 2.0]"),
                     "vector = [1.0, 2.0]", "expected an array of three numbers [x, y, z]");
  expect_solid_error(replaced(base, "body_force = [0.0, 0.0, -1.0]", "body_force = [0.0, -1.0]"),
                     "body_force =", "expected an array of three numbers [x, y, z]");
  expect_solid_error(replaced(base, "fix = \"all\"", "fix = \"both\""), "fix = \"both\"",
                     "'both' is not one of: all, x, y, z");
  expect_solid_error(replaced(base, "[[10, 1, 2, 0, 0, 0]", "[[10, 1, 2, 0, 0]"),
                     "voigt =", "expected six rows of six numbers");
  expect_solid_error(replaced(base, "fix = \"z\"", "fix = \"z\"\nz = 0.5"), "fix = \"z\"",
                     "cannot be combined with z = 0.5");
}

TEST(SolidCaseFile, ZIsAnErrorInAPlaneCase) {
  const std::string text = replaced(base_case(), "y = -0.01", "y = -0.01\nz = 0.0");
  const fs::path path = write_case(text);
  const std::string error = read_error(path);
  EXPECT_EQ(error.rfind(location(path, line_containing(text, "z = 0.0")), 0), 0u) << error;
  EXPECT_NE(error.find("u_z applies to solid bodies only"), std::string::npos) << error;
}

TEST(SolidCaseFile, AMeshOfTheOtherDimensionIsAnErrorNamingTheBodyAndMesh) {
  const std::string plane_mesh =
      replaced(solid_case(), "solid_block_hexahedra.geo", "case_lower.msh");
  CaseDefinition solid = read_case_file(write_case(plane_mesh));
  try {
    static_cast<void>(load_body(solid.bodies[1]));
    ADD_FAILURE() << "a plane mesh in a solid case was accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("body 'lower'"), std::string::npos) << message;
    EXPECT_NE(message.find("case_lower.msh"), std::string::npos) << message;
    EXPECT_NE(message.find("' is two-dimensional (area elements) but the case file has "
                           "dimension = 3"),
              std::string::npos)
        << message;
  }
  const std::string solid_mesh = replaced(base_case(), "case_lower.msh", "solid_block.geo");
  CaseDefinition plane = read_case_file(write_case(solid_mesh));
  try {
    static_cast<void>(load_body(plane.bodies[1]));
    ADD_FAILURE() << "a solid mesh in a plane case was accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("solid_block.geo"), std::string::npos) << message;
    EXPECT_NE(message.find("set dimension = 3 at the top of the case file"), std::string::npos)
        << message;
  }
}

}  // namespace
}  // namespace robin
