// ordering_benchmark CASE MESH_SIZE [--factorize]
// The fill-reducing ordering of each body's stiffness, two ways, on the bodies of CASE meshed at
// MESH_SIZE (the .geo variable h):
//   dofs:  CHOLMOD's own choice (cholmod_analyze's default: AMD, then METIS when AMD fills
//          much) on the graph of the degrees of freedom, as robin-contact did before;
//   nodes: fill_reducing_ordering without the nodes' positions (AMD, and METIS when AMD's order
//          needs many flops, on the graph of the nodes), as servers did before the geometric
//          dissection and as other callers still do;
//   geometry: fill_reducing_ordering with the nodes' positions (geometric nested dissection with
//          CAMD, and METIS when that order needs very many flops), as the servers do now;
// each without and with the contact boundary's dofs eliminated last (the order the servers use
// for a dense interface operator), followed by CHOLMOD's supernodal symbolic analysis with
// that order. Prints one markdown row per body, variant and way: ordering seconds (order and
// symbolic analysis), entries of L, flops of the factorization, the supernodal factor's memory
// (values: 8 bytes per stored entry, amalgamation zeros included; integer arrays: row indices,
// supernode and column arrays, permutation), the numerical factorization's largest update matrix
// (CHOLMOD's workspace C, maxcsize doubles), and with --factorize the
// numerical factorization's seconds. The matrix is the free-free block of the stiffness (the
// Dirichlet dofs removed, as the servers do); the contact dofs are its free dofs on the contact
// boundaries. Run through benchmarks/ordering_benchmark.sh.

#include <suitesparse/cholmod.h>

#include <Eigen/CholmodSupport>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "coupling/case_file.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/fill_reducing_ordering.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

enum class Way { dofs, nodes, geometry };

const char* way_name(Way way) {
  return way == Way::dofs ? "dofs" : way == Way::nodes ? "nodes" : "geometry";
}

/// CHOLMOD's default order of the matrix without `trailing`, then `trailing`.
std::vector<int> cholmod_dof_ordering(const robin::SparseMatrix& lower,
                                      const std::vector<int>& trailing, cholmod_common& common) {
  const int size = static_cast<int>(lower.rows());
  std::vector<int> new_index(static_cast<std::size_t>(size), 0);
  for (int unknown : trailing) new_index[unknown] = -1;
  std::vector<int> leading;
  for (int unknown = 0; unknown < size; ++unknown) {
    if (new_index[unknown] < 0) continue;
    new_index[unknown] = static_cast<int>(leading.size());
    leading.push_back(unknown);
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column < lower.outerSize(); ++column) {
    for (robin::SparseMatrix::InnerIterator entry(lower, column); entry; ++entry) {
      if (new_index[entry.row()] >= 0 && new_index[column] >= 0) {
        entries.emplace_back(new_index[entry.row()], new_index[column], entry.value());
      }
    }
  }
  robin::SparseMatrix block(static_cast<int>(leading.size()), static_cast<int>(leading.size()));
  block.setFromTriplets(entries.begin(), entries.end());
  const robin::SparseMatrix& leading_block = block;
  cholmod_sparse view = Eigen::viewAsCholmod(leading_block.selfadjointView<Eigen::Lower>());
  common.supernodal = CHOLMOD_SIMPLICIAL;
  cholmod_factor* symbolic = cholmod_analyze(&view, &common);
  const auto* permutation = static_cast<const int*>(symbolic->Perm);
  std::vector<int> ordering;
  for (std::size_t k = 0; k < leading.size(); ++k) ordering.push_back(leading[permutation[k]]);
  cholmod_free_factor(&symbolic, &common);
  ordering.insert(ordering.end(), trailing.begin(), trailing.end());
  return ordering;
}

