// Bad input through the real executables: every problem ends with a non-zero exit and a message
// naming the file, the field (and line) and the body; never a crash (exit by signal) or a hang.
// Each case is a variant of examples/two_blocks.toml written to a temporary directory.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code = -1;  // -1 when killed by a signal
  std::string output;  // stdout and stderr
};

CommandResult run_command(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen(("timeout 60 " + command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  return result;
}

std::string read_text(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = fs::temp_directory_path() /
                 ("robin_bad_input_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(directory_);
    const fs::path meshes = fs::path(ROBIN_EXAMPLES) / "meshes";
    base_case_ = read_text(fs::path(ROBIN_EXAMPLES) / "two_blocks.toml");
    base_case_ = std::regex_replace(base_case_, std::regex("meshes/"), meshes.string() + "/");
  }
  void TearDown() override { fs::remove_all(directory_); }

  /// Writes the base case with `from` replaced by `to` (which must occur) and returns its path.
  fs::path write_case(const std::string& from, const std::string& to) {
    const std::size_t position = base_case_.find(from);
    EXPECT_NE(position, std::string::npos) << from;
    std::string text = base_case_;
    if (position != std::string::npos) text.replace(position, from.size(), to);
    const fs::path path = directory_ / "case.toml";
    std::ofstream(path) << text;
    return path;
  }

  /// Runs robin-monolithic on the case and checks a clean failure whose message contains
  /// every fragment.
  void expect_failure(const fs::path& case_path, const std::vector<std::string>& fragments) {
    const std::string binary = std::string(ROBIN_BINARY_DIR) + "/bin/robin-monolithic";
    const CommandResult result = run_command(binary + " " + case_path.string() + " --output " +
                                             (directory_ / "out").string() + " --overwrite");
    EXPECT_EQ(result.exit_code, 1) << result.output;
    expect_fragments(result.output, fragments);
  }

  /// Runs robin-run (two robin-subdomain servers and the coordinator) on the case and checks a
  /// clean failure whose message contains every fragment.
  void expect_coupled_failure(const fs::path& case_path,
                              const std::vector<std::string>& fragments) {
    const std::string binary = std::string(ROBIN_BINARY_DIR) + "/bin/robin-run";
    const CommandResult result = run_command(binary + " " + case_path.string() + " --output " +
                                             (directory_ / "coupled").string() + " --overwrite");
    EXPECT_EQ(result.exit_code, 1) << result.output;
    expect_fragments(result.output, fragments);
  }

  static void expect_fragments(const std::string& output,
                               const std::vector<std::string>& fragments) {
    for (const std::string& fragment : fragments) {
      EXPECT_NE(output.find(fragment), std::string::npos) << "missing '" << fragment << "' in:\n"
                                                          << output;
    }
  }

  fs::path directory_;
  std::string base_case_;
};

TEST_F(BadInput, MissingCaseFile) {
  expect_failure(directory_ / "nowhere.toml", {"nowhere.toml"});
}

TEST_F(BadInput, MalformedCaseFileNamesTheLine) {
  expect_failure(write_case("title = \"symmetric two blocks\"", "title = \"unterminated"),
                 {"case.toml:4"});
}

TEST_F(BadInput, UnknownKeyIsAnError) {
  expect_failure(write_case("young = 1000.0", "youngs = 1000.0"), {"case.toml", "youngs", "lower"});
}

TEST_F(BadInput, MissingMeshNamesThePathAndBody) {
  expect_failure(write_case("block_lower.geo", "no_such_mesh.geo"), {"no_such_mesh.geo", "lower"});
}

TEST_F(BadInput, MalformedMeshNamesTheFile) {
  const fs::path garbage = directory_ / "garbage.msh";
  std::ofstream(garbage) << "$MeshFormat\nthis is not a mesh\n";
  const std::string lower = fs::path(ROBIN_EXAMPLES).string() + "/meshes/block_lower.geo";
  expect_failure(write_case(lower + "\"\nmesh_size = 0.1", garbage.string() + "\""),
                 {"garbage.msh", "lower"});
}

TEST_F(BadInput, UnknownPhysicalGroupNamesTheFieldAndBody) {
  expect_failure(write_case("boundary = \"bottom\"", "boundary = \"floor\""),
                 {"case.toml", "floor", "lower", "dirichlet"});
}

TEST_F(BadInput, IncompressiblePoissonRatio) {
  expect_failure(write_case("poisson = 0.3", "poisson = 0.5"), {"case.toml", "lower", "oisson"});
}

TEST_F(BadInput, NonPositiveDefiniteVoigtMatrix) {
  expect_failure(write_case("young = 1000.0\npoisson = 0.3",
                            "voigt = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]"),
                 {"case.toml", "lower", "positive definite"});
}

TEST_F(BadInput, BodyWithoutEnoughDirichletConditions) {
  expect_failure(write_case("x = 0.0\ny = 0.0", "y = 0.0"), {"case.toml", "lower", "rigid motion"});
}

// Through the service (robin-run), errors about a body's setup name the case file too: a body
// left with a rigid motion (the server's SINGULAR_BODY) names the line and key of its Dirichlet
// condition, a boundary name unknown to the mesh and a .geo with a syntax error name the line
// and key of the case file.
TEST_F(BadInput, ServiceErrorsAboutABodyNameTheCaseFileLineAndKey) {
  const fs::path singular = write_case("x = 0.0\ny = 0.0", "y = 0.0");
  const int dirichlet_line = 21;  // "boundary = \"bottom\"" of two_blocks.toml
  ASSERT_NE(read_text(singular).find("boundary = \"bottom\""), std::string::npos);
  std::istringstream lines(read_text(singular));
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (line == "boundary = \"bottom\"") {
      EXPECT_EQ(number, dirichlet_line);
    }
  }
  expect_coupled_failure(
      singular, {"case.toml:" + std::to_string(dirichlet_line) + " body[1].dirichlet[1].boundary",
                 "body 'lower'", "SINGULAR_BODY", "rigid motion"});

  expect_coupled_failure(write_case("boundary = \"bottom\"", "boundary = \"floor\""),
                         {"case.toml:" + std::to_string(dirichlet_line) +
                          ": body 'lower': " + "body[1].dirichlet[1].boundary: boundary 'floor'"});

  const fs::path broken = directory_ / "broken.geo";
  std::ofstream(broken)
      << "DefineConstant[ h = 0.1 ];\nPoint(1) = {0, 0, 0, h};\nLine(1) = {1, 2;\n";
  const std::string lower = fs::path(ROBIN_EXAMPLES).string() + "/meshes/block_lower.geo";
  const fs::path syntax = write_case(lower, broken.string());
  int mesh_line = 0;
  std::istringstream case_lines(read_text(syntax));
  for (int number = 1; std::getline(case_lines, line); ++number) {
    if (line.find("broken.geo") != std::string::npos) mesh_line = number;
  }
  expect_coupled_failure(
      syntax, {"case.toml:" + std::to_string(mesh_line) + ": body 'lower': body[1].mesh: ",
               "broken.geo", "line 3", "syntax error"});
}

TEST_F(BadInput, GapExpressionThatDoesNotParse) {
  expect_failure(write_case("[coupling]", "[gap]\nexpression = \"sin(x\"\n\n[coupling]"),
                 {"case.toml", "gap.expression"});
}

// A Dirichlet condition on the upper block's left side moves its corner contact node down by
// the whole platen displacement 0.01, while the contact compresses the blocks by about half of
// it: the excluded corner pair (its normal displacement is prescribed) penetrates by about 0.005.
// Both tools write their results and exit 1 naming the node.
TEST_F(BadInput, PrescribedDisplacementThatPenetratesIsAnError) {
  const fs::path case_path =
      write_case("boundary = \"top\"\nx = 0.0\ny = -0.01",
                 "boundary = \"top\"\nx = 0.0\ny = -0.01\n[[body.dirichlet]]\n"
                 "boundary = \"left\"\ny = -0.01");
  const std::vector<std::string> fragments = {"body 'upper' contact node", "(-1, 0)",
                                              "into each other"};
  expect_failure(case_path, fragments);
  EXPECT_TRUE(fs::exists(directory_ / "out" / "summary.json"));
  expect_coupled_failure(case_path, fragments);
  EXPECT_TRUE(fs::exists(directory_ / "coupled" / "summary.json"));
}

TEST_F(BadInput, ContactBoundaryThatIsADirichletBoundary) {
  expect_failure(write_case("contact_boundary = \"contact\"", "contact_boundary = \"bottom\""),
                 {"lower", "upper", "Dirichlet", "contact_boundary"});
}

// An output directory that cannot be made is a command-line error before any server starts.
TEST_F(BadInput, UnwritableOutputDirectoryIsACommandLineError) {
  const fs::path blocker = directory_ / "a_file";
  std::ofstream(blocker) << "not a directory";
  const std::string binary = std::string(ROBIN_BINARY_DIR) + "/bin/robin-run";
  const CommandResult result =
      run_command(binary + " " + ROBIN_EXAMPLES + "/two_blocks.toml --output " +
                  (blocker / "results").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  expect_fragments(result.output, {"--output", "cannot create the directory", "a_file/results"});
}

}  // namespace
