#include "numerics/cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "numerics/errors.hpp"

namespace robin {
namespace {

static_assert(std::is_same_v<SparseMatrix::StorageIndex, int>,
              "the CHOLMOD factor is read with int indices (cholmod_* rather than cholmod_l_*)");

/// Right-hand sides solved together: bounds the dense workspace CHOLMOD allocates.
constexpr Eigen::Index solve_block_columns = 64;

/// Smallest accepted ratio min_j d_j / max_j d_j of the pivots d_j = L_jj^2. For an SPD
/// matrix lambda_min <= d_j <= lambda_max, so the ratio is >= 1 / cond(K): a smaller ratio
/// means cond(K) > 1e13, a stiffness with a rigid motion that rounding made "positive".
constexpr double minimum_pivot_ratio = 1e-13;

/// Eigen's supernodal LL' keeps the cholmod_factor protected; this exposes it read-only.
class SupernodalCholesky : public Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
 public:
  const cholmod_factor* factor() const { return m_cholmodFactor; }
};

/// Pivots d_j = L_jj^2 of a supernodal factor: column j of supernode s is stored in
/// x[px[s] + j * nrows + ...], the supernode block being column-major with nrows rows.
Eigen::VectorXd supernodal_pivots(const cholmod_factor& factor) {
  Eigen::VectorXd pivots(static_cast<Eigen::Index>(factor.n));
  const auto* super = static_cast<const int*>(factor.super);
  const auto* pi = static_cast<const int*>(factor.pi);
  const auto* px = static_cast<const int*>(factor.px);
  const auto* values = static_cast<const double*>(factor.x);
  for (std::size_t s = 0; s < factor.nsuper; ++s) {
    const int column_count = super[s + 1] - super[s];
    const int row_count = pi[s + 1] - pi[s];
    for (int j = 0; j < column_count; ++j) {
      const double diagonal = values[px[s] + j * row_count + j];
      pivots[super[s] + j] = diagonal * diagonal;
    }
  }
  return pivots;
}

std::string format_number(double value) {
  std::ostringstream stream;
  stream.precision(3);
  stream << value;
  return stream.str();
}

[[noreturn]] void throw_singular(const std::string& body_name, const std::string& detail) {
  throw SingularBodyError("body '" + body_name +
                          "': the stiffness matrix is not positive definite (CHOLMOD: " + detail +
                          "): the Dirichlet conditions probably leave a rigid motion free, or "
                          "the mesh has a disconnected part");
}

}  // namespace

struct CholeskyFactor::Implementation {
  SupernodalCholesky cholesky;
  std::string body_name;
  int size = 0;

  void factorize(const SparseMatrix& matrix);
  void check_pivots() const;
};

void CholeskyFactor::Implementation::factorize(const SparseMatrix& matrix) {
  cholmod_common& common = cholesky.cholmod();
  common.print = 0;                // CHOLMOD prints nothing, not even warnings
  common.error_handler = nullptr;  // failures are read from common.status instead
  common.supernodal = CHOLMOD_SUPERNODAL;
  // The fill-reducing ordering is CHOLMOD's default choice (AMD, METIS when worthwhile).
  cholesky.analyzePattern(matrix);
  if (cholesky.factor() == nullptr || common.status < CHOLMOD_OK) {
    throw std::runtime_error("body '" + body_name + "': CHOLMOD analysis failed (status " +
                             std::to_string(common.status) + ", e.g. out of memory)");
  }
  cholesky.factorize(matrix);
  const cholmod_factor& factor = *cholesky.factor();
  if (common.status < CHOLMOD_OK) {
    throw std::runtime_error("body '" + body_name + "': CHOLMOD factorization failed (status " +
                             std::to_string(common.status) + ", e.g. out of memory)");
  }
  if (cholesky.info() != Eigen::Success || common.status == CHOLMOD_NOT_POSDEF ||
      factor.minor < factor.n) {
    std::string detail = "non-positive pivot " + std::to_string(factor.minor + 1) + " of " +
                         std::to_string(factor.n);
    if (factor.Perm != nullptr && factor.minor < factor.n) {
      detail += ", equation " + std::to_string(static_cast<const int*>(factor.Perm)[factor.minor]);
    }
    throw_singular(body_name, detail);
  }
  check_pivots();
}

