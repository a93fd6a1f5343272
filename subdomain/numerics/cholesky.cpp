#include "numerics/cholesky.hpp"

#include <cblas.h>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <new>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "numerics/errors.hpp"
#include "numerics/fill_reducing_ordering.hpp"

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

/// Eigen's supernodal LL' keeps the cholmod_factor protected; this exposes it read-only and
/// adds the symbolic analysis with a given elimination order (cholmod_analyze_p).
class SupernodalCholesky : public Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
 public:
  const cholmod_factor* factor() const { return m_cholmodFactor; }

  /// analyzePattern() with `ordering` (ordering[k] = unknown eliminated k-th) instead of
  /// CHOLMOD's own choice; CHOLMOD may still postorder it (the final order is factor()->Perm).
  void analyze_pattern_ordered(const SparseMatrix& matrix, std::vector<int>& ordering) {
    cholmod_common& common = cholmod();
    if (m_cholmodFactor != nullptr) cholmod_free_factor(&m_cholmodFactor, &common);
    cholmod_sparse view = Eigen::viewAsCholmod(matrix.selfadjointView<Eigen::Lower>());
    const int method_count = common.nmethods;
    const int first_method = common.method[0].ordering;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_GIVEN;
    m_cholmodFactor = cholmod_analyze_p(&view, ordering.data(), nullptr, 0, &common);
    common.nmethods = method_count;
    common.method[0].ordering = first_method;
    m_isInitialized = true;
    m_info = Eigen::Success;
    m_analysisIsOk = true;
    m_factorizationIsOk = false;
  }

  /// factorize(matrix), freeing `matrix` as soon as CHOLMOD holds its own permuted copy, so the
  /// two are not resident beside L. The steps of cholmod_factorize_p for a supernodal factor of
  /// a lower-stored matrix (final_asis, no shift): S = tril(P A P') by two transposes (S = A
  /// for the natural order), then cholmod_super_numeric; the same S, hence the same L.
  void factorize_releasing(SparseMatrix& matrix) {
    cholmod_common& common = cholmod();
    cholmod_factor* factor = m_cholmodFactor;
    common.status = CHOLMOD_OK;
    cholmod_sparse* permuted = nullptr;
    if (factor->ordering != CHOLMOD_NATURAL) {
      cholmod_sparse view =
          Eigen::viewAsCholmod(std::as_const(matrix).selfadjointView<Eigen::Lower>());
      cholmod_sparse* upper = cholmod_ptranspose(&view, 2, static_cast<int*>(factor->Perm), nullptr,
                                                 0, &common);  // triu(P A P')
      SparseMatrix().swap(matrix);  // frees it (Eigen's assignment would keep the storage)
      if (upper != nullptr) permuted = cholmod_ptranspose(upper, 2, nullptr, nullptr, 0, &common);
      cholmod_free_sparse(&upper, &common);
    }
    if (common.status == CHOLMOD_OK) {
      cholmod_sparse view =
          Eigen::viewAsCholmod(std::as_const(matrix).selfadjointView<Eigen::Lower>());
      double no_shift[2] = {0.0, 0.0};
      cholmod_super_numeric(permuted != nullptr ? permuted : &view, nullptr, no_shift, factor,
                            &common);
    }
    cholmod_free_sparse(&permuted, &common);
    SparseMatrix().swap(matrix);
    m_info = factor->minor == factor->n ? Eigen::Success : Eigen::NumericalIssue;
    m_factorizationIsOk = true;
  }
};

/// The trailing block L(first:, first:) of a supernodal LL' factor, dense lower triangular.
/// Supernode s holds columns super[s] .. super[s+1]-1 as a column-major block of nrows rows
/// (row indices s[pi[s]] ...), starting at x[px[s]]; its first ncols rows are its own columns.
Eigen::MatrixXd trailing_factor_block(const cholmod_factor& factor, int first) {
  const int size = static_cast<int>(factor.n);
  const auto* super = static_cast<const int*>(factor.super);
  const auto* pi = static_cast<const int*>(factor.pi);
  const auto* px = static_cast<const int*>(factor.px);
  const auto* rows = static_cast<const int*>(factor.s);
  const auto* values = static_cast<const double*>(factor.x);
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(size - first, size - first);
  for (std::size_t s = 0; s < factor.nsuper; ++s) {
    if (super[s + 1] <= first) continue;
    const int row_count = pi[s + 1] - pi[s];
    for (int column = std::max(super[s], first); column < super[s + 1]; ++column) {
      const int local = column - super[s];
      const double* entries = values + px[s] + static_cast<long>(local) * row_count;
      for (int r = local; r < row_count; ++r) {
        block(rows[pi[s] + r] - first, column - first) = entries[r];
      }
    }
  }
  return block;
}