void measure(const std::string& body, const robin::SparseMatrix& lower,
             const std::vector<int>& trailing, const std::vector<Eigen::Vector3d>& points, Way way,
             bool factorize) {
  cholmod_common common;
  cholmod_start(&common);
  const auto start = Clock::now();
  const std::vector<Eigen::Vector3d> no_points;
  std::vector<int> ordering =
      way == Way::dofs
          ? cholmod_dof_ordering(lower, trailing, common)
          : robin::fill_reducing_ordering(lower, trailing,
                                          way == Way::geometry ? points : no_points, common, body);
  cholmod_sparse view = Eigen::viewAsCholmod(lower.selfadjointView<Eigen::Lower>());
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_GIVEN;
  common.supernodal = CHOLMOD_SUPERNODAL;
  cholmod_factor* factor = cholmod_analyze_p(&view, ordering.data(), nullptr, 0, &common);
  const double ordering_seconds = seconds_since(start);
  const double entries = common.lnz;
  const double mebibyte = 1024.0 * 1024.0;
  const double value_mebibytes = 8.0 * static_cast<double>(factor->xsize) / mebibyte;
  const double index_mebibytes =
      4.0 * static_cast<double>(factor->ssize + 4 * factor->nsuper + 3 * factor->n) / mebibyte;
  const double update_mebibytes = 8.0 * static_cast<double>(factor->maxcsize) / mebibyte;
  const double flops = common.fl;
  std::string factorization = "-";
  if (factorize) {
    const auto factor_start = Clock::now();
    cholmod_factorize(&view, factor, &common);
    factorization = std::to_string(seconds_since(factor_start));
    if (common.status != CHOLMOD_OK)
      factorization += " (status " + std::to_string(common.status) + ")";
  }
  std::printf("| %s | %d | %zu | %s | %.3f | %.3e | %.3e | %.1f + %.1f | %.1f | %s |\n",
              body.c_str(), static_cast<int>(lower.rows()), trailing.size(), way_name(way),
              ordering_seconds, entries, flops, value_mebibytes, index_mebibytes, update_mebibytes,
              factorization.c_str());
  std::fflush(stdout);
  cholmod_free_factor(&factor, &common);
  cholmod_finish(&common);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4 || (argc == 4 && std::strcmp(argv[3], "--factorize") != 0)) {
    std::fprintf(stderr, "usage: ordering_benchmark CASE MESH_SIZE [--factorize]\n");
    return 1;
  }
  const bool factorize = argc == 4;
  robin::CaseDefinition definition = robin::read_case_file(argv[1]);
  for (auto& body : definition.bodies) body.mesh_options.size = std::atof(argv[2]);
  robin::load_meshes(definition);
  std::printf(
      "| body | dofs | trailing dofs | graph ordered | ordering + symbolic (s) | entries of L | "
      "flops | factor values + integers (MiB) | largest update (MiB) | numerical factorization "
      "(s) |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const robin::BodyCase& body : definition.bodies) {
    const robin::Mesh& mesh = body.definition.mesh;
    std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
    for (const robin::DirichletCondition& condition : body.definition.dirichlet) {
      const std::optional<double> values[] = {condition.x, condition.y, condition.z};
      for (int node : mesh.boundary(condition.boundary).nodes()) {
        for (int component = 0; component < mesh.dimension; ++component) {
          if (values[component]) prescribed[mesh.dimension * node + component] = values[component];
        }
      }
    }
    const robin::DofMap dofs(prescribed);
    const robin::SparseMatrix lower =
        dofs.reduce_matrix(robin::assemble_stiffness(mesh, body.definition.material))
            .triangularView<Eigen::Lower>();
    std::vector<int> trailing;
    for (const std::string& name : body.definition.contact_boundaries) {
      for (int node : mesh.boundary(name).nodes()) {
        for (int component = 0; component < mesh.dimension; ++component) {
          const int free_index = dofs.free_index(mesh.dimension * node + component);
          if (free_index >= 0) trailing.push_back(free_index);
        }
      }
    }
    std::vector<Eigen::Vector3d> points;
    for (int node : robin::free_dof_nodes(mesh, dofs)) {
      points.push_back(mesh.nodes[static_cast<std::size_t>(node)]);
    }
    for (const std::vector<int>& last : {std::vector<int>{}, trailing}) {
      for (Way way : {Way::dofs, Way::nodes, Way::geometry}) {
        measure(body.definition.name, lower, last, points, way, factorize);
      }
    }
  }
  return 0;
}
