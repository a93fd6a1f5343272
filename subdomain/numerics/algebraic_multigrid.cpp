#include "numerics/algebraic_multigrid.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>

#include "numerics/cholesky.hpp"
#include "numerics/galerkin_product.hpp"

namespace robin {
namespace {

/// y = A_F x: only the entries of A (compressed, row-major) with keep[k] set.
void multiply_kept(const RowMajorSparseMatrix& matrix, const std::vector<char>& keep,
                   const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const int* starts = matrix.outerIndexPtr();
  const int* columns = matrix.innerIndexPtr();
  const double* values = matrix.valuePtr();
  const int rows = static_cast<int>(matrix.rows());
  for (int row = 0; row < rows; ++row) {
    double sum = 0.0;
    for (int k = starts[row]; k < starts[row + 1]; ++k) {
      if (keep[static_cast<std::size_t>(k)]) sum += values[k] * x[columns[k]];
    }
    y[row] = sum;
  }
}

/// The Gauss-Seidel smoother's storage of a level's lower triangle (diagonal included):
/// compressed rows in single precision.
using SinglePrecisionRows = Eigen::SparseMatrix<float, Eigen::RowMajor, int>;

/// r = b - A x; `product` is workspace.
void subtract_symmetric_product(const BlockSymmetricMatrix<float>& matrix,
                                const Eigen::VectorXd& right_hand_side, const Eigen::VectorXd& x,
                                Eigen::VectorXd& product, Eigen::VectorXd& residual) {
  matrix.multiply(x, product);
  residual = right_hand_side - product;
}

/// 1 / A_ii; throws std::invalid_argument for a diagonal entry that is not positive.
Eigen::VectorXd inverse_diagonal(const RowMajorSparseMatrix& matrix) {
  Eigen::VectorXd inverse = matrix.diagonal();
  for (Eigen::Index row = 0; row < inverse.size(); ++row) {
    if (!(inverse[row] > 0.0)) {
      throw std::invalid_argument(
          "AlgebraicMultigrid: a diagonal entry is not positive (the matrix is not positive "
          "definite)");
    }
    inverse[row] = 1.0 / inverse[row];
  }
  return inverse;
}

/// Largest eigenvalue of D^{-1} A, A given by `multiply(x, y)` (y = A x), estimated from below by
/// `steps` Lanczos steps on the symmetric D^{-1/2} A D^{-1/2} (same spectrum) from a fixed
/// pseudo-random start: the largest eigenvalue of the Lanczos tridiagonal matrix.
template <typename Multiply>
double estimate_spectral_radius(Multiply multiply, const Eigen::VectorXd& inverse_diagonal,
                                int steps) {
  const Eigen::Index size = inverse_diagonal.size();
  const Eigen::VectorXd scale = inverse_diagonal.cwiseSqrt();
  std::mt19937 generator(2026);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd current = Eigen::VectorXd::NullaryExpr(size, [&] { return uniform(generator); });
  current.normalize();
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(size), product(size), work(size);
  std::vector<double> diagonal, off_diagonal;
  double beta = 0.0;
  for (int step = 0; step < std::min<Eigen::Index>(steps, size); ++step) {
    work = scale.cwiseProduct(current);
    multiply(work, product);
    product = scale.cwiseProduct(product) - beta * previous;
    const double alpha = product.dot(current);
    product -= alpha * current;
    diagonal.push_back(alpha);
    beta = product.norm();
    if (beta <= 1e-12 * std::abs(alpha)) break;  // an invariant subspace: the Ritz values are exact
    off_diagonal.push_back(beta);
    previous = std::move(current);
    current = product / beta;
  }
  const Eigen::Index order = static_cast<Eigen::Index>(diagonal.size());
  Eigen::MatrixXd tridiagonal = Eigen::MatrixXd::Zero(order, order);
  for (Eigen::Index k = 0; k < order; ++k) {
    tridiagonal(k, k) = diagonal[static_cast<std::size_t>(k)];
    if (k + 1 < order) {
      tridiagonal(k, k + 1) = tridiagonal(k + 1, k) = off_diagonal[static_cast<std::size_t>(k)];
    }
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(tridiagonal, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

/// The strong connections of each node (step 1 of the header comment), neighbours of node i in
/// neighbours[start[i] .. start[i + 1]) with their block norms ||A_ij||_F in weights.
struct NodeGraph {
  std::vector<int> start;
  std::vector<int> neighbours;
  std::vector<double> weights;
};

/// ||A_ij||_F^2 for every node pair of the matrix graph, node by node; `visit(i, j, square)`.
template <typename Visit>
void for_each_block_norm(const RowMajorSparseMatrix& matrix, const BlockLayout& blocks,
                         Visit visit) {
  std::vector<double> accumulated(static_cast<std::size_t>(blocks.count()), 0.0);
  std::vector<int> seen_by(static_cast<std::size_t>(blocks.count()), -1);  // the last node
  std::vector<int> touched;
  for (int node = 0; node < blocks.count(); ++node) {
    for (int k = blocks.first(node); k < blocks.first(node + 1); ++k) {
      for (RowMajorSparseMatrix::InnerIterator entry(matrix,
                                                     blocks.members()[static_cast<std::size_t>(k)]);
           entry; ++entry) {
        const int other = blocks.block_of(entry.col());
        if (seen_by[other] != node) {
          seen_by[other] = node;
          accumulated[other] = 0.0;
          touched.push_back(other);
        }
        accumulated[other] += entry.value() * entry.value();
      }
    }
    for (int other : touched) visit(node, other, accumulated[other]);
    touched.clear();
  }
}

/// The node graph of `matrix` with the pairs i != j whose `strength(i, j, ||A_ij||_F^2)` is
/// positive, that value as their weight.
template <typename Strength>
NodeGraph strong_graph(const RowMajorSparseMatrix& matrix, const BlockLayout& blocks,
                       Strength strength) {
  NodeGraph graph;
  graph.start.push_back(0);
  int current = 0;
  for_each_block_norm(matrix, blocks, [&](int node, int other, double square) {
    while (current < node) {
      graph.start.push_back(static_cast<int>(graph.neighbours.size()));
      ++current;
    }
    if (other == node) return;
    const double weight = strength(node, other, square);
    if (weight > 0.0) {
      graph.neighbours.push_back(other);
      graph.weights.push_back(weight);
    }
  });
  while (current < blocks.count()) {
    graph.start.push_back(static_cast<int>(graph.neighbours.size()));
    ++current;
  }
  return graph;
}

NodeGraph strong_node_graph(const RowMajorSparseMatrix& matrix, const BlockLayout& blocks,
                            double threshold) {
  std::vector<double> diagonal_norm(static_cast<std::size_t>(blocks.count()), 0.0);
  for_each_block_norm(matrix, blocks, [&](int node, int other, double square) {
    if (node == other) diagonal_norm[node] = std::sqrt(square);
  });
  return strong_graph(matrix, blocks, [&](int node, int other, double square) {
    const double norm = std::sqrt(square);
    return norm >= threshold * std::sqrt(diagonal_norm[node] * diagonal_norm[other]) ? norm : 0.0;
  });
}

/// The position of each node block: `positions` indexed by the node numbers of `nodes` (the
/// level's node of each unknown), read at each block's first unknown.
std::vector<Eigen::Vector3d> block_positions(const BlockLayout& blocks,
                                             const std::vector<int>& nodes,
                                             const std::vector<Eigen::Vector3d>& positions) {
  std::vector<Eigen::Vector3d> result(static_cast<std::size_t>(blocks.count()));
  for (int block = 0; block < blocks.count(); ++block) {
    const int unknown = blocks.members()[static_cast<std::size_t>(blocks.first(block))];
    result[static_cast<std::size_t>(block)] =
        positions[static_cast<std::size_t>(nodes[static_cast<std::size_t>(unknown)])];
  }
  return result;
}

/// The strong connections by the distance Laplacian (step 1 of the header comment), with the
/// weights w_ij in graph.weights.
NodeGraph distance_node_graph(const RowMajorSparseMatrix& matrix, const BlockLayout& blocks,
                              const std::vector<Eigen::Vector3d>& positions, double threshold) {
  const auto weight = [&](int node, int other) {
    const double square =
        (positions[static_cast<std::size_t>(node)] - positions[static_cast<std::size_t>(other)])
            .squaredNorm();
    return square > 0.0 ? 1.0 / square : std::numeric_limits<double>::infinity();
  };
  std::vector<double> diagonal(static_cast<std::size_t>(blocks.count()), 0.0);
  for_each_block_norm(matrix, blocks, [&](int node, int other, double) {
    if (node != other) diagonal[static_cast<std::size_t>(node)] += weight(node, other);
  });
  return strong_graph(matrix, blocks, [&](int node, int other, double square) {
    if (square == 0.0) return 0.0;
    const double strength = weight(node, other);
    return strength >= threshold * std::sqrt(diagonal[static_cast<std::size_t>(node)] *
                                             diagonal[static_cast<std::size_t>(other)])
               ? strength
               : 0.0;
  });
}

/// The position of each aggregate: the mean of its nodes' positions.
std::vector<Eigen::Vector3d> aggregate_positions(const std::vector<int>& aggregate,
                                                 int aggregate_count,
                                                 const std::vector<Eigen::Vector3d>& positions) {
  std::vector<Eigen::Vector3d> sums(static_cast<std::size_t>(aggregate_count),
                                    Eigen::Vector3d::Zero());
  std::vector<int> counts(static_cast<std::size_t>(aggregate_count), 0);
  for (std::size_t node = 0; node < aggregate.size(); ++node) {
    sums[static_cast<std::size_t>(aggregate[node])] += positions[node];
    ++counts[static_cast<std::size_t>(aggregate[node])];
  }
  for (std::size_t group = 0; group < sums.size(); ++group) sums[group] /= counts[group];
  return sums;
}

/// Per stored entry of A (row-major order), whether its two nodes are the same or strongly
/// connected in `graph`: the entries of the filtered matrix A_F.
std::vector<char> strong_entries(const RowMajorSparseMatrix& matrix, const BlockLayout& blocks,
                                 const NodeGraph& graph) {
  std::vector<char> keep(static_cast<std::size_t>(matrix.nonZeros()), 0);
  std::vector<int> strong_for(static_cast<std::size_t>(blocks.count()), -1);
  const int* starts = matrix.outerIndexPtr();
  const int* columns = matrix.innerIndexPtr();
  for (int node = 0; node < blocks.count(); ++node) {
    strong_for[static_cast<std::size_t>(node)] = node;
    for (int k = graph.start[node]; k < graph.start[node + 1]; ++k) {
      strong_for[static_cast<std::size_t>(graph.neighbours[k])] = node;
    }
    for (int k = blocks.first(node); k < blocks.first(node + 1); ++k) {
      const int row = blocks.members()[static_cast<std::size_t>(k)];
      for (int entry = starts[row]; entry < starts[row + 1]; ++entry) {
        const int other = blocks.block_of(columns[entry]);
        keep[static_cast<std::size_t>(entry)] = strong_for[static_cast<std::size_t>(other)] == node;
      }
    }
  }
  return keep;
}

/// Greedy aggregation (step 2 of the header comment): the aggregate of each node, and their count.
std::pair<std::vector<int>, int> aggregate_nodes(const NodeGraph& graph) {
  const int nodes = static_cast<int>(graph.start.size()) - 1;
  std::vector<int> aggregate(static_cast<std::size_t>(nodes), -1);
  int count = 0;
  for (int node = 0; node < nodes; ++node) {  // (a) whole free neighbourhoods
    bool free = aggregate[node] < 0;
    for (int k = graph.start[node]; free && k < graph.start[node + 1]; ++k) {
      free = aggregate[graph.neighbours[k]] < 0;
    }
    if (!free) continue;
    aggregate[node] = count;
    for (int k = graph.start[node]; k < graph.start[node + 1]; ++k) {
      aggregate[graph.neighbours[k]] = count;
    }
    ++count;
  }
  const std::vector<int> first = aggregate;
  for (int node = 0; node < nodes; ++node) {  // (b) join the strongest neighbouring aggregate
    if (aggregate[node] >= 0) continue;
    double strongest = -1.0;
    for (int k = graph.start[node]; k < graph.start[node + 1]; ++k) {
      if (first[graph.neighbours[k]] >= 0 && graph.weights[k] > strongest) {
        strongest = graph.weights[k];
        aggregate[node] = first[graph.neighbours[k]];
      }
    }
  }
  for (int node = 0; node < nodes; ++node) {  // (c) the rest with their remaining neighbours
    if (aggregate[node] >= 0) continue;
    aggregate[node] = count;
    for (int k = graph.start[node]; k < graph.start[node + 1]; ++k) {
      if (aggregate[graph.neighbours[k]] < 0) aggregate[graph.neighbours[k]] = count;
    }
    ++count;
  }
  return {aggregate, count};
}

/// P_tent, the coarse near-null space and the aggregate of each coarse unknown (step 3).
struct TentativeProlongator {
  RowMajorSparseMatrix prolongator;
  Eigen::MatrixXd coarse_near_null_space;
  std::vector<int> coarse_nodes;
};

TentativeProlongator tentative_prolongator(const BlockLayout& blocks,
                                           const std::vector<int>& aggregate, int aggregate_count,
                                           const Eigen::MatrixXd& near_null_space) {
  std::vector<int> dof_aggregate(static_cast<std::size_t>(blocks.size()));
  for (std::size_t unknown = 0; unknown < dof_aggregate.size(); ++unknown) {
    dof_aggregate[unknown] =
        aggregate[static_cast<std::size_t>(blocks.block_of(static_cast<int>(unknown)))];
  }
  const BlockLayout members(dof_aggregate);  // unknowns per aggregate
  const Eigen::Index modes = near_null_space.cols();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(blocks.size() * modes));
  std::vector<Eigen::MatrixXd> coarse_rows;
  TentativeProlongator result;
  int columns = 0;
  for (int group = 0; group < aggregate_count; ++group) {
    const int first = members.first(group), rows = members.first(group + 1) - first;
    Eigen::MatrixXd local(rows, modes);
    for (int k = 0; k < rows; ++k)
      local.row(k) = near_null_space.row(members.members()[static_cast<std::size_t>(first + k)]);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(local);
    qr.setThreshold(1e-10);
    const int rank = std::max<int>(1, static_cast<int>(qr.rank()));
    const Eigen::MatrixXd basis = qr.householderQ() * Eigen::MatrixXd::Identity(rows, rank);
    const Eigen::MatrixXd upper =
        qr.matrixR().topRows(rank).triangularView<Eigen::Upper>().toDenseMatrix();
    coarse_rows.push_back(upper * qr.colsPermutation().transpose());
    for (int k = 0; k < rows; ++k) {
      for (int c = 0; c < rank; ++c) {
        entries.emplace_back(members.members()[static_cast<std::size_t>(first + k)], columns + c,
                             basis(k, c));
      }
    }
    for (int c = 0; c < rank; ++c) result.coarse_nodes.push_back(group);
    columns += rank;
  }
  result.prolongator.resize(blocks.size(), columns);
  result.prolongator.setFromTriplets(entries.begin(), entries.end());
  result.coarse_near_null_space.resize(columns, modes);
  for (int group = 0, row = 0; group < aggregate_count; ++group) {
    const Eigen::MatrixXd& rows = coarse_rows[static_cast<std::size_t>(group)];
    result.coarse_near_null_space.middleRows(row, rows.rows()) = rows;
    row += static_cast<int>(rows.rows());
  }
  return result;
}

/// P = (I - omega D^{-1} A_F) P_tent (step 4), A_F the entries of A with keep[k] set, row by
/// row with a sparse accumulator (P_tent has one aggregate's columns per row): a first pass
/// counts each row's entries, a second writes them into P's exact storage.
RowMajorSparseMatrix smooth_prolongator(const RowMajorSparseMatrix& matrix,
                                        const std::vector<char>& keep,
                                        const Eigen::VectorXd& inverse_diagonal, double omega,
                                        const RowMajorSparseMatrix& tentative) {
  const Eigen::Index rows = matrix.rows(), columns = tentative.cols();
  std::vector<double> accumulated(static_cast<std::size_t>(columns), 0.0);
  std::vector<Eigen::Index> last_row(static_cast<std::size_t>(columns), -1);
  std::vector<int> row_columns;
  const auto add = [&](Eigen::Index row, int column, double value) {
    if (last_row[static_cast<std::size_t>(column)] != row) {
      last_row[static_cast<std::size_t>(column)] = row;
      accumulated[static_cast<std::size_t>(column)] = 0.0;
      row_columns.push_back(column);
    }
    accumulated[static_cast<std::size_t>(column)] += value;
  };
  const auto accumulate_row = [&](Eigen::Index row) {  // row_columns and accumulated
    row_columns.clear();
    const double factor = -omega * inverse_diagonal[row];
    for (int k = matrix.outerIndexPtr()[row]; k < matrix.outerIndexPtr()[row + 1]; ++k) {
      if (!keep[static_cast<std::size_t>(k)]) continue;
      const double scaled = factor * matrix.valuePtr()[k];
      for (RowMajorSparseMatrix::InnerIterator entry(tentative, matrix.innerIndexPtr()[k]); entry;
           ++entry) {
        add(row, static_cast<int>(entry.col()), scaled * entry.value());
      }
    }
    for (RowMajorSparseMatrix::InnerIterator entry(tentative, row); entry; ++entry) {
      add(row, static_cast<int>(entry.col()), entry.value());
    }
  };
  RowMajorSparseMatrix smoothed(rows, columns);
  int* starts = smoothed.outerIndexPtr();
  starts[0] = 0;
  for (Eigen::Index row = 0; row < rows; ++row) {
    accumulate_row(row);
    starts[row + 1] = starts[row] + static_cast<int>(row_columns.size());
  }
  std::fill(last_row.begin(), last_row.end(), -1);
  smoothed.resizeNonZeros(starts[rows]);
  for (Eigen::Index row = 0; row < rows; ++row) {
    accumulate_row(row);
    std::sort(row_columns.begin(), row_columns.end());
    int position = smoothed.outerIndexPtr()[row];
    for (int column : row_columns) {
      smoothed.innerIndexPtr()[position] = column;
      smoothed.valuePtr()[position++] = accumulated[static_cast<std::size_t>(column)];
    }
  }
  return smoothed;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

SparseMatrixOperator::SparseMatrixOperator(const SparseMatrix& lower,
                                           const std::vector<int>& unknown_blocks)
    : matrix_(lower.rows() == lower.cols()
                  ? RowMajorSparseMatrix(lower.selfadjointView<Eigen::Lower>())
                  : throw std::invalid_argument("SparseMatrixOperator: the matrix is not square"),
              unknown_blocks) {}

SparseMatrixOperator::SparseMatrixOperator(const RowMajorSparseMatrix& matrix, BlockLayout layout)
    : matrix_(matrix, std::move(layout)) {}

void SparseMatrixOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  matrix_.multiply(x, y);
}

struct AlgebraicMultigrid::Level {
  RowMajorSparseMatrix matrix;  // A_l, both triangles (during the setup only)
  Eigen::VectorXd inverse_diagonal;
  // what the V-cycle reads, in single precision: A_l and P by blocks (P empty on the coarsest
  // level), and for the Gauss-Seidel smoother the scalar lower triangle of A_l
  BlockSymmetricMatrix<float> blocks;
  BlockSparseMatrix<float> prolongation;
  SinglePrecisionRows lower;
  int unknowns = 0;
  long nonzeros = 0;  // of A_l, both triangles
  int nodes = 0;
  double spectral_radius = 0.0;
  double interval_low = 0.0, interval_high = 0.0;  // the Chebyshev interval
  // workspace of apply
  mutable Eigen::VectorXd residual, update, product, coarse_right_hand_side, coarse_solution;
};

struct AlgebraicMultigrid::CoarseSolver {
  std::unique_ptr<CholeskyFactor> factor;
};

AlgebraicMultigrid::AlgebraicMultigrid(const SparseMatrix& lower,
                                       const Eigen::MatrixXd& near_null_space,
                                       const std::vector<int>& dof_nodes,
                                       const std::vector<Eigen::Vector3d>& node_positions,
                                       const AlgebraicMultigridOptions& options)
    : AlgebraicMultigrid(SparseMatrix(lower), near_null_space, dof_nodes, node_positions, options) {
}

AlgebraicMultigrid::AlgebraicMultigrid(SparseMatrix&& lower, const Eigen::MatrixXd& near_null_space,
                                       const std::vector<int>& dof_nodes,
                                       const std::vector<Eigen::Vector3d>& node_positions,
                                       const AlgebraicMultigridOptions& options)
    : options_(options) {
  const auto start = std::chrono::steady_clock::now();
  if (lower.rows() != lower.cols()) {
    throw std::invalid_argument("AlgebraicMultigrid: the matrix is not square");
  }
  if (near_null_space.rows() != lower.rows() || near_null_space.cols() < 1 ||
      static_cast<Eigen::Index>(dof_nodes.size()) != lower.rows()) {
    throw std::invalid_argument(
        "AlgebraicMultigrid: the near-null space or the dof nodes do not match the matrix");
  }
  if (options_.smoother_degree < 1) {
    throw std::invalid_argument("AlgebraicMultigrid: smoother_degree below 1");
  }
  for (int node : dof_nodes) {
    if (node < 0) throw std::invalid_argument("AlgebraicMultigrid: a negative node number");
    if (!node_positions.empty() && node >= static_cast<int>(node_positions.size())) {
      throw std::invalid_argument("AlgebraicMultigrid: a dof's node has no position");
    }
  }
  RowMajorSparseMatrix matrix = lower.selfadjointView<Eigen::Lower>();
  SparseMatrix().swap(lower);  // freed: the blocks and the levels hold A from here
  build_hierarchy(std::move(matrix), near_null_space, dof_nodes, node_positions);
  setup_seconds_ = seconds_since(start);
}

AlgebraicMultigrid::~AlgebraicMultigrid() = default;

/// Keeps of a set-up level what the V-cycle reads besides A_l by blocks (A_l's scalar lower
/// triangle for the Gauss-Seidel smoother, in single precision) and frees A_l in double precision.
void AlgebraicMultigrid::finish_level(Level& level) const {
  if (options_.smoother == MultigridSmoother::symmetric_gauss_seidel) {
    level.lower = level.matrix.triangularView<Eigen::Lower>().cast<float>();
    level.lower.makeCompressed();
  }
  RowMajorSparseMatrix().swap(level.matrix);  // swapped out: assignment would keep the storage
}

void AlgebraicMultigrid::build_hierarchy(RowMajorSparseMatrix&& fine_matrix,
                                         const Eigen::MatrixXd& near_null_space,
                                         const std::vector<int>& dof_nodes,
                                         std::vector<Eigen::Vector3d> positions) {
  Eigen::MatrixXd modes = near_null_space;
  std::vector<int> nodes = dof_nodes;
  auto level = std::make_unique<Level>();
  level->matrix.swap(fine_matrix);
  fine_operator_ = std::make_unique<SparseMatrixOperator>(level->matrix,
                                                          BlockLayout(consecutive_numbers(nodes)));
  while (true) {
    const RowMajorSparseMatrix& matrix = level->matrix;
    const int unknowns = static_cast<int>(matrix.rows());
    level->unknowns = unknowns;
    level->nonzeros = static_cast<long>(matrix.nonZeros());
    level->inverse_diagonal = inverse_diagonal(matrix);
    if (unknowns <= options_.coarse_size_limit ||
        static_cast<int>(levels_.size()) + 1 >= options_.maximum_levels) {
      break;
    }
    BlockLayout blocks(consecutive_numbers(nodes));
    level->nodes = blocks.count();
    level->blocks = levels_.empty() ? BlockSymmetricMatrix<float>(fine_operator_->blocks())
                                    : BlockSymmetricMatrix<float>(matrix, blocks);
    level->spectral_radius = estimate_spectral_radius(
        [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) { level->blocks.multiply(x, y); },
        level->inverse_diagonal, options_.lanczos_steps);
    level->interval_high = options_.spectrum_safety * level->spectral_radius;
    level->interval_low = level->interval_high / options_.smoother_interval_ratio;
    level->residual.resize(unknowns);
    level->update.resize(unknowns);
    level->product.resize(unknowns);
    std::vector<Eigen::Vector3d> positions_of_blocks;
    if (!positions.empty()) positions_of_blocks = block_positions(blocks, nodes, positions);
    const NodeGraph graph = positions.empty()
                                ? strong_node_graph(matrix, blocks, options_.strength_threshold)
                                : distance_node_graph(matrix, blocks, positions_of_blocks,
                                                      options_.distance_strength_threshold);
    const auto [aggregate, aggregate_count] = aggregate_nodes(graph);
    TentativeProlongator tentative =
        tentative_prolongator(blocks, aggregate, aggregate_count, modes);
    if (tentative.prolongator.cols() >= unknowns) break;  // no coarsening: this is the coarsest
    if (!positions.empty()) {
      positions = aggregate_positions(aggregate, aggregate_count, positions_of_blocks);
    }
    RowMajorSparseMatrix prolongator;
    if (options_.prolongator_damping > 0.0) {
      const std::vector<char> keep = strong_entries(matrix, blocks, graph);
      const double omega =
          options_.prolongator_damping /
          estimate_spectral_radius([&](const Eigen::VectorXd& x,
                                       Eigen::VectorXd& y) { multiply_kept(matrix, keep, x, y); },
                                   level->inverse_diagonal, options_.lanczos_steps);
      prolongator =
          smooth_prolongator(matrix, keep, level->inverse_diagonal, omega, tentative.prolongator);
    } else {
      prolongator.swap(tentative.prolongator);  // Eigen 3.4: no move assignment
    }
    RowMajorSparseMatrix().swap(tentative.prolongator);
    const BlockSparseMatrix<double> block_prolongator(prolongator, std::move(blocks),
                                                      BlockLayout(tentative.coarse_nodes));
    RowMajorSparseMatrix().swap(prolongator);
    auto coarse = std::make_unique<Level>();
    coarse->matrix = galerkin_product(matrix, block_prolongator);
    level->prolongation = BlockSparseMatrix<float>(block_prolongator);
    level->coarse_right_hand_side.resize(coarse->matrix.rows());
    level->coarse_solution.resize(coarse->matrix.rows());
    modes = std::move(tentative.coarse_near_null_space);
    nodes = std::move(tentative.coarse_nodes);
    finish_level(*level);
    levels_.push_back(std::move(level));
    level = std::move(coarse);
  }
  // the coarsest level: solved by its Cholesky factor, no blocks or smoother
  level->nodes = BlockLayout(consecutive_numbers(nodes)).count();
  const SparseMatrix coarsest = SparseMatrix(level->matrix).triangularView<Eigen::Lower>();
  RowMajorSparseMatrix().swap(level->matrix);
  levels_.push_back(std::move(level));
  coarse_solver_ = std::make_unique<CoarseSolver>();
  coarse_solver_->factor = std::make_unique<CholeskyFactor>(coarsest, "coarsest multigrid level");
}

int AlgebraicMultigrid::size() const {
  return fine_operator_->size();
}

void AlgebraicMultigrid::apply(const Eigen::VectorXd& residual, Eigen::VectorXd& correction) const {
  if (residual.size() != size()) {
    throw std::invalid_argument("AlgebraicMultigrid::apply: the vector's size differs");
  }
  correction.resize(size());
  cycle(0, residual, correction);
}

void AlgebraicMultigrid::cycle(std::size_t index, const Eigen::VectorXd& right_hand_side,
                               Eigen::VectorXd& solution) const {
  const Level& level = *levels_[index];
  if (index + 1 == levels_.size()) {
    solution = coarse_solver_->factor->solve(right_hand_side);
    return;
  }
  if (options_.smoother == MultigridSmoother::chebyshev) {
    smooth(level, right_hand_side, solution, true);
  } else {
    smooth_gauss_seidel(level, right_hand_side, solution, true);
  }
  subtract_symmetric_product(level.blocks, right_hand_side, solution, level.product,
                             level.residual);
  level.prolongation.multiply_transpose(level.residual, level.coarse_right_hand_side);
  cycle(index + 1, level.coarse_right_hand_side, level.coarse_solution);
  level.prolongation.multiply(level.coarse_solution, level.product);
  solution += level.product;
  if (options_.smoother == MultigridSmoother::chebyshev) {
    smooth(level, right_hand_side, solution, false);
  } else {
    smooth_gauss_seidel(level, right_hand_side, solution, false);
  }
}

/// One Gauss-Seidel sweep over the rows, ascending (forward, the pre-smoother: from x = 0) or
/// descending (the post-smoother, from the given x): x_i += (b_i - sum_j A_ij x_j) / A_ii, with
/// the x_j already updated in this sweep. From the lower triangle: the row i holds A_ij for
/// j <= i; the forward sweep needs no other terms (x_j = 0 for j > i), the backward one sums the
/// terms of the updated x_j, j > i, in `level.update` by scattering each row once it is updated.
void AlgebraicMultigrid::smooth_gauss_seidel(const Level& level,
                                             const Eigen::VectorXd& right_hand_side,
                                             Eigen::VectorXd& solution, bool forward) const {
  const int* starts = level.lower.outerIndexPtr();
  const int* columns = level.lower.innerIndexPtr();
  const float* values = level.lower.valuePtr();
  const int rows = static_cast<int>(level.lower.rows());
  if (forward) solution.setZero();
  double* x = solution.data();
  double* other_triangle = level.update.data();
  level.update.setZero();
  for (int step = 0; step < rows; ++step) {
    const int row = forward ? step : rows - 1 - step;
    double sum = right_hand_side[row] - other_triangle[row];
    for (int k = starts[row]; k < starts[row + 1]; ++k) sum -= values[k] * x[columns[k]];
    x[row] += sum * level.inverse_diagonal[row];
    if (!forward) {
      for (int k = starts[row]; k < starts[row + 1]; ++k) {
        if (columns[k] != row) other_triangle[columns[k]] += values[k] * x[row];
      }
    }
  }
}

/// Chebyshev iteration for D^{-1} A x = D^{-1} b on [low, high] (Saad, Iterative Methods for
/// Sparse Linear Systems, Algorithm 12.1): theta = (high + low) / 2, delta = (high - low) / 2,
/// sigma = theta / delta; d_0 = D^{-1} r_0 / theta, and for k >= 1 with rho_0 = 1 / sigma,
/// rho_k = 1 / (2 sigma - rho_{k-1}): d_k = rho_k rho_{k-1} d_{k-1} + (2 rho_k / delta) D^{-1} r_k,
/// x_{k+1} = x_k + d_k, r_{k+1} = r_k - A d_k.
void AlgebraicMultigrid::smooth(const Level& level, const Eigen::VectorXd& right_hand_side,
                                Eigen::VectorXd& solution, bool zero_guess) const {
  const double theta = 0.5 * (level.interval_high + level.interval_low);
  const double delta = 0.5 * (level.interval_high - level.interval_low);
  const double sigma = theta / delta;
  Eigen::VectorXd& residual = level.residual;
  Eigen::VectorXd& update = level.update;
  if (zero_guess) {
    residual = right_hand_side;
  } else {
    subtract_symmetric_product(level.blocks, right_hand_side, solution, level.product, residual);
  }
  update = level.inverse_diagonal.cwiseProduct(residual) / theta;
  if (zero_guess) {
    solution = update;
  } else {
    solution += update;
  }
  double rho = 1.0 / sigma;
  for (int step = 1; step < options_.smoother_degree; ++step) {
    level.blocks.multiply(update, level.product);
    residual -= level.product;
    const double next_rho = 1.0 / (2.0 * sigma - rho);
    update = (next_rho * rho) * update +
             (2.0 * next_rho / delta) * level.inverse_diagonal.cwiseProduct(residual);
    solution += update;
    rho = next_rho;
  }
}

std::vector<MultigridLevelSummary> AlgebraicMultigrid::levels() const {
  std::vector<MultigridLevelSummary> summaries;
  for (const auto& level : levels_) {
    MultigridLevelSummary summary;
    summary.unknowns = level->unknowns;
    summary.nonzeros = level->nonzeros;
    summary.nodes = level->nodes;
    summary.spectral_radius = level->spectral_radius;
    summaries.push_back(summary);
  }
  return summaries;
}

double AlgebraicMultigrid::operator_complexity() const {
  double total = 0.0;
  for (const auto& level : levels_) total += static_cast<double>(level->nonzeros);
  return total / static_cast<double>(levels_.front()->nonzeros);
}

}  // namespace robin
