// The .vtu files the tools write, read by VTK's own reader (ParaView's VTK, python3-paraview),
// against the analytic solution of the contact patch test examples/non_matching_blocks.toml:
// robin-monolithic (fields computed in-process) and robin-run (fields computed by two
// robin-subdomain servers and sent in FieldsReply, boundaries included).
//
// The case: the lower block [0, 1] x [-0.5, 0] (E1 = 1000, nu1 = 0.3) on rollers at its bottom,
// the upper block [0, 1] x [0, 0.4] (E2 = 400, nu2 = 0.25) whose top is pushed down by 0.01,
// both left edges held in x, plane strain. The exact solution is uniform uniaxial compression
// s_yy = -p in both bodies with
//   p = 0.01 / (0.5 (1 - nu1^2) / E1 + 0.4 (1 - nu2^2) / E2),
// s_xx = s_xy = 0, s_zz = -nu p (plane strain: e_zz = 0), so in each body
//   u_x = nu (1 + nu) p x / E,
//   u_y = -(1 - nu^2) p (y + 0.5) / E1          (lower),
//   u_y = -0.01 + (1 - nu^2) p (0.4 - y) / E2   (upper),
//   von Mises = sqrt(((0 + p)^2 + (-p + nu p)^2 + (-nu p)^2) / 2) = p sqrt(1 - nu + nu^2).
// Linear triangles and bilinear quadrilaterals reproduce it; the coupled run stops at its
// tolerance 1e-8, far below the tolerances used here.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>

#include "../unit/vtk_xml_test_reader.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using nlohmann::json;
using testing::example;
using testing::ProcessOutcome;
using testing::run_tool;
using testing::TemporaryDirectory;

constexpr double imposed = 0.01;
constexpr double lower_height = 0.5, upper_height = 0.4;

struct Body {
  const char* name;
  double young;
  double poisson;
  std::array<const char*, 4> boundaries;  // in name order
};
constexpr Body lower{"lower", 1000.0, 0.3, {"bottom", "contact", "left", "right"}};
constexpr Body upper{"upper", 400.0, 0.25, {"contact", "left", "right", "top"}};

double contact_pressure() {
  return imposed / (lower_height * (1 - lower.poisson * lower.poisson) / lower.young +
                    upper_height * (1 - upper.poisson * upper.poisson) / upper.young);
}

Eigen::Vector2d exact_displacement(const Body& body, double x, double y) {
  const double p = contact_pressure(), nu = body.poisson, young = body.young;
  const double u_x = nu * (1 + nu) * p * x / young;
  if (&body == &lower) return {u_x, -(1 - nu * nu) * p * (y + lower_height) / young};
  return {u_x, -imposed + (1 - nu * nu) * p * (upper_height - y) / young};
}

