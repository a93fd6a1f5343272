// Who reads a body's .msh file (MeshDelivery, coordinator/coupling/case_file.hpp): robin-run's
// own local robin-subdomain servers read it themselves (SetupBody.mesh_path under the
// --data-directory robin-run gives them, the file's directory); with --server-executable the
// coordinator reads it and sends the mesh as MeshData, as robin-coordinator does. Both runs are
// real robin-run processes with real servers, on files Gmsh wrote (the lower body as MSH 2.2,
// the upper one as binary MSH 4.1: both heads the coordinator summarizes).
//  - The results are the same bytes both ways: the server's reader and the coordinator's are
//    the same native reader, and the mesh travels exactly as data.
//  - The mesh did not travel: what the coordinator sent each server stays below one double per
//    node, against at least two per node (the coordinates) when it sends the mesh.
//  - A boundary name the file's head does not list makes the coordinator read the file whole,
//    and its error names the case file's line and the mesh, as with MeshData.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "remote_test_support.hpp"

namespace robin {
namespace {

using nlohmann::json;
using testing::example;
using testing::read_text;
using testing::TemporaryDirectory;

/// examples/meshes/block_`body`.geo meshed by the gmsh command at h = 0.05 into `path` in
/// `format` ("msh22", "msh41"), binary when `binary`.
void mesh_block(const std::string& body, const std::filesystem::path& path,
                const std::string& format, bool binary) {
  const std::string command = "gmsh -2 -setnumber h 0.05 -format " + format +
                              (binary ? " -bin " : " ") +
                              example("meshes/block_" + body + ".geo").string() + " -o " +
                              path.string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
}

/// examples/two_blocks_partial.toml on the .msh files of `directory` (the case written there).
std::filesystem::path msh_case(const std::filesystem::path& directory) {
  mesh_block("lower", directory / "lower.msh", "msh22", false);
  mesh_block("upper", directory / "upper.msh", "msh41", true);
  std::string text = read_text(example("two_blocks_partial.toml"));
  text = std::regex_replace(text, std::regex("meshes/block_(lower|upper)\\.geo"), "$1.msh");
  text = std::regex_replace(text, std::regex("mesh_size = [0-9.]+\n"), "");
  const std::filesystem::path path = directory / "case.toml";
  std::ofstream(path) << text;
  return path;
}

TEST(ServerReadMeshes, SameResultsAsWhenTheCoordinatorSendsTheMeshes) {
  const TemporaryDirectory directory("server-read-meshes");
  const std::filesystem::path case_file = msh_case(directory.path());
  const std::filesystem::path servers = directory.path() / "servers";
  const std::filesystem::path coordinator = directory.path() / "coordinator";
  const auto read_by_servers = testing::run_robin_run(case_file, servers, false);
  ASSERT_EQ(read_by_servers.exit, "exited with status 0") << read_by_servers.errors;
  const auto sent = testing::run_robin_run(case_file, coordinator, true);
  ASSERT_EQ(sent.exit, "exited with status 0") << sent.errors;
  for (const char* file : {"lower.vtu", "upper.vtu", "contact.csv"}) {
    EXPECT_TRUE(read_text(servers / file) == read_text(coordinator / file))
        << file << " differs between the runs";
  }
  const json by_servers = testing::read_summary(servers);
  const json by_coordinator = testing::read_summary(coordinator);
  EXPECT_EQ(by_servers["iterations"], by_coordinator["iterations"]);
  EXPECT_EQ(by_servers["contact_force_resultant"], by_coordinator["contact_force_resultant"]);
  for (std::size_t body = 0; body < 2; ++body) {
    const std::string name = by_servers["bodies"][body]["name"];
    const long nodes = testing::vtu_point_count(servers / (name + ".vtu"));
    ASSERT_GT(nodes, 0) << name;
    EXPECT_LT(by_servers["bodies"][body]["bytes_sent"].get<long>(), 8 * nodes)
        << name << ": the mesh was sent anyway";
    EXPECT_GE(by_coordinator["bodies"][body]["bytes_sent"].get<long>(), 2 * 8 * nodes)
        << name << ": the coordinator's run did not send the mesh";
  }
}

TEST(ServerReadMeshes, ABoundaryTheHeadDoesNotListGetsTheCoordinatorsError) {
  const TemporaryDirectory directory("server-read-meshes-error");
  const std::filesystem::path case_file = msh_case(directory.path());
  std::string text = read_text(case_file);
  text = std::regex_replace(text, std::regex("boundary = \"bottom\""), "boundary = \"floor\"");
  std::ofstream(case_file) << text;
  const auto result = testing::run_robin_run(case_file, directory.path() / "out", false);
  EXPECT_EQ(result.exit, "exited with status 1") << result.errors;
  for (const std::string fragment : {"case.toml:", "body 'lower'", "dirichlet",
                                     "boundary 'floor' is not a physical curve", "lower.msh"}) {
    EXPECT_NE(result.errors.find(fragment), std::string::npos)
        << "missing '" << fragment << "' in:\n"
        << result.errors;
  }
}

}  // namespace
}  // namespace robin