/// X' X for X = L^{-1} Y, with L the trailing block (lower triangular, n x n) and Y (n x m)
/// whose column k is zero above row top[order[k]] (nondecreasing in k): the lower triangle of
/// the result, in Y's column order. Column blocks of `width` are solved from their first
/// nonzero row down (X is zero above it, rows below it need only L's trailing part), and each
/// block's products skip the rows where it is zero: a third of the flops of a dense
/// dtrsm and dsyrk when the tops spread evenly. BLAS level 3 (the system's, OpenBLAS on
/// Debian with libopenblas0).
Eigen::MatrixXd staircase_congruence(const Eigen::MatrixXd& lower, Eigen::MatrixXd& y,
                                     const std::vector<int>& order, const std::vector<int>& top) {
  constexpr int width = 64;
  const int n = static_cast<int>(lower.rows());
  const int m = static_cast<int>(y.cols());
  const auto block_top = [&](int start) { return top[static_cast<std::size_t>(order[start])]; };
  for (int start = 0; start < m; start += width) {
    const int count = std::min(width, m - start);
    const int from = block_top(start);
    if (from >= n) continue;  // rows of B without a trailing entry: zero columns
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, n - from, count,
                1.0, lower.data() + from + static_cast<long>(from) * n, n,
                y.data() + from + static_cast<long>(start) * n, n);
  }
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(m, m);
  for (int start = 0; start < m; start += width) {
    const int count = std::min(width, m - start);
    const int from = block_top(start);
    if (from >= n) continue;
    const double* block = y.data() + from + static_cast<long>(start) * n;
    // the diagonal block, then the block row left of it: X_J' X_I over the rows from J's top
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, count, n - from, 1.0, block, n, 0.0,
                result.data() + start + static_cast<long>(start) * m, m);
    if (start > 0) {
      cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, count, start, n - from, 1.0, block, n,
                  y.data() + from, n, 0.0, result.data() + start, m);
    }
  }
  return result;
}

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

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
  int trailing_count = 0;
  bool has_trailing_block = false;
  std::vector<int> position;  // position[j] = step at which unknown j is eliminated

  double memory_limit_bytes = 0.0;
  double ordering_seconds = 0.0;
  double factorization_seconds = 0.0;

  void factorize(SparseMatrix& matrix, FactorizationOptions& options);
  void check_memory_estimate();
  void check_pivots() const;
  void locate_trailing(const std::vector<int>& trailing);
  bool within_trailing_block(const Eigen::VectorXd& right_hand_side) const;
  Eigen::VectorXd solve_from_trailing_block(const Eigen::VectorXd& right_hand_side);
};

/// CHOLMOD reports an allocation it could not make as a status, not an exception: rethrown as
/// std::bad_alloc, so that callers handle it as any other exhausted memory.
void throw_if_out_of_memory(const cholmod_common& common) {
  if (common.status == CHOLMOD_OUT_OF_MEMORY) throw std::bad_alloc();
}

