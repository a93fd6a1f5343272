// robin-monolithic end to end: the real binary (build/bin/robin-monolithic) on
// examples/two_blocks_partial.toml with --output into a temporary directory exits 0 and leaves
// solution.pvd (naming one .vtu per body), the two .vtu files, contact.csv and summary.json.
// summary.json is checked against independent readings of the other outputs:
//  - its keys: method, converged, iterations, dofs per body (fewer than 2 x the body's .vtu
//    points), contact_force_resultant, timings {mesh, assembly, factorization, solve, total}
//    (disjoint intervals of the run: their sum is at most the total);
//  - contact_force_resultant = sum over contact.csv rows of lambda_i n1_i to 1e-10 relative;
//  - each body in equilibrium with it: sum of the .vtu reaction field + the body's
//    applied_force from the summary -+ the resultant (body 1 gets -R, body 2 +R) = 0 to 1e-10
//    relative to |R|.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../unit/vtk_xml_test_reader.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using nlohmann::json;
using testing::example;
using testing::ProcessOutcome;
using testing::run_tool;
using testing::TemporaryDirectory;

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> parts;
  std::stringstream stream(line);
  for (std::string part; std::getline(stream, part, separator);) parts.push_back(part);
  return parts;
}

/// sum_i lambda_i n1_i over the rows of contact.csv (header pair,x,y,nx,ny,gap0,un1,un2,
/// lambda1,lambda2,pressure), with lambda = (lambda1 + lambda2) / 2; counts the rows.
Eigen::Vector2d csv_resultant(const std::filesystem::path& path, int& rows) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split(line, ',');
  auto column = [&header](const std::string& name) {
    const auto found = std::find(header.begin(), header.end(), name);
    EXPECT_NE(found, header.end()) << "contact.csv has no column " << name;
    return static_cast<std::size_t>(found - header.begin());
  };
  const std::size_t nx = column("nx"), ny = column("ny");
  const std::size_t lambda1 = column("lambda1"), lambda2 = column("lambda2");
  Eigen::Vector2d resultant = Eigen::Vector2d::Zero();
  rows = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> values = split(line, ',');
    EXPECT_EQ(values.size(), header.size()) << line;
    if (values.size() != header.size()) continue;
    const double force = 0.5 * (std::stod(values[lambda1]) + std::stod(values[lambda2]));
    resultant += force * Eigen::Vector2d(std::stod(values[nx]), std::stod(values[ny]));
    ++rows;
  }
  return resultant;
}

/// Sum of the "reaction" point field (3 components, z = 0) of a parsed .vtu and its point count.
Eigen::Vector2d vtu_total_reaction(const json& document, std::size_t& points) {
  const json& piece = document.at("pieces").at(0);
  points = std::stoul(piece.at("attributes").at("NumberOfPoints").get<std::string>());
  const json& values = test::find_array(piece.at("PointData"), "reaction").at("values");
  EXPECT_EQ(values.size(), 3 * points);
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k + 2 < values.size(); k += 3) {
    total += Eigen::Vector2d(values[k].get<double>(), values[k + 1].get<double>());
  }
  return total;
}

Eigen::Vector2d vector_of(const json& pair) {
  return {pair.at(0).get<double>(), pair.at(1).get<double>()};
}

/// timings: every documented interval present and non-negative, their sum at most the total.
void expect_timings(const json& timings) {
  double sum = 0.0;
  for (const char* key : {"mesh", "assembly", "factorization", "solve"}) {
    ASSERT_TRUE(timings.contains(key)) << "timings." << key;
    EXPECT_GE(timings.at(key).get<double>(), 0.0) << key;
    sum += timings.at(key).get<double>();
  }
  ASSERT_TRUE(timings.contains("total"));
  EXPECT_LE(sum, timings.at("total").get<double>() * (1.0 + 1e-12));
}

TEST(RobinMonolithic, WritesConsistentResultFiles) {
  const TemporaryDirectory work("robin-monolithic");
  // robin-monolithic.stderr stays outside the result directory
  const std::filesystem::path results = work.path() / "out";
  const ProcessOutcome outcome =
      run_tool("robin-monolithic",
               {example("two_blocks_partial.toml").string(), "--output", results.string()},
               work.path(), 120.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  for (const char* file : {"solution.pvd", "contact.csv", "summary.json"}) {
    EXPECT_TRUE(std::filesystem::exists(results / file)) << file;
  }
  std::ifstream summary_file(results / "summary.json");
  const json summary = json::parse(summary_file);
  EXPECT_EQ(summary.at("method"), "monolithic");
  EXPECT_EQ(summary.at("converged"), true);
  EXPECT_GT(summary.at("iterations").get<int>(), 0);
  expect_timings(summary.at("timings"));

  // contact_force_resultant against contact.csv.
  int rows = 0;
  const Eigen::Vector2d resultant = vector_of(summary.at("contact_force_resultant"));
  const Eigen::Vector2d from_csv = csv_resultant(results / "contact.csv", rows);
  EXPECT_EQ(rows, summary.at("contact_pairs").get<int>());
  ASSERT_GT(resultant.norm(), 0.0);
  const double csv_error = (from_csv - resultant).norm() / resultant.norm();
  EXPECT_LE(csv_error, 1e-10);

  // One .vtu per body, named in solution.pvd; each body balances the resultant.
  const json collection = test::read_vtk_xml(results / "solution.pvd");
  const json& bodies = summary.at("bodies");
  ASSERT_EQ(bodies.size(), 2u);
  ASSERT_EQ(collection.at("datasets").size(), 2u);
  double worst_balance = 0.0;
  for (std::size_t alpha = 0; alpha < 2; ++alpha) {
    const std::string file = bodies[alpha].at("name").get<std::string>() + ".vtu";
    EXPECT_EQ(collection["datasets"][alpha].at("file"), file);
    ASSERT_TRUE(std::filesystem::exists(results / file)) << file;
    std::size_t points = 0;
    const Eigen::Vector2d reaction = vtu_total_reaction(test::read_vtk_xml(results / file), points);
    EXPECT_EQ(bodies[alpha].at("nodes").get<std::size_t>(), points) << file;
    const int dofs = bodies[alpha].at("dofs").get<int>();
    EXPECT_GT(dofs, 0) << file;
    EXPECT_LT(static_cast<std::size_t>(dofs), 2 * points) << file;
    const Eigen::Vector2d contact = alpha == 0 ? Eigen::Vector2d(-resultant) : resultant;
    const Eigen::Vector2d balance =
        reaction + vector_of(bodies[alpha].at("applied_force")) + contact;
    EXPECT_LE(balance.norm(), 1e-10 * resultant.norm()) << file;
    worst_balance = std::max(worst_balance, balance.norm() / resultant.norm());
  }
  std::cout << "robin-monolithic: resultant (" << resultant.x() << ", " << resultant.y()
            << "), contact.csv sum relative error " << csv_error << ", worst body balance relative "
            << worst_balance << "\n";
}

}  // namespace
}  // namespace robin
