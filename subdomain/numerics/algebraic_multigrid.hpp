#pragma once
// Smoothed-aggregation algebraic multigrid (Vanek, Mandel, Brezina 1996) for a symmetric
// positive definite sparse matrix A with a given near-null space B (n x m: for linear
// elasticity the m rigid body modes restricted to the free dofs, m = 3 in 2D and 6 in 3D),
// used as the preconditioner of conjugate gradients (conjugate_gradient.hpp).
//
// Setup, level by level from A_0 = A, B_0 = B, until a level has at most coarse_size_limit
// unknowns (or maximum_levels is reached):
//  1. Strength of connection on the node graph: the unknowns of a node (the dofs of one mesh node
//     on the finest level, of one aggregate on the coarser ones) are one block. With node
//     positions (the mesh's; an aggregate's is the mean of its nodes'), by the distance
//     Laplacian: for the nodes i != j that A couples, w_ij = 1 / |x_i - x_j|^2, L_ii = sum_j
//     w_ij, and i, j are strongly connected when w_ij >= theta sqrt(L_ii L_jj). On a stretched
//     or graded mesh this keeps the connections across the short sides of a cell and drops those
//     along its long side, so that aggregates follow the strong coupling (semi-coarsening),
//     which the matrix entries of elasticity do not show clearly. Without positions, by the
//     block norms: ||A_ij||_F >= theta sqrt(||A_ii||_F ||A_jj||_F).
//  2. Greedy aggregation of the strong graph: (a) every node whose strong neighbours are all
//     unaggregated forms an aggregate with them; (b) each remaining node joins the aggregate of
//     (a) it is most strongly connected to; (c) the rest form aggregates with their remaining
//     strong neighbours. A node without strong neighbours is an aggregate of its own.
//  3. Tentative prolongator: for aggregate a with unknowns I_a, the QR factorization with column
//     pivoting B(I_a, :) = Q R Pi' gives the columns Q_r (r = numerical rank, at most m) of
//     P_tent on I_a, and the coarse near-null space rows R_r Pi' (r x m), so that
//     P_tent B_coarse = B exactly and P_tent has orthonormal columns.
//  4. Prolongator smoothing (damped Jacobi) with the filtered matrix A_F (the blocks A_ij of the
//     strongly connected nodes and the diagonal blocks; the weak ones dropped):
//     P = (I - omega D^{-1} A_F) P_tent, omega = (4/3) / rho(D^{-1} A_F), D = diag(A), rho
//     estimated by Lanczos on D^{-1/2} A_F D^{-1/2}. P then spreads only along strong
//     connections, which keeps the coarse operators sparse.
//  5. Galerkin coarse operator A_{l+1} = P' A_l P (symmetric positive definite: P has full
//     column rank), computed block by block (galerkin_product.hpp) with P held by blocks of a
//     node's rows against an aggregate's columns.
// The coarsest matrix is factorized by CHOLMOD (cholesky.hpp).
//
// The preconditioner M^{-1} r is one V-cycle from a zero guess: on each level, pre-smoothing by
// a Chebyshev polynomial in D^{-1} A (the same polynomial s: x = s(D^{-1}A) D^{-1} b from
// x = 0), restriction of the residual by P', the next level, prolongation by P, post-smoothing
// by the same polynomial. Both smoothing steps have the error propagation I - s(D^{-1}A) D^{-1}A,
// which is self-adjoint in the A inner product, and the coarsest solve is exact, so M^{-1} is
// symmetric; it is positive definite when the smoother converges in the A-norm, which for
// Chebyshev needs the interval's upper end to bound rho(D^{-1} A): the Lanczos estimate is a
// lower bound, hence the safety factor (AlgebraicMultigridOptions::spectrum_safety).
// The smoother is the Chebyshev iteration of degree k on [upper / ratio, upper], upper = safety x
// the estimate of rho(D^{-1} A) (Adams, Brezina, Hu, Tuminaro 2003): k products with A per
// smoothing step. The alternative smoother (MultigridSmoother::symmetric_gauss_seidel) is, with
// A = L + D + L', a forward Gauss-Seidel sweep (D + L)^{-1} before the coarse correction and a
// backward one (D + L')^{-1} after it: the post-smoother is the transpose of the pre-smoother,
// which again makes the V-cycle symmetric (and positive definite: Gauss-Seidel converges for
// SPD A).
//
// Storage. The finest matrix is kept in double by blocks of the unknowns of a node (the lower
// block triangle, block_symmetric_matrix.hpp: the products of conjugate gradients, y = A x with
// each stored entry read once for both triangles). After the setup each level keeps A_l the same
// way in single precision (blocks of a node's, then an aggregate's unknowns), P by the same
// blocks against the next level's (block_sparse_matrix.hpp) in single precision, and D^{-1}: the V-cycle sums in double, and it is the exact V-cycle
// of the rounded matrices, so still symmetric positive definite, while the products that
// conjugate gradients converge on stay in double. (Its speed is bound by memory traffic, which
// single precision, one triangle and one column index per block reduce.) With the Gauss-Seidel
// smoother a level also keeps its scalar lower triangle in single precision (the sweeps run over
// its rows). P' x is computed by scattering the block rows of P. During the setup A_l is held
// with both triangles in double; P' A P is accumulated block row by block row of A P, which is
// never formed whole, into the block lower triangle of A_{l+1}. The Lanczos estimate of
// rho(D^{-1} A_l) runs on the single-precision blocks (the smoother's own matrix). The apply allocates only the coarsest level's solution (the
// CholeskyFactor's solve); its other workspace is kept per level, so one AlgebraicMultigrid must
// not be applied from two threads at once.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "numerics/block_symmetric_matrix.hpp"
#include "numerics/conjugate_gradient.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/linear_operator.hpp"
#include "numerics/mesh.hpp"

