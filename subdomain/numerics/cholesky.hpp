#pragma once
// Sparse Cholesky factor of a body's stiffness (CHOLMOD supernodal, through Eigen's
// CholmodSupport), computed once and reused for every solve.
//
// Trailing unknowns. The factor may be asked to eliminate a chosen set T of unknowns last
// (the free dofs of the contact boundary): P K P' = L L' with T in the last m positions.
// Then for any B whose columns lie in T, L^{-1} P B' is zero above the last block, so
//   B K^{-1} B' = Y' Y,  Y = L_TT^{-1} (P B')_T,
// with L_TT the trailing m x m block of L (L_TT L_TT' is the Schur complement of K on T).
// This costs O(m^2 n_c) dense work instead of n_c solves with the whole factor.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "numerics/elasticity.hpp"
#include "numerics/setup_progress.hpp"

namespace robin {

/// What a factorization is told besides the matrix.
struct FactorizationOptions {
  /// Eliminated last, in this order (indices into the matrix, distinct): the rest come first,
  /// in the fill-reducing order of the matrix without them (fill_reducing_ordering.hpp).
  std::vector<int> trailing_unknowns{};
  /// > 0: when the symbolic analysis finds that L needs more bytes (8 per stored entry),
  /// ResourceLimitError is thrown before the numerical factorization allocates them.
  double memory_limit_bytes = 0.0;
  /// Told when the numerical factorization begins, after the ordering and symbolic analysis
  /// (may be empty).
  SetupObserver observer{};
  /// The position of each unknown's node (one per unknown), or empty: with positions the
  /// ordering dissects the body geometrically (fill_reducing_ordering.hpp). Released once the
  /// ordering is computed.
  std::vector<Eigen::Vector3d> unknown_points{};
};

class CholeskyFactor {
 public:
  /// Factorizes the symmetric positive definite `matrix` (only its lower triangle is read).
  /// Throws SingularBodyError naming `body_name` when the matrix is not positive definite or
  /// numerically singular (pivot ratio min L_jj^2 / max L_jj^2 < 1e-13, i.e. cond > 1e13);
  /// InputError when it is empty or not square; std::bad_alloc when CHOLMOD runs out of memory;
  /// std::invalid_argument when a trailing unknown is out of range or repeated, or the points
  /// are not one per unknown. Solves are not thread-safe (CHOLMOD workspace).
  CholeskyFactor(const SparseMatrix& matrix, const std::string& body_name,
                 FactorizationOptions options = {});
  /// The same, taking the matrix: it is freed (left empty) during the numerical factorization,
  /// once CHOLMOD has its own permuted copy, so that the two are not resident beside L.
  CholeskyFactor(SparseMatrix&& matrix, const std::string& body_name,
                 FactorizationOptions options = {});
  ~CholeskyFactor();
  CholeskyFactor(const CholeskyFactor&) = delete;
  CholeskyFactor& operator=(const CholeskyFactor&) = delete;

  int size() const;
  /// x = K^{-1} b: one forward and one backward triangular solve; when b is zero outside the
  /// trailing unknowns (a trailing block exists), the forward solve is the dense L_TT's alone;
  /// b = 0 gives x = 0 without a solve.
  Eigen::VectorXd solve(const Eigen::VectorXd& right_hand_side) const;
  /// Multiple right-hand sides at once (supernodal solves in blocks of at most 64 columns).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& right_hand_sides) const;
  /// Number of entries stored in the lower triangle of the supernodal factor L (including the
  /// explicit zeros of supernode amalgamation).
  long factor_nonzeros() const;
  /// True when the trailing unknowns requested at construction occupy the last positions of
  /// the final (postordered) elimination order, so trailing_congruence() is available.
  bool has_trailing_block() const;
  /// B K^{-1} B' (symmetric, n_c x n_c) for a sparse B (n_c x size()) whose nonzero columns are
  /// all trailing unknowns, from the trailing block of L (see the file comment). Throws
  /// std::logic_error without a trailing block, std::invalid_argument when B has a nonzero
  /// outside the trailing unknowns.
  Eigen::MatrixXd trailing_congruence(const SparseMatrix& trace) const;
  /// Number of right-hand sides solved so far: +1 per vector solve, +columns per matrix solve
  /// (each right-hand side costs one forward and one backward triangular solve).
  long solve_count() const { return solve_count_; }
  /// How many of those vector solves had b zero outside the trailing unknowns (forward solve on
  /// L_TT only, one pass over L instead of two).
  long backward_only_solve_count() const { return backward_only_solve_count_; }
  /// Wall time of the fill-reducing ordering and symbolic analysis (seconds).
  double ordering_seconds() const;
  /// Wall time of the numerical factorization and its pivot checks (seconds).
  double factorization_seconds() const;

 private:
  struct Implementation;
  std::unique_ptr<Implementation> implementation_;
  mutable long solve_count_ = 0;
  mutable long backward_only_solve_count_ = 0;
};

}  // namespace robin