/// Checks one body's .vtu against the exact solution.
void expect_patch_solution(const std::filesystem::path& file, const Body& body) {
  SCOPED_TRACE(file.string());
  // Binary, zlib-compressed (the independent reader sees the attributes).
  const json raw = test::read_vtk_xml(file);
  EXPECT_EQ(raw["root"]["compressor"], "vtkZLibDataCompressor");
  EXPECT_EQ(raw["root"]["header_type"], "UInt64");
  EXPECT_EQ(test::find_array(raw["pieces"][0]["PointData"], "displacement")["attributes"]["format"],
            "appended");

  const json grid = test::read_vtu_with_vtk(file);
  const double p = contact_pressure(), nu = body.poisson;
  const double displacement_tolerance = 1e-7 * imposed, stress_tolerance = 1e-6 * p;
  const json& points = grid["points"];
  const json& displacement = grid["point_data"]["displacement"]["values"];
  const json& stress = grid["point_data"]["stress"];
  const json& von_mises = grid["point_data"]["von_mises"]["values"];
  const std::size_t nodes = points.size() / 3;
  ASSERT_GT(nodes, 10u);
  EXPECT_EQ(stress["components"], 6);
  EXPECT_EQ(stress["component_names"], json({"XX", "YY", "ZZ", "XY", "YZ", "XZ"}));
  // (XX, YY, ZZ, XY, YZ, XZ) of the exact solution
  const std::array<double, 6> exact_stress = {0.0, -p, -nu * p, 0.0, 0.0, 0.0};
  const double exact_von_mises = p * std::sqrt(1 - nu + nu * nu);
  double largest_error = 0.0;
  for (std::size_t k = 0; k < nodes; ++k) {
    const double x = points[3 * k].get<double>(), y = points[3 * k + 1].get<double>();
    const Eigen::Vector2d exact = exact_displacement(body, x, y);
    const Eigen::Vector2d computed(displacement[3 * k].get<double>(),
                                   displacement[3 * k + 1].get<double>());
    largest_error = std::max(largest_error, (computed - exact).norm());
    for (std::size_t c = 0; c < 6; ++c) {
      EXPECT_NEAR(stress["values"][6 * k + c].get<double>(), exact_stress[c], stress_tolerance)
          << "node " << k << " component " << c;
    }
    EXPECT_NEAR(von_mises[k].get<double>(), exact_von_mises, stress_tolerance) << "node " << k;
  }
  EXPECT_LE(largest_error, displacement_tolerance);

  // Cells: the area cells, then the boundary edges (VTK_LINE) with boundary_id >= 1 naming
  // boundary_names[id - 1]; the cell stress is the exact one on every cell.
  EXPECT_EQ(grid["field_data"]["boundary_names"], json(body.boundaries));
  const json& types = grid["types"];
  const json& boundary_id = grid["cell_data"]["boundary_id"]["values"];
  const json& cell_stress = grid["cell_data"]["stress"]["values"];
  const json& connectivity = grid["connectivity"];
  const json& offsets = grid["offsets"];
  const json& pressure = grid["point_data"]["contact_pressure"]["values"];
  ASSERT_EQ(boundary_id.size(), types.size());
  std::size_t contact_edges = 0;
  for (std::size_t cell = 0; cell < types.size(); ++cell) {
    const int id = boundary_id[cell].get<int>();
    EXPECT_EQ(types[cell].get<int>() == 3, id >= 1) << "cell " << cell;
    for (std::size_t c = 0; c < 6; ++c) {
      EXPECT_NEAR(cell_stress[6 * cell + c].get<double>(), exact_stress[c], stress_tolerance)
          << "cell " << cell;
    }
    if (id < 1) continue;
    // each end of an edge of boundary "contact" lies on y = 0, "bottom" on y = -0.5, etc.
    const std::string name = body.boundaries.at(static_cast<std::size_t>(id - 1));
    for (std::size_t end = 0; end < 2; ++end) {
      const std::size_t node =
          connectivity[offsets[cell].get<std::size_t>() - 2 + end].get<std::size_t>();
      const double x = points[3 * node].get<double>(), y = points[3 * node + 1].get<double>();
      if (name == "contact") {
        EXPECT_NEAR(y, 0.0, 1e-12);
        // the whole contact edge carries the uniform pressure
        EXPECT_NEAR(pressure[node].get<double>(), p, stress_tolerance) << "contact node " << node;
      } else if (name == "left") {
        EXPECT_NEAR(x, 0.0, 1e-12);
      } else if (name == "right") {
        EXPECT_NEAR(x, 1.0, 1e-12);
      } else {
        EXPECT_NEAR(y, name == "top" ? upper_height : -lower_height, 1e-12);
      }
    }
    contact_edges += name == "contact";
  }
  EXPECT_GE(contact_edges, 10u);
}

class ParaViewOutput : public ::testing::TestWithParam<const char*> {};

INSTANTIATE_TEST_SUITE_P(Tools, ParaViewOutput, ::testing::Values("robin-monolithic", "robin-run"),
                         [](const auto& info) {
                           return std::string(info.param) == "robin-run" ? "RobinRun"
                                                                         : "RobinMonolithic";
                         });

TEST_P(ParaViewOutput, PatchTestFieldsReadByVtkAreTheAnalyticSolution) {
  const TemporaryDirectory directory("paraview-output");
  const std::filesystem::path output = directory.path() / "result";
  const ProcessOutcome outcome = run_tool(
      GetParam(), {example("non_matching_blocks.toml").string(), "--output", output.string()},
      directory.path(), 300.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  const json collection = test::read_vtk_xml(output / "solution.pvd");
  ASSERT_EQ(collection["datasets"].size(), 2u);
  for (const json& dataset : collection["datasets"]) {
    const std::string file = dataset["file"].get<std::string>();
    expect_patch_solution(output / file, file == "lower.vtu" ? lower : upper);
  }
}

}  // namespace
}  // namespace robin