namespace robin {

/// y = A x for a symmetric sparse matrix stored by blocks of unknowns (block_symmetric_matrix.hpp,
/// double precision): each stored entry is read once for both triangles.
class SparseMatrixOperator final : public LinearOperator {
 public:
  /// A from the lower triangle of `lower` (its upper triangle is ignored; a matrix stored with
  /// both triangles is fine), in blocks of the given `unknown_blocks` (BlockSymmetricMatrix;
  /// empty: one block per unknown).
  explicit SparseMatrixOperator(const SparseMatrix& lower,
                                const std::vector<int>& unknown_blocks = {});
  /// A from the symmetric `matrix` (both triangles stored) in the blocks of `layout`.
  SparseMatrixOperator(const RowMajorSparseMatrix& matrix, BlockLayout layout);
  int size() const override { return matrix_.size(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
  /// The lower triangle, diagonal included (column-major), rebuilt from the blocks.
  SparseMatrix lower() const { return matrix_.lower_triangle(); }
  int block_size() const { return matrix_.block_size(); }
  const BlockSymmetricMatrix<double>& blocks() const { return matrix_; }

 private:
  BlockSymmetricMatrix<double> matrix_;
};

/// The smoother of the V-cycle (the file comment).
enum class MultigridSmoother {
  chebyshev,               // the Chebyshev polynomial in D^{-1} A, pre and post
  symmetric_gauss_seidel,  // a forward Gauss-Seidel sweep before, a backward one after
};

struct AlgebraicMultigridOptions {
  MultigridSmoother smoother = MultigridSmoother::chebyshev;
  /// theta of the strength of connection (step 1 of the file comment); 0 keeps every
  /// connection of the matrix graph.
  double strength_threshold = 0.0;
  /// theta of the distance-Laplacian strength (used instead when node positions are given): 0.03
  /// keeps every neighbour of a cube-shaped hexahedron but its corner diagonals, and drops the
  /// neighbours along the long side of an interior cell stretched about 2 to 1 or more.
  double distance_strength_threshold = 0.03;
  /// The coarsest level has at most this many unknowns (or is the last of maximum_levels).
  int coarse_size_limit = 2000;
  int maximum_levels = 10;
  /// Degree of the Chebyshev smoother (products with A per smoothing step), at least 1. Degree 1
  /// is Jacobi damped by 2 / (upper + upper / ratio). It needs more PCG iterations than 2 or 3
  /// but was the fastest to 1e-10 on hexahedral elasticity (docs/benchmarks.md).
  int smoother_degree = 1;
  /// The Chebyshev interval is [upper / ratio, upper], upper = safety * the Lanczos estimate of
  /// rho(D^{-1} A).
  double smoother_interval_ratio = 30.0;
  double spectrum_safety = 1.1;
  /// Lanczos steps of the spectral radius estimates.
  int lanczos_steps = 12;
  /// omega = prolongator_damping / rho(D^{-1} A); 0 leaves P = P_tent (plain aggregation).
  double prolongator_damping = 4.0 / 3.0;
};

/// What one level holds (for reports and tests).
struct MultigridLevelSummary {
  int unknowns = 0;
  long nonzeros = 0;             // stored entries of A_l (both triangles)
  int nodes = 0;                 // blocks of unknowns (mesh nodes, then aggregates)
  // the estimate of rho(D^{-1} A_l), before the safety factor; 0 on the coarsest level (solved
  // by its factor, not smoothed)
  double spectral_radius = 0.0;
};

class AlgebraicMultigrid final : public Preconditioner {
 public:
  /// Sets the hierarchy up for the symmetric positive definite `lower` (only its lower triangle
  /// is kept; its storage is taken over), the near-null space `near_null_space` (n x m, m >= 1) and
  /// `dof_nodes` (n values: the node of each unknown; node numbers are any non-negative integers,
  /// the unknowns of one node need not be consecutive). `node_positions`, indexed by those node
  /// numbers, selects the distance-Laplacian strength of connection (step 1); empty selects the
  /// block norms. Throws std::invalid_argument on inconsistent sizes, a negative node or a node
  /// without a position, SingularBodyError (cholesky.hpp) when the coarsest matrix is not positive
  /// definite.
  AlgebraicMultigrid(SparseMatrix&& lower, const Eigen::MatrixXd& near_null_space,
                     const std::vector<int>& dof_nodes,
                     const std::vector<Eigen::Vector3d>& node_positions = {},
                     const AlgebraicMultigridOptions& options = {});
  /// The same for a copy of `lower`.
  AlgebraicMultigrid(const SparseMatrix& lower, const Eigen::MatrixXd& near_null_space,
                     const std::vector<int>& dof_nodes,
                     const std::vector<Eigen::Vector3d>& node_positions = {},
                     const AlgebraicMultigridOptions& options = {});
  ~AlgebraicMultigrid() override;
  AlgebraicMultigrid(const AlgebraicMultigrid&) = delete;
  AlgebraicMultigrid& operator=(const AlgebraicMultigrid&) = delete;

  int size() const override;
  /// correction = one V-cycle applied to residual from a zero guess (the file comment); the two
  /// must be distinct vectors.
  void apply(const Eigen::VectorXd& residual, Eigen::VectorXd& correction) const override;

  /// The finest matrix (by node blocks, double), for PCG's products.
  const SparseMatrixOperator& fine_operator() const { return *fine_operator_; }
  std::vector<MultigridLevelSummary> levels() const;
  /// sum over levels of nonzeros(A_l) / nonzeros(A_0).
  double operator_complexity() const;
  double setup_seconds() const { return setup_seconds_; }

 private:
  struct Level;
  void build_hierarchy(RowMajorSparseMatrix&& matrix, const Eigen::MatrixXd& near_null_space,
                       const std::vector<int>& dof_nodes, std::vector<Eigen::Vector3d> positions);
  void finish_level(Level& level) const;
  void cycle(std::size_t level, const Eigen::VectorXd& right_hand_side,
             Eigen::VectorXd& solution) const;
  void smooth_gauss_seidel(const Level& level, const Eigen::VectorXd& right_hand_side,
                           Eigen::VectorXd& solution, bool forward) const;
  void smooth(const Level& level, const Eigen::VectorXd& right_hand_side, Eigen::VectorXd& solution,
              bool zero_guess) const;

  AlgebraicMultigridOptions options_;
  std::unique_ptr<SparseMatrixOperator> fine_operator_;
  std::vector<std::unique_ptr<Level>> levels_;
  struct CoarseSolver;
  std::unique_ptr<CoarseSolver> coarse_solver_;
  double setup_seconds_ = 0.0;
};

}  // namespace robin
