// Quasi-static load steps, the pieces: the [loading] table of the case file (values, defaults
// and every refusal with file, line and key), and BodySolver::set_load_factor against the body
// assembled with its loads and prescribed displacements written times the factor (e, the
// displacement, the reactions and the applied force scale; F does not change).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>

#include "../test_files.hpp"
#include "coupling/case_file.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/material.hpp"

namespace robin {
namespace {

namespace fs = std::filesystem;
using testing::TemporaryDirectory;

/// tests/data/case_minimal.toml with `loading` put before its bodies, in `directory`.
fs::path case_with(const TemporaryDirectory& directory, const std::string& loading) {
  const fs::path data(ROBIN_TEST_DATA);
  for (const char* mesh : {"case_upper.geo", "case_lower.geo"}) {
    fs::copy_file(data / mesh, directory.path() / mesh, fs::copy_options::overwrite_existing);
  }
  const fs::path path = directory.path() / "steps.toml";
  testing::write_text(path, "title = \"steps\"\n" + loading + "\n" +
                                testing::file_text(data / "case_minimal.toml"));
  return path;
}

std::string error_of(const fs::path& path) {
  try {
    read_case_file(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(LoadingTable, FactorsStepsAndDefaults) {
  const TemporaryDirectory directory("loading");
  EXPECT_FALSE(read_case_file(case_with(directory, "")).loading.stepped());
  LoadingOptions loading =
      read_case_file(case_with(directory, "[loading]\nfactors = [0.25, 0.5, 1, 2]")).loading;
  EXPECT_EQ(loading.factors, (std::vector<double>{0.25, 0.5, 1.0, 2.0}));
  EXPECT_TRUE(loading.warm_start);
  EXPECT_EQ(loading.timestep(0), 0.25);  // increasing: the factors are the timesteps
  EXPECT_EQ(loading.timestep(3), 2.0);
  EXPECT_NE(loading.context.find("steps.toml:2"), std::string::npos) << loading.context;
  loading =
      read_case_file(case_with(directory, "[loading]\nsteps = 4\nwarm_start = false")).loading;
  EXPECT_EQ(loading.factors, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
  EXPECT_FALSE(loading.warm_start);
  // Loading and unloading: the step numbers are the timesteps.
  loading = read_case_file(case_with(directory, "[loading]\nfactors = [1, 0.5, 0, -1]")).loading;
  EXPECT_EQ(loading.timestep(0), 1.0);
  EXPECT_EQ(loading.timestep(2), 3.0);
}

TEST(LoadingTable, RefusalsNameFileLineAndKey) {
  const TemporaryDirectory directory("loading-errors");
  const auto expect = [&](const std::string& table, const std::string& where,
                          const std::string& problem) {
    const std::string message = error_of(case_with(directory, table));
    EXPECT_NE(message.find((directory.path() / "steps.toml").string() + ":" + where),
              std::string::npos)
        << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  };
  expect("[loading]\nfactors = []", "3: loading.factors", "at least one load factor");
  expect("[loading]\nfactors = [0.5,\n 'one']", "4: loading.factors[2]", "expected a number");
  expect("[loading]\nfactors = [0.5, 2e7]", "3: loading.factors[2]", "magnitude at most 1e6");
  expect("[loading]\nfactors = [nan]", "3: loading.factors[1]", "finite");
  expect("[loading]\nfactors = [inf]", "3: loading.factors[1]", "finite");
  expect("[loading]\nfactors = 0.5", "3: loading.factors", "expected an array");
  expect("[loading]\nsteps = 0", "3: loading.steps", "[1, 10000]");
  expect("[loading]\nsteps = 2.5", "3: loading.steps", "");
  expect("[loading]\nfactors = [1]\nsteps = 1", "4: loading.steps", "not both");
  expect("[loading]\nwarm_start = true", "2: loading", "expected one of factors");
  expect("[loading]\nfactor = [1]", "3: unknown key 'loading.factor'",
         "factors, steps, warm_start");
  expect("[loading]\nfactors = [1]\nwarm_start = 1", "4: loading.warm_start", "");
  expect("loading = 3", "2: loading", "");
}

/// block_lower.geo (h = 0.25): bottom lifted by `lift`, body force (0, -5 t), a traction on
/// the right and a pressure on the left, each times `factor` in the definition itself.
BodyDefinition loaded_block(double factor) {
  static const Mesh mesh =
      read_gmsh_mesh(fs::path(ROBIN_EXAMPLES) / "meshes/block_lower.geo", {.size = 0.25});
  BodyDefinition definition;
  definition.name = "block";
  definition.mesh = mesh;
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.002 * factor, 0.01 * factor, std::nullopt});
  definition.body_force = Eigen::Vector3d(0.0, -5.0 * factor, 0.0);
  TractionCondition traction;
  traction.boundary = "right";
  traction.vector = Eigen::Vector3d(1.0 * factor, 2.0 * factor, 0.0);
  definition.tractions.push_back(traction);
  TractionCondition pressure;
  pressure.boundary = "left";
  pressure.is_pressure = true;
  pressure.pressure = 3.0 * factor;
  definition.tractions.push_back(pressure);
  definition.contact_boundaries = {"contact"};
  return definition;
}

double largest(const Eigen::VectorXd& values) {
  return values.lpNorm<Eigen::Infinity>();
}

TEST(BodySolverLoadFactor, EqualsTheBodyWrittenWithScaledLoads) {
  BodySolver stepped(loaded_block(1.0));
  const InterfaceDescription interface = stepped.contact_boundary();
  const ContactOperator contact = node_to_node_operator(
      interface.node_ids, std::vector<Eigen::Vector3d>(interface.node_ids.size(), {0.0, 1.0, 0.0}),
      interface.weights);
  stepped.assign_contact(contact);
  const Eigen::VectorXd force = Eigen::VectorXd::LinSpaced(stepped.contact_size(), 0.5, 1.5);
  Eigen::VectorXd unit_correction = stepped.solve_correction(force);
  for (const double factor : {0.0, 0.4, -2.0, 7.5}) {
    stepped.set_load_factor(factor);
    EXPECT_EQ(stepped.load_factor(), factor);
    BodySolver written(loaded_block(factor));
    written.assign_contact(contact);
    const double scale = std::max(largest(written.free_trace()), 1e-300);
    EXPECT_LE(largest(stepped.free_trace() - written.free_trace()), 1e-12 * scale + 1e-300)
        << "factor " << factor;
    const Eigen::VectorXd displacement = stepped.displacement(force);
    const Eigen::VectorXd expected = written.displacement(force);
    EXPECT_LE(largest(displacement - expected), 1e-12 * largest(expected)) << "factor " << factor;
    const Eigen::VectorXd reactions = stepped.reactions(displacement);
    EXPECT_LE(largest(reactions - written.reactions(expected)),
              1e-10 * std::max(1.0, largest(reactions)))
        << "factor " << factor;
    EXPECT_LE((stepped.applied_force() - written.applied_force()).norm(),
              1e-12 * std::max(1.0, written.applied_force().norm()));
    EXPECT_LE(largest(stepped.solve_neumann(force) - written.solve_neumann(force)),
              1e-12 * largest(written.solve_neumann(force)));
    // F: the same operator, whatever the load.
    EXPECT_EQ(stepped.solve_correction(force), unit_correction);
  }
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 1.5e6}) {
    EXPECT_THROW(stepped.set_load_factor(bad), InputError);
  }
  EXPECT_EQ(stepped.load_factor(), 7.5);  // a refused factor changes nothing
}

}  // namespace
}  // namespace robin