void CholeskyFactor::Implementation::check_pivots() const {
  const cholmod_factor& factor = *cholesky.factor();
  if (!factor.is_super) return;  // CHOLMOD_SUPERNODAL was requested: never happens
  const Eigen::VectorXd pivots = supernodal_pivots(factor);
  Eigen::Index smallest = 0;
  const double ratio = pivots.minCoeff(&smallest) / pivots.maxCoeff();
  if (!(ratio >= minimum_pivot_ratio)) {
    std::string detail = "pivot ratio " + format_number(ratio) + " < " +
                         format_number(minimum_pivot_ratio) + ", numerically singular";
    if (factor.Perm != nullptr) {
      detail +=
          " at degree of freedom " + std::to_string(static_cast<const int*>(factor.Perm)[smallest]);
    }
    throw_singular(body_name, detail);
  }
}

CholeskyFactor::CholeskyFactor(const SparseMatrix& matrix, const std::string& body_name)
    : implementation_(std::make_unique<Implementation>()) {
  implementation_->body_name = body_name;
  if (matrix.rows() != matrix.cols()) {
    throw InputError("body '" + body_name + "': the stiffness matrix is " +
                     std::to_string(matrix.rows()) + " x " + std::to_string(matrix.cols()) +
                     ", not square");
  }
  if (matrix.rows() == 0) {
    throw InputError("body '" + body_name +
                     "': the stiffness matrix is empty (every degree of freedom is prescribed)");
  }
  implementation_->size = static_cast<int>(matrix.rows());
  implementation_->factorize(matrix);
}

CholeskyFactor::~CholeskyFactor() = default;

int CholeskyFactor::size() const {
  return implementation_->size;
}

Eigen::VectorXd CholeskyFactor::solve(const Eigen::VectorXd& right_hand_side) const {
  if (right_hand_side.size() != size()) {
    throw std::invalid_argument(
        "body '" + implementation_->body_name + "': right-hand side of size " +
        std::to_string(right_hand_side.size()) + " for a factor of size " + std::to_string(size()));
  }
  // x = L^{-T} L^{-1} b (with CHOLMOD's fill-reducing permutation)
  Eigen::VectorXd solution = implementation_->cholesky.solve(right_hand_side);
  if (implementation_->cholesky.info() != Eigen::Success) {
    throw std::runtime_error("body '" + implementation_->body_name + "': CHOLMOD solve failed");
  }
  ++solve_count_;
  return solution;
}

Eigen::MatrixXd CholeskyFactor::solve(const Eigen::MatrixXd& right_hand_sides) const {
  if (right_hand_sides.rows() != size()) {
    throw std::invalid_argument("body '" + implementation_->body_name +
                                "': right-hand sides with " +
                                std::to_string(right_hand_sides.rows()) +
                                " rows for a factor of size " + std::to_string(size()));
  }
  Eigen::MatrixXd solutions(right_hand_sides.rows(), right_hand_sides.cols());
  for (Eigen::Index first = 0; first < right_hand_sides.cols(); first += solve_block_columns) {
    const Eigen::Index width = std::min(solve_block_columns, right_hand_sides.cols() - first);
    solutions.middleCols(first, width) =
        implementation_->cholesky.solve(right_hand_sides.middleCols(first, width));
    if (implementation_->cholesky.info() != Eigen::Success) {
      throw std::runtime_error("body '" + implementation_->body_name + "': CHOLMOD solve failed");
    }
    solve_count_ += width;
  }
  return solutions;
}

long CholeskyFactor::factor_nonzeros() const {
  const cholmod_factor& factor = *implementation_->cholesky.factor();
  if (!factor.is_super) {
    const auto* counts = static_cast<const int*>(factor.nz);
    long total = 0;
    for (std::size_t j = 0; j < factor.n; ++j) total += counts[j];
    return total;
  }
  // Lower trapezoid of each supernode: nrows * ncols - ncols (ncols - 1) / 2 entries,
  // counting the zeros CHOLMOD stores when it amalgamates supernodes.
  const auto* super = static_cast<const int*>(factor.super);
  const auto* pi = static_cast<const int*>(factor.pi);
  long total = 0;
  for (std::size_t s = 0; s < factor.nsuper; ++s) {
    const long column_count = super[s + 1] - super[s];
    const long row_count = pi[s + 1] - pi[s];
    total += row_count * column_count - column_count * (column_count - 1) / 2;
  }
  return total;
}

}  // namespace robin
