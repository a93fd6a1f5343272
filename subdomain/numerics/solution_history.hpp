#pragma once
// Earlier solutions of K x = B' r, kept to start the next solve with a new interface force
// (Fischer 1998, projection onto earlier solutions for successive right-hand sides).
//
// With the kept solutions x_i of K x_i = B' r_i (i = 1 .. m), the start for B' r is the
// x_0 = sum_i c_i x_i of their span that minimises the energy norm of the error x - x_0:
//   G c = h,  G_ij = x_i' K x_j = (B x_i)' r_j,  h_i = x_i' K x = (B x_i)' r,
// which needs no product with K, only the kept traces B x_i and forces. G is symmetrised (the x_i
// are solved to a tolerance) and inverted on its eigenvectors whose eigenvalues exceed 1e-10 of
// the largest (nearly dependent solutions are dropped). When r is a combination of the kept r_i
// the start is the solution up to their tolerance; else it removes the error's part in the span.

#include <Eigen/Core>
#include <deque>

namespace robin {

class SolutionHistory {
 public:
  /// Keeps at most `capacity` solutions (at least 1).
  explicit SolutionHistory(int capacity);

  /// Keeps x = K^{-1} B' r (`solution`, free dofs) with `force` r and `trace` B x, forgetting the
  /// oldest beyond the capacity.
  void add(const Eigen::VectorXd& force, const Eigen::VectorXd& solution,
           const Eigen::VectorXd& trace);
  void clear() { entries_.clear(); }
  bool empty() const { return entries_.empty(); }
  int size() const { return static_cast<int>(entries_.size()); }

  /// x_0 for the force `force` (the file comment); a zero vector of `unknowns` values when no
  /// solution is kept. Throws std::invalid_argument when the sizes differ from the kept ones.
  Eigen::VectorXd start(const Eigen::VectorXd& force, Eigen::Index unknowns) const;

 private:
  struct Entry {
    Eigen::VectorXd force, solution, trace;
  };
  int capacity_;
  std::deque<Entry> entries_;
};

}  // namespace robin