void CholeskyFactor::Implementation::factorize(SparseMatrix& matrix,
                                               FactorizationOptions& options) {
  const std::vector<int>& trailing = options.trailing_unknowns;
  auto start = std::chrono::steady_clock::now();
  cholmod_common& common = cholesky.cholmod();
  common.print = 0;                // CHOLMOD prints nothing, not even warnings
  common.error_handler = nullptr;  // failures are read from common.status instead
  common.supernodal = CHOLMOD_SUPERNODAL;
  std::vector<int> ordering =
      fill_reducing_ordering(matrix, trailing, options.unknown_points, common, body_name);
  std::vector<Eigen::Vector3d>().swap(options.unknown_points);
  cholesky.analyze_pattern_ordered(matrix, ordering);
  if (cholesky.factor() == nullptr || common.status < CHOLMOD_OK) {
    throw_if_out_of_memory(common);
    throw std::runtime_error("body '" + body_name + "': CHOLMOD analysis failed (status " +
                             std::to_string(common.status) + ", e.g. out of memory)");
  }
  check_memory_estimate();
  // The analysis's workspace (several integers per unknown) is not needed beside L: the numerical
  // factorization allocates what it uses.
  cholmod_free_work(&common);
  ordering_seconds = seconds_since(start);
  if (options.observer) options.observer(SetupStage::factorization);
  start = std::chrono::steady_clock::now();
  cholesky.factorize_releasing(matrix);
  const cholmod_factor& factor = *cholesky.factor();
  if (common.status < CHOLMOD_OK) {
    throw_if_out_of_memory(common);
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
  locate_trailing(trailing);
  factorization_seconds = seconds_since(start);
}

/// The symbolic factor knows how many entries L will store (supernodal: xsize; simplicial:
/// CHOLMOD's lnz estimate): refuse before the numerical factorization allocates them.
void CholeskyFactor::Implementation::check_memory_estimate() {
  if (memory_limit_bytes <= 0.0) return;
  const cholmod_factor& symbolic = *cholesky.factor();
  const double entries =
      symbolic.is_super ? static_cast<double>(symbolic.xsize) : cholesky.cholmod().lnz;
  const double bytes = 8.0 * entries;
  if (bytes <= memory_limit_bytes) return;
  const auto gibibytes = [](double value) { return format_number(value / 1073741824.0) + " GiB"; };
  throw ResourceLimitError(
      "body '" + body_name + "': its Cholesky factor would need " + gibibytes(bytes) +
      " (symbolic analysis: " + format_number(entries) + " entries for " + std::to_string(size) +
      " unknowns), above this server's limit of " + gibibytes(memory_limit_bytes) +
      " (robin-subdomain --max-factor-memory MIB raises it)");
}

void CholeskyFactor::Implementation::locate_trailing(const std::vector<int>& trailing) {
  const cholmod_factor& factor = *cholesky.factor();
  trailing_count = static_cast<int>(trailing.size());
  position.assign(factor.n, 0);
  const auto* permutation = static_cast<const int*>(factor.Perm);
  for (int k = 0; k < size; ++k) position[permutation[k]] = k;
  has_trailing_block = !trailing.empty() && factor.is_super &&
                       std::all_of(trailing.begin(), trailing.end(), [&](int unknown) {
                         return position[unknown] >= size - trailing_count;
                       });
}

bool CholeskyFactor::Implementation::within_trailing_block(
    const Eigen::VectorXd& right_hand_side) const {
  if (!has_trailing_block) return false;
  const int first = size - trailing_count;
  for (int unknown = 0; unknown < size; ++unknown) {
    if (right_hand_side[unknown] != 0.0 && position[unknown] < first) return false;
  }
  return true;
}

Eigen::VectorXd CholeskyFactor::Implementation::solve_from_trailing_block(
    const Eigen::VectorXd& right_hand_side) {
  // P b is zero before the trailing block, so is L^{-1} P b: its trailing part is
  // L_TT^{-1} (P b)_T, and x = P' L^{-T} (L^{-1} P b) needs only the backward solve. L_TT is
  // extracted for the solve (the trailing supernodes only), not kept beside L.
  const int first = size - trailing_count;
  const cholmod_factor& factor = *cholesky.factor();
  Eigen::VectorXd forward = Eigen::VectorXd::Zero(size);
  for (int unknown = 0; unknown < size; ++unknown) {
    if (position[unknown] >= first) forward[position[unknown]] = right_hand_side[unknown];
  }
  trailing_factor_block(factor, first)
      .triangularView<Eigen::Lower>()
      .solveInPlace(forward.tail(trailing_count));
  cholmod_common& common = cholesky.cholmod();
  cholmod_dense view = Eigen::viewAsCholmod(forward);
  cholmod_dense* backward =
      cholmod_solve(CHOLMOD_Lt, const_cast<cholmod_factor*>(&factor), &view, &common);
  if (backward == nullptr) {
    throw_if_out_of_memory(common);
    throw std::runtime_error("body '" + body_name + "': CHOLMOD solve failed");
  }
  const auto* values = static_cast<const double*>(backward->x);
  Eigen::VectorXd solution(size);  // x = P' y: unknown j was eliminated at step position[j]
  for (int unknown = 0; unknown < size; ++unknown) solution[unknown] = values[position[unknown]];
  cholmod_free_dense(&backward, &common);
  return solution;
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

CholeskyFactor::CholeskyFactor(const SparseMatrix& matrix, const std::string& body_name,
                               FactorizationOptions options)
    : CholeskyFactor(SparseMatrix(matrix), body_name, std::move(options)) {}

CholeskyFactor::CholeskyFactor(SparseMatrix&& matrix, const std::string& body_name,
                               FactorizationOptions options)
    : implementation_(std::make_unique<Implementation>()) {
  implementation_->body_name = body_name;
  implementation_->memory_limit_bytes = options.memory_limit_bytes;
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
  implementation_->factorize(matrix, options);
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
  ++solve_count_;
  if ((right_hand_side.array() == 0.0).all()) return Eigen::VectorXd::Zero(size());
  if (implementation_->within_trailing_block(right_hand_side)) {
    ++backward_only_solve_count_;
    return implementation_->solve_from_trailing_block(right_hand_side);
  }
  // x = L^{-T} L^{-1} b (with CHOLMOD's fill-reducing permutation)
  Eigen::VectorXd solution = implementation_->cholesky.solve(right_hand_side);
  if (implementation_->cholesky.info() != Eigen::Success) {
    throw std::runtime_error("body '" + implementation_->body_name + "': CHOLMOD solve failed");
  }
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

namespace robin {

double CholeskyFactor::ordering_seconds() const {
  return implementation_->ordering_seconds;
}

double CholeskyFactor::factorization_seconds() const {
  return implementation_->factorization_seconds;
}

bool CholeskyFactor::has_trailing_block() const {
  return implementation_->has_trailing_block;
}

Eigen::MatrixXd CholeskyFactor::trailing_congruence(const SparseMatrix& trace) const {
  const Implementation& factor = *implementation_;
  if (!factor.has_trailing_block) {
    throw std::logic_error("body '" + factor.body_name + "': the factor has no trailing block");
  }
  if (trace.cols() != size()) {
    throw std::invalid_argument("body '" + factor.body_name + "': a trace with " +
                                std::to_string(trace.cols()) + " columns for a factor of size " +
                                std::to_string(size()));
  }
  const int first = size() - factor.trailing_count;
  const int trailing = factor.trailing_count;
  const int rows = static_cast<int>(trace.rows());
  // Y = (P B')_T, its columns (the rows of B) in the order of their first nonzero row top_j;
  // then X = L_TT^{-1} Y is zero above top_j in column j, and B K^{-1} B' = X' X
  std::vector<int> top(static_cast<std::size_t>(rows), trailing);
  for (int column = 0; column < trace.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(trace, column); entry; ++entry) {
      const int step = factor.position[column] - first;
      if (step < 0) {
        throw std::invalid_argument("body '" + factor.body_name + "': the trace reads unknown " +
                                    std::to_string(column) + ", not a trailing unknown");
      }
      int& row_top = top[static_cast<std::size_t>(entry.row())];
      row_top = std::min(row_top, step);
    }
  }
  std::vector<int> order(static_cast<std::size_t>(rows));  // sorted position -> row of B
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&top](int a, int b) { return top[a] < top[b]; });
  std::vector<int> place(static_cast<std::size_t>(rows));  // row of B -> sorted position
  for (int k = 0; k < rows; ++k) place[static_cast<std::size_t>(order[k])] = k;
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(trailing, rows);
  for (int column = 0; column < trace.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(trace, column); entry; ++entry) {
      reduced(factor.position[column] - first, place[static_cast<std::size_t>(entry.row())]) +=
          entry.value();
    }
  }
  Eigen::MatrixXd congruence = Eigen::MatrixXd::Zero(rows, rows);
  if (rows == 0) return congruence;
  const Eigen::MatrixXd block = trailing_factor_block(*factor.cholesky.factor(), first);
  const Eigen::MatrixXd sorted = staircase_congruence(block, reduced, order, top);
  for (int j = 0; j < rows; ++j) {
    for (int i = j; i < rows; ++i) {
      const double value = sorted(i, j);
      congruence(order[i], order[j]) = value;
      congruence(order[j], order[i]) = value;
    }
  }
  return congruence;
}

}  // namespace robin
