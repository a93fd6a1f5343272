#include "coupling/monolithic_solver.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

#include "numerics/errors.hpp"

namespace robin {
namespace {

/// (F1 + F2) x: the compliance of the pair of bodies seen by a common contact force.
class SumOperator final : public LinearOperator {
 public:
  SumOperator(const LinearOperator& first, const LinearOperator& second)
      : first_(first), second_(second) {}
  int size() const override { return first_.size(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    first_.apply(x, y);
    second_.apply(x, scratch_);
    y += scratch_;
  }

 private:
  const LinearOperator& first_;
  const LinearOperator& second_;
  mutable Eigen::VectorXd scratch_;
};

double maximum_absolute(const Eigen::VectorXd& values) {
  return values.size() == 0 ? 0.0 : values.lpNorm<Eigen::Infinity>();
}

}  // namespace

InterfaceResiduals interface_residuals(const Eigen::VectorXd& gap, const Eigen::VectorXd& trace1,
                                       const Eigen::VectorXd& trace2, const Eigen::VectorXd& force1,
                                       const Eigen::VectorXd& force2) {
  constexpr double tiny = std::numeric_limits<double>::min();
  const double displacement_scale =
      std::max({maximum_absolute(gap), maximum_absolute(trace1), maximum_absolute(trace2), tiny});
  const double force_scale = std::max({maximum_absolute(force1), maximum_absolute(force2), tiny});
  InterfaceResiduals residuals;
  for (Eigen::Index i = 0; i < gap.size(); ++i) {
    const double clearance = gap[i] - trace1[i] - trace2[i];
    const double force = 0.5 * (force1[i] + force2[i]);
    residuals.penetration = std::max(residuals.penetration, -clearance / displacement_scale);
    residuals.force_balance =
        std::max(residuals.force_balance, std::abs(force1[i] - force2[i]) / force_scale);
    residuals.complementarity =
        std::max(residuals.complementarity,
                 std::abs(force * clearance) / (force_scale * displacement_scale));
  }
  return residuals;
}

MonolithicResult solve_monolithic(const BodySolver& body1, const BodySolver& body2,
                                  const ContactPairing& pairing, const MprgpParameters& parameters,
                                  const Eigen::VectorXd& initial_force) {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Index size = static_cast<Eigen::Index>(pairing.size());
  if (body1.contact_size() != size || body2.contact_size() != size) {
    throw InputError("monolithic solve: both bodies must be assigned the " + std::to_string(size) +
                     " contact pairs first");
  }
  const Eigen::VectorXd gap = pairing.gaps();
  // minimise 1/2 l'(F1 + F2) l - l'(e1 + e2 - d), l >= 0
  const SumOperator compliance(body1.compliance(), body2.compliance());
  const Eigen::VectorXd right_hand_side = body1.free_trace() + body2.free_trace() - gap;
  MonolithicResult result;
  MprgpParameters scaled = parameters;
  scaled.solution_scaled_tolerance = true;  // resolve lambda relative to itself, not to |e - d|
  const Eigen::VectorXd initial = initial_force.size() == size
                                      ? Eigen::VectorXd(initial_force.cwiseMax(0.0))
                                      : Eigen::VectorXd(Eigen::VectorXd::Zero(size));
  result.qp =
      solve_mprgp(compliance, right_hand_side, Eigen::VectorXd::Zero(size), initial, scaled);
  result.contact_force = result.qp.solution;
  // u_N = e - F lambda on each body
  Eigen::VectorXd product;
  body1.compliance().apply(result.contact_force, product);
  result.normal_trace1 = body1.free_trace() - product;
  body2.compliance().apply(result.contact_force, product);
  result.normal_trace2 = body2.free_trace() - product;
  result.residuals = interface_residuals(gap, result.normal_trace1, result.normal_trace2,
                                         result.contact_force, result.contact_force);
  result.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<MonolithicStep> solve_monolithic_steps(BodySolver& body1, BodySolver& body2,
                                                   const ContactPairing& pairing,
                                                   const LoadingOptions& loading,
                                                   const MprgpParameters& parameters) {
  std::vector<MonolithicStep> steps;
  for (std::size_t k = 0; k < loading.factors.size(); ++k) {
    MonolithicStep step;
    step.step = static_cast<int>(k + 1);
    step.factor = loading.factors[k];
    body1.set_load_factor(step.factor);
    body2.set_load_factor(step.factor);
    const Eigen::VectorXd initial = loading.warm_start && !steps.empty()
                                        ? steps.back().result.contact_force
                                        : Eigen::VectorXd();
    step.result = solve_monolithic(body1, body2, pairing, parameters, initial);
    const bool converged = step.result.qp.status == QpStatus::converged;
    steps.push_back(std::move(step));
    if (!converged) break;
  }
  return steps;
}

}  // namespace robin
